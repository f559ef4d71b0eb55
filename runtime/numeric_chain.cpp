#include "numeric_chain.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace weilgen {

namespace {
Eigen::Vector3d vec(const Vec3& v) { return {v[0], v[1], v[2]}; }

Eigen::Matrix4d translation(const Eigen::Vector3d& t) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<3, 1>(0, 3) = t;
  return m;
}

Eigen::Matrix4d rotation(const Eigen::Vector3d& axis, double angle_rad) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.block<3, 3>(0, 0) = Eigen::AngleAxisd(angle_rad, axis.normalized()).toRotationMatrix();
  return m;
}

Eigen::Matrix4d rigid_inverse(const Eigen::Matrix4d& m) {
  Eigen::Matrix4d r = Eigen::Matrix4d::Identity();
  r.block<3, 3>(0, 0) = m.block<3, 3>(0, 0).transpose();
  r.block<3, 1>(0, 3) = -m.block<3, 3>(0, 0).transpose() * m.block<3, 1>(0, 3);
  return r;
}
}  // namespace

NumericChain::NumericChain(Description desc)
    : desc_(std::move(desc)), axis_bodies_(desc_.axes()), params_(desc_.parameter_defaults()) {}

void NumericChain::set_parameters(const std::vector<double>& values) {
  if (values.size() != desc_.parameters.size())
    throw std::invalid_argument("expected " + std::to_string(desc_.parameters.size()) +
                                " parameter values");
  for (std::size_t i = 0; i < values.size(); ++i) params_[desc_.parameters[i].name] = values[i];
}

Eigen::Matrix4d NumericChain::error_transform(int body, ErrorPlacement placement,
                                              const std::vector<double>& errors) const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (int ei : desc_.bodies[body].errors) {
    const ErrorDef& e = desc_.errors[ei];
    if (e.placement != placement) continue;
    const double v = errors.at(ei);
    m = m * (e.effect == ErrorEffect::Translation ? translation(v * vec(e.direction))
                                                  : rotation(vec(e.direction), v));
  }
  return m;
}

Eigen::Matrix4d NumericChain::body_transform(int body, const std::vector<double>& axes,
                                             const std::vector<double>& errors) const {
  const Body& b = desc_.bodies[body];
  Eigen::Vector3d t;
  for (int i = 0; i < 3; ++i) t[i] = b.offset.translation[i].eval(params_);
  Eigen::Matrix4d m = translation(t);
  for (const auto& r : b.offset.rotations)
    m = m * rotation(vec(r.axis), r.angle_deg.eval(params_) * M_PI / 180.0);

  Eigen::Matrix4d joint = Eigen::Matrix4d::Identity();
  if (b.joint.type != JointType::Fixed) {
    const auto k = std::find(axis_bodies_.begin(), axis_bodies_.end(), body) - axis_bodies_.begin();
    const double q = axes.at(static_cast<std::size_t>(k)) * b.joint.to_base;
    joint = b.joint.type == JointType::Prismatic ? translation(q * vec(b.joint.axis))
                                                 : rotation(vec(b.joint.axis), q);
  }
  const Eigen::Matrix4d axis = error_transform(body, ErrorPlacement::Axis, errors);
  return m * error_transform(body, ErrorPlacement::Before, errors) * axis * joint *
         rigid_inverse(axis) * error_transform(body, ErrorPlacement::After, errors);
}

Eigen::Matrix4d NumericChain::branch(const PointSpec& end, const std::vector<double>& axes,
                                     const std::vector<double>& errors) const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (int b : desc_.chain_to(end.body)) m = m * body_transform(b, axes, errors);
  Eigen::Vector3d p;
  for (int i = 0; i < 3; ++i) p[i] = end.point[i].eval(params_);
  return m * translation(p);
}

Eigen::Matrix4d NumericChain::tool_in_workpiece(const std::vector<double>& axes,
                                                const std::vector<double>& errors) const {
  if (axes.size() != axis_bodies_.size())
    throw std::invalid_argument("expected " + std::to_string(axis_bodies_.size()) + " axis values");
  if (errors.size() != desc_.errors.size())
    throw std::invalid_argument("expected " + std::to_string(desc_.errors.size()) +
                                " error values");
  return rigid_inverse(branch(desc_.workpiece, axes, errors)) * branch(desc_.tool, axes, errors);
}

std::array<double, 6> NumericChain::deviation(const std::vector<double>& axes,
                                              const std::vector<double>& errors) const {
  const Eigen::Matrix4d actual = tool_in_workpiece(axes, errors);
  const Eigen::Matrix4d nominal =
      tool_in_workpiece(axes, std::vector<double>(desc_.errors.size(), 0.0));
  const Eigen::Vector3d dp = actual.block<3, 1>(0, 3) - nominal.block<3, 1>(0, 3);
  const Eigen::Matrix3d dr = actual.block<3, 3>(0, 0) * nominal.block<3, 3>(0, 0).transpose();
  const Eigen::AngleAxisd aa(dr);
  const Eigen::Vector3d w = aa.angle() * aa.axis();
  return {dp[0], dp[1], dp[2], w[0], w[1], w[2]};
}

}  // namespace weilgen
