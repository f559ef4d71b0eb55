#include "weilgen/model/numeric_chain.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "weilgen/base/constants.hpp"
#include "weilgen/machine/derived.hpp"

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
    : desc_(std::move(desc)),
      axis_bodies_(desc_.axes()),
      linked_bodies_(desc_.linked_axes()),
      params_(desc_.parameter_defaults()) {
  const std::size_t nb = desc_.bodies.size();
  paths_.resize(nb);
  placed_.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    paths_[b] = desc_.chain_to(static_cast<int>(b));
    for (int ei : desc_.bodies[b].errors)
      placed_[b][static_cast<std::size_t>(desc_.errors[static_cast<std::size_t>(ei)].placement)]
          .push_back(ei);
  }
  cache_parameters();
}

void NumericChain::set_parameters(const std::vector<double>& values) {
  if (values.size() != desc_.parameters.size())
    throw std::invalid_argument("expected " + std::to_string(desc_.parameters.size()) +
                                " parameter values");
  for (std::size_t i = 0; i < values.size(); ++i) params_[desc_.parameters[i].name] = values[i];
  cache_parameters();
}

void NumericChain::cache_parameters() {
  offsets_.resize(desc_.bodies.size());
  through_.resize(desc_.bodies.size());
  for (std::size_t k = 0; k < desc_.bodies.size(); ++k) {
    const Body& b = desc_.bodies[k];
    Eigen::Vector3d t;
    for (int i = 0; i < 3; ++i) t[i] = b.offset.translation[i].eval(params_);
    Eigen::Matrix4d m = translation(t);
    for (const auto& r : b.offset.rotations)
      m = m * rotation(vec(r.axis), r.angle_deg.eval(params_) * kPi / 180.0);
    offsets_[k] = m;
    for (int i = 0; i < 3; ++i) through_[k][i] = b.joint.through[i].eval(params_);
  }
  tool_point_ = point_of(desc_.tool);
  workpiece_point_ = point_of(desc_.workpiece);
}

Eigen::Vector3d NumericChain::point_of(const PointSpec& end) const {
  Eigen::Vector3d p;
  for (int i = 0; i < 3; ++i) p[i] = end.point[i].eval(params_);
  return p;
}

Eigen::Matrix4d NumericChain::error_transform(int body, ErrorPlacement placement,
                                              const std::vector<double>& errors) const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (int ei : placed_[static_cast<std::size_t>(body)][static_cast<std::size_t>(placement)]) {
    const ErrorDef& e = desc_.errors[static_cast<std::size_t>(ei)];
    const double v = errors[static_cast<std::size_t>(ei)];
    m = m * (e.effect == ErrorEffect::Translation ? translation(v * vec(e.direction))
                                                  : rotation(vec(e.direction), v));
  }
  return m;
}

Eigen::Matrix4d NumericChain::body_transform(int body, const std::vector<double>& q_body,
                                             const std::vector<double>& errors) const {
  const Body& b = desc_.bodies[static_cast<std::size_t>(body)];
  const Eigen::Matrix4d& m = offsets_[static_cast<std::size_t>(body)];
  Eigen::Matrix4d joint = Eigen::Matrix4d::Identity();
  if (b.joint.type != JointType::Fixed) {
    const double q = q_body[static_cast<std::size_t>(body)] * b.joint.to_base;
    if (b.joint.type == JointType::Prismatic) {
      joint = translation(q * vec(b.joint.axis));
    } else {
      const Eigen::Vector3d& through = through_[static_cast<std::size_t>(body)];
      joint = translation(through) * rotation(vec(b.joint.axis), q) * translation(-through);
    }
  }
  const Eigen::Matrix4d axis = error_transform(body, ErrorPlacement::Axis, errors);
  return m * error_transform(body, ErrorPlacement::Before, errors) * axis * joint *
         rigid_inverse(axis) * error_transform(body, ErrorPlacement::After, errors);
}

