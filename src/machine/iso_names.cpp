#include "weilgen/machine/iso_names.hpp"

#include <cmath>
#include <stdexcept>

namespace weilgen {
namespace {

constexpr char kTranslationLetters[] = "XYZ";
constexpr char kRotationLetters[] = "ABC";

// The parts of a name of the form E_<letter>[0]<coordinate>.
struct IsoParts {
  char letter = 0;  // X Y Z A B C
  int index = 0;    // 0 1 2 for x y z (A B C: about x y z)
  bool rotation = false;
  bool zero = false;  // the "0" of E_C0Y: a property of the axis line, not a motion error
  std::string coordinate;
};

bool is_identifier_start(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_';
}

bool split_iso_name(const std::string& name, IsoParts& parts) {
  if (name.size() < 4 || name.compare(0, 2, "E_") != 0) return false;
  const char c = name[2];
  for (int i = 0; i < 3; ++i) {
    if (c == kTranslationLetters[i] || c == kRotationLetters[i]) {
      parts.letter = c;
      parts.index = i;
      parts.rotation = c == kRotationLetters[i];
    }
  }
  if (parts.letter == 0) return false;
  size_t rest = 3;
  // A coordinate cannot start with a digit, so a 0 here is the axis-line marker.
  if (name[rest] == '0') {
    parts.zero = true;
    ++rest;
  }
  if (rest >= name.size() || !is_identifier_start(name[rest])) return false;
  parts.coordinate = name.substr(rest);
  return true;
}

Vec3 unit_vector(int index) {
  Vec3 v{0, 0, 0};
  v[static_cast<size_t>(index)] = 1;
  return v;
}

IsoMatch mismatch(std::string reason) {
  IsoMatch m;
  m.status = IsoMatch::Status::Mismatch;
  m.reason = std::move(reason);
  return m;
}

std::string motion_group(const IsoParts& p, JointType type, bool along_axis) {
  if (type == JointType::Prismatic) {
    if (p.rotation) return "angular";
    return along_axis ? "positioning" : "straightness";
  }
  if (p.rotation) return along_axis ? "positioning" : "tilt";
  return along_axis ? "axial" : "radial";
}

// Fills group/placement/dependence for E_<R>0K and E_<D>0K; returns a reason when meaningless.
std::string axis_line_error(const IsoParts& p, JointType type, bool along_axis, IsoError& e) {
  e.dependence = Dependence::PIGE;
  if (type == JointType::Prismatic) {
    if (along_axis) {
      return "a rotation about a linear axis' own direction has no meaning for a line";
    }
    if (!p.rotation) {
      return "a linear axis line has no location: translating it does not change the motion "
             "(use a straightness error E_<D>K or a custom error with placement: before)";
    }
    e.group = "squareness";
    e.placement = ErrorPlacement::Axis;
    return "";
  }
  if (along_axis) {
    // E_C0C (zero position) and E_Z0C (axial offset) commute with the rotation: a constant
    // offset of the body frame, before the motion.
    e.group = "location";
    e.placement = ErrorPlacement::Before;
  } else {
    e.group = p.rotation ? "squareness" : "location";
    e.placement = ErrorPlacement::Axis;
  }
  return "";
}

}  // namespace

int principal_axis(const Vec3& axis) {
  constexpr double kTol = 1e-12;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    if (std::abs(std::abs(axis[static_cast<size_t>(i)]) - 1) < kTol &&
        std::abs(axis[static_cast<size_t>(j)]) < kTol &&
        std::abs(axis[static_cast<size_t>(k)]) < kTol) {
      return i;
    }
  }
  return -1;
}

std::string iso_not_applicable(const Joint& joint) {
  if (joint.type == JointType::Fixed) {
    return "the body has no joint, so it has no ISO 230-1 motion errors";
  }
  if (principal_axis(joint.axis) < 0) {
    return "ISO 230-1 names need a joint axis along x, y or z, and joint " + joint.coordinate +
           " is skewed; define custom errors (effect, direction, group)";
  }
  return "";
}

IsoMatch match_iso_name(const Joint& joint, const std::string& name) {
  IsoParts p;
  if (!split_iso_name(name, p)) return {};
  if (std::string reason = iso_not_applicable(joint); !reason.empty()) return mismatch(reason);
  if (p.coordinate != joint.coordinate) {
    return mismatch("it names coordinate " + p.coordinate +
                    " but this body's joint coordinate is " + joint.coordinate);
  }
  const bool along_axis = p.index == principal_axis(joint.axis);
  IsoMatch m;
  m.status = IsoMatch::Status::Fits;
  IsoError& e = m.error;
  e.effect = p.rotation ? ErrorEffect::Rotation : ErrorEffect::Translation;
  e.direction = unit_vector(p.index);
  e.unit = p.rotation ? "urad" : "um";
  if (p.zero) {
    if (std::string reason = axis_line_error(p, joint.type, along_axis, e); !reason.empty()) {
      return mismatch(reason);
    }
  } else {
    e.group = motion_group(p, joint.type, along_axis);
    e.placement = ErrorPlacement::After;
    e.dependence = Dependence::PDGE;
  }
  return m;
}

std::vector<std::string> iso_motion_errors(const Joint& joint) {
  if (std::string reason = iso_not_applicable(joint); !reason.empty()) {
    throw std::invalid_argument(reason);
  }
  std::vector<std::string> names;
  for (const char* letters : {kTranslationLetters, kRotationLetters}) {
    for (int i = 0; i < 3; ++i) names.push_back(std::string("E_") + letters[i] + joint.coordinate);
  }
  return names;
}

}  // namespace weilgen
