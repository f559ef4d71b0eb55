#include <algorithm>
#include <cmath>
#include <memory>

#include "effects.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen::gap_detail {

// ---- reversal ------------------------------------------------------------------------------
// Backlash of one axis: the axis stops short by half its lost motion B in the direction of
// approach, q_actual = q - dir B/2, and that reaches the outputs through the kinematic chain
// (the nominal Jacobian at the pose): on a turning table a reversal of C moves dx and dy by the
// table's radius times B/2, whatever C is. One parameter per axis: B, in µm for a linear axis
// and µrad for a rotary one. On a ballbar trace a further variant takes both axes at once, one
// column each.

void add_reversal(const EffectContext& ctx, std::vector<Candidate>& out) {
  const GapData& d = *ctx.data;
  if (d.dir.empty() || !ctx.chain) return;
  Candidate c;
  c.name = "reversal";
  std::vector<std::string> axes;
  std::vector<std::size_t> index;  // into GapData::axes
  for (const auto& [axis, v] : d.dir) {
    const auto it = std::find(d.axes.begin(), d.axes.end(), axis);
    if (it == d.axes.end()) continue;  // a direction of something that is not an axis
    axes.push_back(axis);
    index.push_back(static_cast<std::size_t>(it - d.axes.begin()));
    c.variants.push_back({axis, {static_cast<double>(axes.size() - 1)}});
  }
  if (axes.empty()) return;
  // A ballbar circle reverses both of its axes: backlash of each at once is the usual case.
  if (d.circle && axes.size() > 1) c.variants.push_back({join(axes), {-1.0}});
  const auto jacobians = std::make_shared<std::vector<MatrixXd>>(axis_jacobians(ctx));
  // Per unit of B (µm or µrad) of each axis: its unit's size in mm or rad.
  std::vector<double> per_unit;
  for (std::size_t k = 0; k < axes.size(); ++k) {
    const std::string& u = index[k] < d.axis_units.size() ? d.axis_units[index[k]] : "mm";
    const bool rotary = u == "deg" || u == "rad";
    // B in µm (linear, axis in mm) or µrad (rotary): the axis moves by B in its own unit.
    per_unit.push_back(rotary ? (u == "deg" ? 1e-6 * 180 / kPi : 1e-6)
                              : (u == "um"  ? 1.0
                                 : u == "m" ? 1e-6
                                            : 1e-3));
  }
  // The measured output each axis moves most (the region's output).
  std::vector<std::string> moved;
  for (std::size_t k = 0; k < axes.size(); ++k) {
    std::array<double, kObservationKinds> size{};
    for (const auto& ob : d.points.observations) {
      const MatrixXd& J = (*jacobians)[ob.row];
      if (J.size() == 0) continue;
      for (int o = 0; o < kNumDeviationOutputs; ++o)
        size[static_cast<std::size_t>(ob.output)] +=
            std::abs(observation_weight(ob, o) * kMeasuredScale[static_cast<std::size_t>(o)] *
                     J(o, static_cast<Index>(index[k])));
    }
    moved.push_back(observation_name(
        static_cast<std::size_t>(std::max_element(size.begin(), size.end()) - size.begin())));
  }
  // The axes of a variant: one (hyper = its index) or all (hyper = -1).
  const auto chosen = [n = axes.size()](const Variant& v) {
    std::vector<std::size_t> ks;
    if (v.hyper[0] < 0)
      for (std::size_t k = 0; k < n; ++k) ks.push_back(k);
    else
      ks.push_back(static_cast<std::size_t>(v.hyper[0]));
    return ks;
  };
  c.columns = [&d, jacobians, index, axes, per_unit, chosen](const Variant& v,
                                                             const std::vector<double>&) {
    const std::vector<std::size_t> ks = chosen(v);
    const auto& obs = d.points.observations;
    MatrixXd E = MatrixXd::Zero(static_cast<Index>(obs.size()), static_cast<Index>(ks.size()));
    for (std::size_t col = 0; col < ks.size(); ++col) {
      const std::size_t k = ks[col];
      const std::vector<double>& dir = d.dir.at(axes[k]);
      for (std::size_t i = 0; i < obs.size(); ++i) {
        const MatrixXd& J = (*jacobians)[obs[i].row];
        if (J.size() == 0) continue;
        double s = 0;
        for (int o = 0; o < kNumDeviationOutputs; ++o)
          s += observation_weight(obs[i], o) * kMeasuredScale[static_cast<std::size_t>(o)] *
               J(o, static_cast<Index>(index[k]));
        // q_actual = q - dir B/2.
        E(static_cast<Index>(i), static_cast<Index>(col)) = -dir[obs[i].row] / 2 * per_unit[k] * s;
      }
    }
    return E;
  };
  c.describe = [&d, axes, index, moved, chosen](const Variant& v, const VectorXd& coef,
                                                EffectFit& fit) {
    const std::vector<std::size_t> ks = chosen(v);
    std::size_t largest = ks.front();
    double largest_b = -1;
    for (std::size_t col = 0; col < ks.size(); ++col) {
      const std::size_t k = ks[col];
      const std::string& axis = axes[k];
      const std::string u = index[k] < d.axis_units.size() ? d.axis_units[index[k]] : "mm";
      const bool rotary = u == "deg" || u == "rad";
      const double b = static_cast<Index>(col) < coef.size() ? coef[static_cast<Index>(col)] : 0;
      fit.summary += (col ? ", " : "reversal of ") + axis + ": " + format_short(std::abs(b), 2) +
                     (rotary ? " µrad" : " µm");
      // One axis: reversal_um; several: reversal_um_<axis> each.
      fit.params[std::string(rotary ? "reversal_urad" : "reversal_um") +
                 (ks.size() > 1 ? "_" + axis : "")] = b;
      fit.params["axis_" + axis] = 1;
      if (std::abs(b) > largest_b) largest_b = std::abs(b), largest = k;
    }
    GapRegion r;
    r.by = "dir_" + axes[largest];
    r.output = moved[largest];
    r.from = -1;
    r.to = 1;
    fit.region = r;
  };
  out.push_back(std::move(c));
}

}  // namespace weilgen::gap_detail
