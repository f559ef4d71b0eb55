// Axis compensation tables of LinuxCNC (a joint's COMP_FILE): per nominal (commanded) position
// the deviation of the actual position, approached in the positive (forward) and the negative
// (reverse) direction, in machine units. From an ISO 230-2 evaluation here; from an identified
// model along one axis in analysis/axis_comp_table.hpp; written by report/comp_table_document.hpp.
//
// Sign convention (docs/controllers.md): a deviation is actual − commanded, as in ISO 230-2
// (x_ij = P_ij − P_i). LinuxCNC adds nominal − actual to the motor command (usrmotLoadComp:
// trim = nominal − forward for COMP_FILE_TYPE 0; motor = command + trim, control.c), so the
// machine, commanded P, is sent to P − x̄(P) and arrives at P to first order.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "weilgen/measure/iso230_2_study.hpp"

namespace weilgen {

// LinuxCNC keeps at most this many entries per joint (EMCMOT_COMP_SIZE, motion.h).
constexpr std::size_t kMaxCompEntries = 256;

struct CompTable {
  std::string axis;             // the axis (messages, comments)
  std::string unit;             // machine units of every column: "mm", "inch" or "deg"
  int joint = -1;               // the LinuxCNC joint when known (a model's table), else -1
  std::vector<double> nominal;  // commanded positions, strictly ascending
  std::vector<double> forward;  // actual − nominal approached in + direction
  std::vector<double> reverse;  // actual − nominal approached in − direction
  // 1..kMaxCompEntries entries, equal sizes, finite values, nominal strictly ascending; throws
  // std::invalid_argument saying which.
  void validate() const;
};

struct CompTableOptions {
  int type = 0;  // COMP_FILE_TYPE: 0 nominal, forward, reverse positions; 1 nominal and trims
  std::string linear_unit = "mm";  // a linear axis' machine units: "mm" or "inch"
  // Which ISO 230-2 means (comp_table_from_iso): "classical" (the standard's x̄↑, x̄↓) or "drift"
  // (the drift-eliminated chart: the machine in the reference cycle's thermal state).
  std::string source = "classical";
  // type 0 or 1, linear_unit mm or inch, source classical or drift (std::invalid_argument
  // naming --comp-type, --comp-units, --comp-source).
  void validate() const;
};

// A length in mm, or an angle in deg, in the machine units of `options` ("deg" for an angle).
double to_machine_units(double value_mm_or_deg, bool rotary, const CompTableOptions& options);
std::string machine_unit(bool rotary, const CompTableOptions& options);

// The table of an evaluated ISO 230-2 run: the targets, forward = x̄↑, reverse = x̄↓ (µm → mm,
// µrad → deg), in machine units. Throws std::invalid_argument for source "drift" without a drift
// evaluation (fewer than 2 targets) and for a table validate() refuses (more than 256 targets).
CompTable comp_table_from_iso(const Iso230_2StudyResult& result, const CompTableOptions& options);

}  // namespace weilgen