Eigen::Matrix4d NumericChain::branch(int body, const Eigen::Vector3d& point,
                                     const std::vector<double>& q_body,
                                     const std::vector<double>& errors) const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  if (body >= 0 && static_cast<std::size_t>(body) < paths_.size())
    for (int b : paths_[static_cast<std::size_t>(body)]) m = m * body_transform(b, q_body, errors);
  return m * translation(point);
}

std::map<std::string, double> NumericChain::coordinate_values(
    const std::vector<double>& axes) const {
  std::map<std::string, double> values = params_;
  for (std::size_t k = 0; k < axis_bodies_.size(); ++k)
    values[desc_.bodies[static_cast<std::size_t>(axis_bodies_[k])].joint.coordinate] = axes[k];
  resolve_links(desc_, values);
  return values;
}

Eigen::Matrix4d NumericChain::output_transform(std::map<std::string, double> values,
                                               const std::vector<double>& q_body,
                                               const std::vector<double>& errors) const {
  const std::vector<double> none(errors.size(), 0.0);
  for (const ChainPoint& p : desc_.points) {
    const Eigen::Vector3d at = point_of(p.at);
    const Eigen::Vector3d d =
        (branch(p.at.body, at, q_body, errors) - branch(p.at.body, at, q_body, none))
            .block<3, 1>(0, 3);
    for (int i = 0; i < 3; ++i) values[p.name + "." + static_cast<char>('x' + i)] = d[i];
  }
  for (const ChainDirection& u : desc_.directions) {
    const Eigen::Vector3d r =
        branch(u.body, Eigen::Vector3d::Zero(), q_body, none).block<3, 3>(0, 0) * vec(u.direction);
    for (int i = 0; i < 3; ++i) values[u.name + "." + static_cast<char>('x' + i)] = r[i];
  }
  for (const Derived& q : desc_.derived) values[q.name] = q.value.eval(values);
  auto vec3 = [&](const std::array<Expr, 3>& e) {
    return Eigen::Vector3d(e[0].eval(values), e[1].eval(values), e[2].eval(values));
  };
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (const TransformStep& s : desc_.output->steps) {
    if (s.kind == TransformStep::Kind::Translate) {
      m = m * translation(vec3(s.translation));
      continue;
    }
    // exp(ξ^ a) for ξ = (ω, v): a screw about the line through ω × v with pitch ω·v (|ω| = 1),
    // or a translation by v·a (ω = 0).
    const Eigen::Vector3d w = vec(s.omega), v = vec3(s.v);
    const double a = s.amount.eval(values);
    if (w.norm() == 0) {
      m = m * translation(a * v);
    } else {
      const Eigen::Vector3d q = w.cross(v);
      m = m * translation(q) * rotation(w, a) * translation(w.dot(v) * a * w - q);
    }
  }
  return m * translation(vec3(desc_.output->point));
}

Eigen::Matrix4d NumericChain::tool_in_workpiece(const std::vector<double>& axes,
                                                const std::vector<double>& errors) const {
  if (axes.size() != axis_bodies_.size())
    throw std::invalid_argument("expected " + std::to_string(axis_bodies_.size()) + " axis values");
  if (errors.size() != desc_.errors.size())
    throw std::invalid_argument("expected " + std::to_string(desc_.errors.size()) +
                                " error values");
  std::vector<double> q_body(desc_.bodies.size(), 0.0);
  for (std::size_t k = 0; k < axis_bodies_.size(); ++k)
    q_body[static_cast<std::size_t>(axis_bodies_[k])] = axes[k];
  // Names are needed only for linked coordinates and the output transform: serial machines
  // evaluate without building them (this chain is the numeric engine's hot path).
  if (linked_bodies_.empty() && !desc_.output)
    return rigid_inverse(branch(desc_.workpiece.body, workpiece_point_, q_body, errors)) *
           branch(desc_.tool.body, tool_point_, q_body, errors);
  const std::map<std::string, double> values = coordinate_values(axes);
  for (int b : linked_bodies_)
    q_body[static_cast<std::size_t>(b)] =
        values.at(desc_.bodies[static_cast<std::size_t>(b)].joint.coordinate);
  if (desc_.output) return output_transform(values, q_body, errors);
  return rigid_inverse(branch(desc_.workpiece.body, workpiece_point_, q_body, errors)) *
         branch(desc_.tool.body, tool_point_, q_body, errors);
}

