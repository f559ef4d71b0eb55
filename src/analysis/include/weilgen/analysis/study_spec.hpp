// The study inputs: where to evaluate a machine (poses), what tolerances apply to its outputs, and
// how its errors are distributed. Parsed from command-line flags (--at, --grid, --tolerance,
// --set) and tolerance files (tolerance_file.hpp); the grammar is in docs/study-inputs.md.
//
// Every parse error throws std::invalid_argument (flags) or InputError (files, "file:line:col:")
// with one line naming the flag or file, the offending text and what was expected, e.g.
//   --grid: "X=0:1000:0": count must be >= 1
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "weilgen/base/units.hpp"
#include "weilgen/machine/description.hpp"
#include "weilgen/machine/outputs.hpp"
#include "weilgen/uq/distribution.hpp"

namespace weilgen {

// ---- Poses -----------------------------------------------------------------------------------

// --at "X=0,Y=1500,Z=600" (repeatable, one pose each) and --grid "X=0:1000:5,Y=0,Z=600:1400:5"
// (each axis a value or start:stop:count, count >= 1 evenly spaced values from start to stop,
// count 1 = start; at most one --grid). Axis names are the machine's coordinates; values are in
// the axis unit (the joint's `unit`: mm or deg for the shipped machines) unless a unit is written
// ("Y=1.5m", "A=0.5rad"); each value must lie within the axis range when the machine file gives
// one. --at names every axis (an axis left out is an error naming it); in --grid an axis not
// named takes 0 when 0 is within its range, else it must be given.
// The grid is the Cartesian product in the order the axes are written, the LAST written axis
// varying fastest; grid poses come first, then the --at poses. No poses at all is an error.
struct PoseSet {
  std::vector<std::string> axes;           // Description::axes() coordinate names, in that order
  std::vector<std::string> units;          // each axis's unit (Joint::unit: "mm", "deg", ...)
  std::vector<std::vector<double>> poses;  // each: values for all axes (axis units), axes order
  // Indices (into axes) of the grid axes with more than one value, in written order, and the
  // values of each. poses[0 .. grid size) are the grid, in row-major order over grid_axes.
  std::vector<std::size_t> grid_axes;
  std::vector<std::vector<double>> grid_values;
  std::size_t grid_size() const;  // number of grid poses (0 without --grid)
};
PoseSet parse_poses(const Description& desc, const std::vector<std::string>& at,
                    const std::vector<std::string>& grid);

// One flag of --grid items without their product: each named axis (index into
// Description::axes()) with its values in the axis unit (a value, or start:stop:count), checked
// as --grid checks them; `flag` names the flag in messages ("--candidates").
std::vector<std::pair<std::size_t, std::vector<double>>> parse_axis_values(const Description& desc,
                                                                           const std::string& flag,
                                                                           const std::string& text);

// Most poses a grid may have (the product of its counts).
constexpr std::size_t kMaxGridPoses = 10'000'000;

// ---- Outputs and tolerances -------------------------------------------------------------------

// --tolerance "dx=0.03mm" (repeatable, or comma-separated "dx=0.03mm,dy=30um"); value > 0, default
// unit mm for positions (dx, dy, dz, dp) and rad for orientations (da, db, dc); a length unit on an
// orientation or an angle unit on a position is an error, as is an output given twice.
struct OutputTolerance {
  OutputId output;
  double value;      // base units (mm or rad)
  std::string text;  // the value as written ("0.03mm")
};
std::vector<OutputTolerance> parse_tolerances(const std::vector<std::string>& flags);

// ---- Error distributions ----------------------------------------------------------------------

// The distribution of every error in BASE units (mm, rad), in Description::errors order: the
// machine file's (ErrorDef::distribution * to_base), then the tolerance files in order, then the
// --set flags in order, each overriding what came before:
//   --set "E_XX=sigma:5um" | "E_XX=normal:0,0.005mm" | "E_XX=uniform:-0.01,0.01mm"
//       | "E_XX=truncnormal:0,0.005,-0.01,0.01mm" | "E_XX=const:2um"
// NAME is an error name, an alias (a sign -1 alias negates: the distribution is the alias's) or
// "group:<group>" (every error of the group). A number without a unit takes the unit written after
// the last number, else the error's declared unit. An error left without a distribution is an
// error ("E_XX has no distribution: give one in the machine file, a tolerance file or --set").
std::vector<InputDistribution> error_distributions(const Description& desc,
                                                   const std::vector<std::string>& tolerance_files,
                                                   const std::vector<std::string>& set_flags);

// The errors a name selects in --set, identify --fix, ...: an error name, an alias (with the
// alias's sign), "group:<group>" (every error of the group, sign +1) or "axis:<axis>" (every
// error of the body the axis moves, sign +1). Throws
// std::invalid_argument "<context>: unknown error ..." / "no errors in group ..." naming the
// machine's errors or groups.
struct ErrorTarget {
  std::size_t error = 0;  // index into Description::errors
  int sign = 1;
};
std::vector<ErrorTarget> select_errors(const Description& desc, const std::string& name,
                                       const std::string& context);

// One --set flag applied to `dists` (Description::errors order, base units; empty = none yet).
void apply_set_flag(const Description& desc, const std::string& flag,
                    std::vector<std::optional<InputDistribution>>& dists);

// The machine file's distribution of error i in base units (nullopt when it has none).
std::optional<InputDistribution> machine_distribution(const ErrorDef& err);

}  // namespace weilgen
