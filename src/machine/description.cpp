#include "weilgen/machine/description.hpp"

#include <algorithm>
#include <cstdio>

namespace weilgen {
namespace {

std::string format_value(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

bool is_zero(const Expr& e) { return e.is_number() && e.number == 0.0; }

}  // namespace

bool Offset::is_identity() const {
  const bool no_rotation =
      std::all_of(rotations.begin(), rotations.end(),
                  [](const StaticRotation& r) { return is_zero(r.angle_deg); });
  return no_rotation && std::all_of(translation.begin(), translation.end(), is_zero);
}

std::string Distribution::str() const {
  switch (kind) {
    case Kind::None:
      return "none";
    case Kind::Normal:
      return "normal(" + format_value(a) + ", " + format_value(b) + ")";
    case Kind::Uniform:
      return "uniform(" + format_value(a) + ", " + format_value(b) + ")";
    case Kind::TruncatedNormal:
      return "truncnormal(" + format_value(a) + ", " + format_value(b) + ", " + format_value(lo) +
             ", " + format_value(hi) + ")";
  }
  return "none";
}

int Description::body_index(const std::string& body_name) const {
  for (size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].name == body_name) return static_cast<int>(i);
  }
  return -1;
}

int Description::error_index(const std::string& error_name) const {
  for (size_t i = 0; i < errors.size(); ++i) {
    const ErrorDef& e = errors[i];
    const bool alias = std::any_of(e.aliases.begin(), e.aliases.end(),
                                   [&](const Alias& a) { return a.name == error_name; });
    if (e.name == error_name || alias) return static_cast<int>(i);
  }
  return -1;
}

std::vector<int> Description::axes() const {
  std::vector<int> out;
  for (size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].joint.type != JointType::Fixed && !bodies[i].joint.link)
      out.push_back(static_cast<int>(i));
  }
  return out;
}

const Joint& Description::axis_joint(std::size_t axis) const {
  return bodies[static_cast<std::size_t>(axes()[axis])].joint;
}

std::vector<int> Description::linked_axes() const {
  std::vector<int> out;
  for (size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].joint.type != JointType::Fixed && bodies[i].joint.link)
      out.push_back(static_cast<int>(i));
  }
  return out;
}

int Description::coordinate_body(const std::string& coordinate) const {
  for (size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].joint.type != JointType::Fixed && bodies[i].joint.coordinate == coordinate)
      return static_cast<int>(i);
  }
  return -1;
}

std::vector<int> Description::chain_to(int b) const {
  std::vector<int> path;
  // The bound guards against a malformed (cyclic) hand-built description.
  const int n = static_cast<int>(bodies.size());
  for (int i = b; i >= 0 && i < n && static_cast<int>(path.size()) <= n; i = bodies[i].parent) {
    path.push_back(i);
  }
  std::reverse(path.begin(), path.end());
  return path;
}

std::map<std::string, double> Description::parameter_defaults() const {
  std::map<std::string, double> out;
  for (const Parameter& p : parameters) out[p.name] = p.value;
  return out;
}

const std::vector<std::string>& builtin_groups() {
  static const std::vector<std::string> groups = {
      "positioning", "straightness", "angular",  "radial",  "axial", "tilt",
      "squareness",  "parallelism",  "location", "thermal", "other"};
  return groups;
}

std::vector<std::string> error_names(const Description& desc) {
  std::vector<std::string> names;
  for (const ErrorDef& e : desc.errors) names.push_back(e.name);
  return names;
}

// Groups that have at least one error, in Description::groups order.
std::vector<std::string> used_groups(const Description& desc) {
  std::vector<std::string> groups;
  for (const std::string& g : desc.groups) {
    for (const ErrorDef& e : desc.errors) {
      if (e.group == g) {
        groups.push_back(g);
        break;
      }
    }
  }
  return groups;
}

}  // namespace weilgen
