// The kinematic chain as the effects see it: axis Jacobians (an axis' backlash, its thermal
// scale), the sensitivity of every observation to each motion error of each axis (periodic and
// bump shapes of one error), and the orientation of the tool and machine frames in the workpiece
// frame (thermal growth of the spindle or of the structure).
#include <algorithm>
#include <cmath>

#include "effects.hpp"
#include "weilgen/base/parallel.hpp"
#include "weilgen/machine/iso_names.hpp"
#include "weilgen/uq/dense.hpp"

namespace weilgen::gap_detail {

namespace {

// Rows that carry an observation and a full pose.
std::vector<char> rows_needed(const GapData& d) {
  std::vector<char> needed(d.points.poses.size(), 0);
  for (const auto& o : d.points.observations)
    if (d.points.poses[o.row].size() == d.axes.size()) needed[o.row] = 1;
  return needed;
}

}  // namespace

std::vector<Eigen::MatrixXd> axis_jacobians(const EffectContext& ctx) {
  if (!ctx.jacobians) {
    const GapData& d = *ctx.data;
    const NumericChain& chain = *ctx.chain;
    auto J = std::make_shared<std::vector<Eigen::MatrixXd>>(d.points.poses.size());
    const std::vector<char> needed = rows_needed(d);
    parallel_blocks(J->size(), 64, ctx.threads,
                    [&](std::size_t, std::size_t begin, std::size_t end, unsigned) {
                      for (std::size_t r = begin; r < end; ++r)
                        if (needed[r])  // 6 x axes, per axis unit
                          (*J)[r] = chain.nominal_jacobian(d.points.poses[r]);
                    });
    ctx.jacobians = std::move(J);
  }
  return *ctx.jacobians;
}

std::vector<Eigen::Matrix3d> frame_rotations(const EffectContext& ctx, Frame frame) {
  const GapData& d = *ctx.data;
  const NumericChain& chain = *ctx.chain;
  const std::vector<double> zero(chain.num_errors(), 0.0);
  std::vector<Eigen::Matrix3d> R(d.points.poses.size(), Eigen::Matrix3d::Identity());
  const std::vector<char> needed = rows_needed(d);
  for (std::size_t r = 0; r < R.size(); ++r) {
    if (!needed[r]) continue;
    R[r] = frame == Frame::Tool
               ? Eigen::Matrix3d(chain.tool_in_workpiece(d.points.poses[r], zero).block<3, 3>(0, 0))
               : Eigen::Matrix3d(
                     chain.workpiece_in_base(d.points.poses[r]).block<3, 3>(0, 0).transpose());
  }
  return R;
}

double measured(const PointObservation& ob, const double* v6) {
  double s = 0;
  for (int o = 0; o < kNumDeviationOutputs; ++o)
    s += observation_weight(ob, o) * kMeasuredScale[static_cast<std::size_t>(o)] * v6[o];
  return s;
}

std::vector<AxisError> axis_errors(const EffectContext& ctx, std::size_t min_levels) {
  const GapData& d = *ctx.data;
  const Model& model = *ctx.model;
  const Description& desc = model.description();
  const std::vector<int> bodies = desc.axes();
  const auto& obs = d.points.observations;
  const std::size_t ne = model.num_errors();
  // d(output)/d(error) per table row (6 x errors), from the model at zero error.
  std::vector<std::vector<double>> coeff(d.points.poses.size());
  const std::vector<char> needed = rows_needed(d);
  ModelData md(model);
  for (std::size_t r = 0; r < coeff.size(); ++r) {
    if (!needed[r]) continue;
    coeff[r].resize(6 * ne);
    model.coefficients(md, d.points.poses[r].data(), coeff[r].data());
  }
  std::vector<AxisError> out;
  for (const AxisInfo& axis : varying_axes(d, min_levels)) {
    if (axis.index >= bodies.size()) continue;
    const Joint& j = desc.bodies[static_cast<std::size_t>(bodies[axis.index])].joint;
    if (!iso_not_applicable(j).empty()) continue;
    // Positioning first, then straightness, then the angular errors: among errors the data
    // cannot tell apart the first is named and the others listed.
    std::vector<std::string> names = iso_motion_errors(j);
    const int along = principal_axis(j.axis);
    if (j.type == JointType::Prismatic && along >= 0)
      std::stable_partition(names.begin(), names.end(), [&](const std::string& n) {
        return n.size() > 2 && n[2] == "XYZ"[along];
      });
    std::vector<AxisError> mine;
    for (const std::string& n : names) {
      const int e = desc.error_index(n);
      if (e < 0) continue;  // not in the file: the missing_error candidate's job
      const ErrorDef& def = desc.errors[static_cast<std::size_t>(e)];
      AxisError ae;
      ae.axis = axis;
      ae.error = e;
      ae.name = def.name;
      ae.rotation = def.effect == ErrorEffect::Rotation;
      // Per µm or µrad of the error.
      const double per = ae.rotation ? 1e-6 : 1e-3;
      auto unit = std::make_shared<VectorXd>(static_cast<Index>(obs.size()));
      std::array<double, kObservationKinds> reach{};
      for (std::size_t i = 0; i < obs.size(); ++i) {
        double v = 0;
        if (!coeff[obs[i].row].empty()) {
          double g[6];
          for (int o = 0; o < 6; ++o)
            g[o] =
                coeff[obs[i].row][static_cast<std::size_t>(o) * ne + static_cast<std::size_t>(e)];
          v = per * measured(obs[i], g);
        }
        (*unit)[static_cast<Index>(i)] = v;
        reach[static_cast<std::size_t>(obs[i].output)] += v * v;
      }
      if (!(unit->norm() > 1e-9 * std::sqrt(static_cast<double>(obs.size())))) continue;
      ae.output = static_cast<int>(std::max_element(reach.begin(), reach.end()) - reach.begin());
      // The same column up to a factor as an error listed before: the data cannot tell them
      // apart (a line run: a straightness and the angular error whose lever arm is constant).
      bool same = false;
      for (AxisError& m : mine) {
        const double c = m.unit->dot(*unit);
        if (c * c >= (1 - 1e-8) * m.unit->squaredNorm() * unit->squaredNorm()) {
          m.same_as.push_back(ae.name);
          same = true;
          break;
        }
      }
      if (same) continue;
      ae.unit = unit;
      mine.push_back(std::move(ae));
    }
    for (AxisError& m : mine) out.push_back(std::move(m));
  }
  return out;
}

std::shared_ptr<const std::vector<AxisError>> shaped_errors(const EffectContext& ctx) {
  if (!ctx.shaped_errors)
    ctx.shaped_errors = std::make_shared<const std::vector<AxisError>>(axis_errors(ctx, 6));
  return ctx.shaped_errors;
}

}  // namespace weilgen::gap_detail
