// How a LinuxCNC configuration's joints map to a model's axes (docs/controllers.md,
// machines/README.md "LinuxCNC"). LinuxCNC's joint positions (trivkins: joint N = axis letter N
// of `coordinates=`) are the tool's position relative to the workpiece, in the configuration's
// units; the model's axis coordinate is the position of the axis' own body. For each axis
//   model = offset + sign * scale * joint,   joint = (model - offset) / (sign * scale),
// and a correction maps back as d joint = sign * d model / scale. The defaults come from the
// machine description: an axis that carries the workpiece moves it the other way than the tool
// moves relative to it (sign -1), an axis that carries the tool has sign +1, and a joint axis
// written opposite to its letter (axis: -x for X) flips that; the `linuxcnc:` section or the
// flags of `weilgen linuxcnc` override sign, offset, letter, joint number and linear units.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "weilgen/machine/description.hpp"

namespace weilgen {

struct LinuxcncJoint {
  std::string coordinate;  // the model axis ("X", "Y231")
  std::size_t axis = 0;    // its index in Description::axes() (the model's kAxes order)
  char letter = 'X';       // LinuxCNC axis letter
  int joint = 0;           // LinuxCNC joint number
  int sign = 1;            // model = offset + sign * scale * joint
  double scale = 1;        // model axis units per LinuxCNC unit (25.4 for inch on a mm axis)
  double offset = 0;       // model coordinate at LinuxCNC's joint zero, model axis unit
  bool rotary = false;
  std::string unit;         // LinuxCNC's unit of the joint: mm, inch or deg
  std::string model_unit;   // the model axis' unit (mm, deg, ...)
  std::string sign_reason;  // why this sign: "carries the workpiece", "machine file", "--sign"
  double travel_min = 0, travel_max = 0;  // the model axis' range, model unit

  double to_model(double joint_position) const { return offset + sign * scale * joint_position; }
  double to_joint(double model_position) const {
    return (model_position - offset) / (sign * scale);
  }
};

struct LinuxcncMapping {
  std::vector<LinuxcncJoint> axes;  // model kAxes order
  std::string coordinates;          // trivkins coordinates=, letters in joint order ("XYZAC")
  int num_joints = 0;               // [KINS]JOINTS
  std::string linear_units = "mm";  // [TRAJ]LINEAR_UNITS
  // The joint of LinuxCNC joint number j (index into axes), -1 when none.
  int axis_of_joint(int j) const;
};

// What the flags of `weilgen linuxcnc` override: --units mm|inch, --sign X=-1, --offset X=250.
struct LinuxcncOverrides {
  std::string units;
  std::vector<std::pair<std::string, int>> signs;
  std::vector<std::pair<std::string, double>> offsets;
};

// Parses "X=-1,Y=1" (--sign) and "X=250,C=-90" (--offset); std::invalid_argument naming `flag`
// for an unknown axis, a sign other than 1 / -1, a value that is not a finite number.
std::vector<std::pair<std::string, int>> parse_linuxcnc_signs(const Description& desc,
                                                              const std::string& text);
std::vector<std::pair<std::string, double>> parse_linuxcnc_offsets(const Description& desc,
                                                                   const std::string& text);

// The mapping of every independent axis. Throws InputError at the `linuxcnc:` section for two
// axes with one letter or joint number, joint numbers with a gap, or an axis whose default
// letter cannot be chosen; std::invalid_argument for bad overrides (unknown units).
LinuxcncMapping linuxcnc_mapping(const Description& desc, const LinuxcncOverrides& overrides = {});

}  // namespace weilgen
