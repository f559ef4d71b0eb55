// Axis Jacobians for the effects that act through the kinematic chain (reversal of an axis).
#include <Eigen/Dense>
#include <cmath>

#include "effects.hpp"

namespace weilgen::gap_detail {

namespace {

// The axial vector of the skew part of R: the rotation vector up to O(angle^3).
Eigen::Vector3d axial(const Eigen::Matrix3d& r) {
  return 0.5 * Eigen::Vector3d(r(2, 1) - r(1, 2), r(0, 2) - r(2, 0), r(1, 0) - r(0, 1));
}

}  // namespace

std::vector<Eigen::MatrixXd> axis_jacobians(const EffectContext& ctx) {
  const GapData& d = *ctx.data;
  const NumericChain& chain = *ctx.chain;
  const std::vector<double> zero(chain.num_errors(), 0.0);
  const std::size_t na = d.axes.size();
  std::vector<Eigen::MatrixXd> J(d.points.poses.size());
  std::vector<char> needed(d.points.poses.size(), 0);
  for (const auto& o : d.points.observations) needed[o.row] = 1;
  for (std::size_t r = 0; r < J.size(); ++r) {
    if (!needed[r] || d.points.poses[r].size() != na) continue;
    Eigen::MatrixXd j = Eigen::MatrixXd::Zero(6, static_cast<Eigen::Index>(na));
    for (std::size_t a = 0; a < na; ++a) {
      // 1e-3 of the axis unit (µm, millidegree): far above rounding, far below any curvature.
      const double h = 1e-3;
      std::vector<double> up = d.points.poses[r], down = d.points.poses[r];
      up[a] += h;
      down[a] -= h;
      const Eigen::Matrix4d tu = chain.tool_in_workpiece(up, zero);
      const Eigen::Matrix4d td = chain.tool_in_workpiece(down, zero);
      const auto col = static_cast<Eigen::Index>(a);
      j.block<3, 1>(0, col) = (tu.block<3, 1>(0, 3) - td.block<3, 1>(0, 3)) / (2 * h);
      j.block<3, 1>(3, col) =
          axial(tu.block<3, 3>(0, 0) * td.block<3, 3>(0, 0).transpose()) / (2 * h);
    }
    J[r] = j;
  }
  return J;
}

}  // namespace weilgen::gap_detail