Eigen::Matrix4d NumericChain::workpiece_in_base(const std::vector<double>& axes) const {
  if (axes.size() != axis_bodies_.size())
    throw std::invalid_argument("expected " + std::to_string(axis_bodies_.size()) + " axis values");
  if (desc_.output) return Eigen::Matrix4d::Identity();
  std::vector<double> q_body(desc_.bodies.size(), 0.0);
  for (std::size_t k = 0; k < axis_bodies_.size(); ++k)
    q_body[static_cast<std::size_t>(axis_bodies_[k])] = axes[k];
  if (!linked_bodies_.empty()) {
    const std::map<std::string, double> values = coordinate_values(axes);
    for (int b : linked_bodies_)
      q_body[static_cast<std::size_t>(b)] =
          values.at(desc_.bodies[static_cast<std::size_t>(b)].joint.coordinate);
  }
  return branch(desc_.workpiece.body, workpiece_point_, q_body,
                std::vector<double>(desc_.errors.size(), 0.0));
}

namespace {
// Position difference and rotation vector of `actual` against `nominal` (the outputs).
std::array<double, 6> relative(const Eigen::Matrix4d& actual, const Eigen::Matrix4d& nominal) {
  const Eigen::Vector3d dp = actual.block<3, 1>(0, 3) - nominal.block<3, 1>(0, 3);
  const Eigen::Matrix3d dr = actual.block<3, 3>(0, 0) * nominal.block<3, 3>(0, 0).transpose();
  const Eigen::AngleAxisd aa(dr);
  const Eigen::Vector3d w = aa.angle() * aa.axis();
  return {dp[0], dp[1], dp[2], w[0], w[1], w[2]};
}
}  // namespace

std::array<double, 6> NumericChain::deviation(const std::vector<double>& axes,
                                              const std::vector<double>& errors) const {
  const Eigen::Matrix4d actual = tool_in_workpiece(axes, errors);
  return relative(actual, nominal(axes));
}

Eigen::Matrix4d NumericChain::nominal(const std::vector<double>& axes) const {
  return tool_in_workpiece(axes, std::vector<double>(desc_.errors.size(), 0.0));
}

std::array<double, 6> NumericChain::deviation(const std::vector<double>& axes,
                                              const std::vector<double>& errors,
                                              const Eigen::Matrix4d& nominal) const {
  return relative(tool_in_workpiece(axes, errors), nominal);
}

