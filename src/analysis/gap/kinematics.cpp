// Axis Jacobians for the effects that act through the kinematic chain (reversal of an axis).
#include <Eigen/Dense>

#include "effects.hpp"

namespace weilgen::gap_detail {

std::vector<Eigen::MatrixXd> axis_jacobians(const EffectContext& ctx) {
  const GapData& d = *ctx.data;
  const NumericChain& chain = *ctx.chain;
  const std::size_t na = d.axes.size();
  std::vector<Eigen::MatrixXd> J(d.points.poses.size());
  std::vector<char> needed(d.points.poses.size(), 0);
  for (const auto& o : d.points.observations) needed[o.row] = 1;
  for (std::size_t r = 0; r < J.size(); ++r) {
    if (!needed[r] || d.points.poses[r].size() != na) continue;
    J[r] = chain.nominal_jacobian(d.points.poses[r]);  // 6 x axes, per axis unit
  }
  return J;
}

}  // namespace weilgen::gap_detail
