// A LinuxCNC axis compensation table from an identified model (`weilgen identify ... --comp-table
// F --axis X`): along one axis, the model's deviation at the identified errors, expressed as the
// axis' own positioning deviation, at evenly spaced positions with the other axes fixed.
//
// At a pose q the model predicts the tool's deviation d(q, e(q)) (workpiece frame). A joint
// compensation can only move the axis itself, so the table holds the axis displacement that the
// nominal kinematics turns into the same deviation along the axis' motion: for a linear axis
// δ = j·dp / |j|² with j the position column of the nominal Jacobian (mm per mm), for a rotary
// axis the same with the orientation column and the rotation deviation (deg). For an ISO 230-1
// positioning error such as E_XX of a linear axis, δ is that error: the table is what an ISO
// 230-2 measurement along the axis would evaluate to (actual − commanded, measure/comp_table.hpp).
// The model has no reversal error: forward = reverse. The table is in LinuxCNC's joint
// coordinates (machine/linuxcnc.hpp: the tool relative to the workpiece, the machine file's
// `linuxcnc:` signs and offsets, --comp-units): on an axis that carries the workpiece (sign -1)
// the joint position is minus the model's and so is the deviation, entries ascending in the
// joint position.
#pragma once

#include <string>
#include <vector>

#include "weilgen/analysis/identify.hpp"
#include "weilgen/base/output_paths.hpp"
#include "weilgen/measure/comp_table.hpp"
#include "weilgen/model/model.hpp"

namespace weilgen {

struct AxisCompTableOptions {
  std::string axis;         // the model coordinate the table runs along (--axis)
  std::size_t points = 41;  // evenly spaced over the axis' range, 2..kMaxCompEntries
  // The other axes, "Y=-200,Z=-150" in the --at grammar (docs/study-inputs.md); an axis not
  // named takes 0 when 0 is within its range, else it must be given.
  std::string at;
  CompTableOptions table;  // machine units (--comp-units); type is the writer's
  // axis given, 2 <= points <= 256, table options (std::invalid_argument naming the flag).
  void validate() const;
};

// The table flags of a verb before any work, for every front end: without a table (`path`
// empty) each flag in `given` (written "--comp-type" ...) is refused as needing --comp-table;
// with one, the options valid (all of them with `model_axis`, `identify`'s table; else the
// table options, `iso230-2`'s) and `path` none of `inputs` (std::invalid_argument naming the
// flag).
void check_comp_table_flags(const std::string& path, const AxisCompTableOptions& options,
                            const std::vector<std::string>& given,
                            const std::vector<PathArg>& inputs, bool model_axis);

// Checks the options against the machine before any work: validate(), the axis a coordinate
// of the model with a finite range, --comp-at naming the other axes within their ranges
// (std::invalid_argument naming the flag).
void check_axis_comp_table(const Description& desc, const AxisCompTableOptions& options);

// The table along options.axis with the errors of `theta` (param.errors_at). Throws
// std::invalid_argument for an unknown axis, an axis without a finite range, or a bad --comp-at.
CompTable axis_comp_table(const Model& model, const ErrorParameterisation& param,
                          const std::vector<double>& theta, const AxisCompTableOptions& options);

}  // namespace weilgen