void NumericChain::deviation_steps(const std::vector<double>& axes,
                                   const std::vector<double>& errors,
                                   const std::vector<double>& steps, const Eigen::Matrix4d& nominal,
                                   std::array<double, 6>& at,
                                   std::vector<std::array<double, 6>>& stepped) const {
  const std::size_t ne = desc_.errors.size();
  if (steps.size() != ne) throw std::invalid_argument("expected " + std::to_string(ne) + " steps");
  stepped.resize(ne);
  at = deviation(axes, errors, nominal);  // checks the sizes
  std::vector<double> e = errors;
  if (!linked_bodies_.empty() || desc_.output) {
    for (std::size_t k = 0; k < ne; ++k) {
      if (steps[k] == 0) continue;
      e[k] = errors[k] + steps[k];
      stepped[k] = deviation(axes, e, nominal);
      e[k] = errors[k];
    }
    return;
  }
  // A serial chain: each branch's products from the base, as branch() multiplies them, with
  // the partial product before every body kept; a step in an error of body b redoes b's
  // transform and the products from b on in every branch through b.
  std::vector<double> q_body(desc_.bodies.size(), 0.0);
  for (std::size_t k = 0; k < axis_bodies_.size(); ++k)
    q_body[static_cast<std::size_t>(axis_bodies_[k])] = axes[k];
  struct Branch {
    const std::vector<int>* path = nullptr;
    const Eigen::Vector3d* point = nullptr;
    std::vector<Eigen::Matrix4d> before;  // before[j]: the product of the first j transforms
    std::vector<Eigen::Matrix4d> body;    // the transforms at `errors`
    Eigen::Matrix4d frame;                // branch(): the whole product times Trans(point)
  };
  static const std::vector<int> kNoPath;
  auto make = [&](int end, const Eigen::Vector3d& point) {
    Branch br;
    br.path = end >= 0 && static_cast<std::size_t>(end) < paths_.size()
                  ? &paths_[static_cast<std::size_t>(end)]
                  : &kNoPath;
    br.point = &point;
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    for (int b : *br.path) {
      br.before.push_back(m);
      br.body.push_back(body_transform(b, q_body, errors));
      m = m * br.body.back();
    }
    br.frame = m * translation(point);
    return br;
  };
  const Branch work = make(desc_.workpiece.body, workpiece_point_);
  const Branch tool = make(desc_.tool.body, tool_point_);
  // The branch's frame with body b's transform replaced by `bt` (the branch's own if b is not
  // on it).
  auto restep = [](const Branch& br, int b, const Eigen::Matrix4d& bt) {
    const auto it = std::find(br.path->begin(), br.path->end(), b);
    if (it == br.path->end()) return br.frame;
    const auto j = static_cast<std::size_t>(it - br.path->begin());
    Eigen::Matrix4d m = br.before[j] * bt;
    for (std::size_t i = j + 1; i < br.body.size(); ++i) m = m * br.body[i];
    return Eigen::Matrix4d(m * translation(*br.point));
  };
  for (std::size_t k = 0; k < ne; ++k) {
    if (steps[k] == 0) continue;
    const int b = desc_.errors[k].body;
    e[k] = errors[k] + steps[k];
    const Eigen::Matrix4d bt = b >= 0 ? body_transform(b, q_body, e) : Eigen::Matrix4d::Identity();
    e[k] = errors[k];
    const Eigen::Matrix4d actual = rigid_inverse(restep(work, b, bt)) * restep(tool, b, bt);
    stepped[k] = relative(actual, nominal);
  }
}

Eigen::Matrix<double, 6, Eigen::Dynamic> NumericChain::nominal_jacobian(
    const std::vector<double>& axes) const {
  const std::vector<double> zero(desc_.errors.size(), 0.0);
  const double h = 1e-3;
  Eigen::Matrix<double, 6, Eigen::Dynamic> j(6, static_cast<Eigen::Index>(axes.size()));
  for (std::size_t a = 0; a < axes.size(); ++a) {
    std::vector<double> up = axes, down = axes;
    up[a] += h;
    down[a] -= h;
    const Eigen::Matrix4d tu = tool_in_workpiece(up, zero);
    const Eigen::Matrix4d td = tool_in_workpiece(down, zero);
    const Eigen::Matrix3d r = tu.block<3, 3>(0, 0) * td.block<3, 3>(0, 0).transpose();
    const auto col = static_cast<Eigen::Index>(a);
    j.block<3, 1>(0, col) = (tu.block<3, 1>(0, 3) - td.block<3, 1>(0, 3)) / (2 * h);
    j.block<3, 1>(3, col) =
        0.5 * Eigen::Vector3d(r(2, 1) - r(1, 2), r(0, 2) - r(2, 0), r(1, 0) - r(0, 1)) / (2 * h);
  }
  return j;
}

}  // namespace weilgen
