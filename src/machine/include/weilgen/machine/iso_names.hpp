// ISO 230-1 error names (E_XX, E_C0Y, E_X0C, ...) interpreted for a given joint, per the table in
// machines/README.md. Used by the YAML loader to fill in an error's effect, direction, group,
// placement, dependence and default unit from its name.
#pragma once

#include <string>
#include <vector>

#include "weilgen/machine/description.hpp"

namespace weilgen {

// What the ISO table says about one error of one joint.
struct IsoError {
  ErrorEffect effect = ErrorEffect::Translation;
  Vec3 direction{1, 0, 0};  // +x, +y or +z of the body frame
  std::string group;
  ErrorPlacement placement = ErrorPlacement::After;
  Dependence dependence = Dependence::PDGE;
  std::string unit;  // default unit: um for translations, urad for rotations
};

struct IsoMatch {
  enum class Status {
    NotIso,    // not of the form E_<letter>[0]<coordinate>: a custom name
    Fits,      // an ISO name for this joint; `error` is filled
    Mismatch,  // ISO-shaped but not meaningful for this joint; `reason` says why
  };
  Status status = Status::NotIso;
  IsoError error;
  std::string reason;
};

// 0, 1, 2 when `axis` is ±x, ±y, ±z; -1 for a skewed (or zero) axis.
int principal_axis(const Vec3& axis);

// Empty when ISO names apply to `joint` (a prismatic or revolute joint along ±x, ±y or ±z);
// otherwise the reason they do not.
std::string iso_not_applicable(const Joint& joint);

// Interprets `name` as an ISO 230-1 error name of `joint`.
IsoMatch match_iso_name(const Joint& joint, const std::string& name);

// The six ISO 230-1 motion errors of `joint` in the fixed order E_XK, E_YK, E_ZK, E_AK, E_BK,
// E_CK (K = the joint's coordinate). Throws std::invalid_argument (iso_not_applicable's reason)
// when ISO names do not apply.
std::vector<std::string> iso_motion_errors(const Joint& joint);

}  // namespace weilgen
