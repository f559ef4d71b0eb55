// The whole ISO 230-2 evaluation of one axis of a measurement table: the axis and deviation
// columns, the runs, the classical figures (k = 2 and Student-t) and, with at least 2 targets,
// the drift seed's drift-eliminated evaluation. What `weilgen iso230-2` computes.
#pragma once

#include <optional>
#include <string>

#include "weilgen/measure/iso230_2.hpp"
#include "weilgen/measure/measurement_csv.hpp"

namespace weilgen {

struct Iso230_2StudyOptions {
  std::string axis;    // coordinate column; empty: the '# axis:' key or the only candidate
  std::string column;  // deviation column; empty: the axis's (dx_um for X ...)
  double target_tolerance_mm = 1e-6;  // positions closer than this are the same target
  DriftOptions drift;                 // alpha, reference position and cycle
  // alpha in (0, 1) and a target tolerance > 0 (std::invalid_argument naming the flag).
  void validate() const;
};

struct Iso230_2StudyResult {
  IsoColumns columns;
  IsoRuns runs;
  Iso230_2Result classical;
  std::optional<DriftResult> drift;  // none with fewer than 2 targets
};

class Iso230_2Study {
 public:
  explicit Iso230_2Study(Iso230_2StudyOptions options);  // validates the options
  const Iso230_2StudyOptions& options() const { return options_; }
  // InputError for unusable data; std::invalid_argument for a reference position or cycle with
  // fewer than 2 targets or not in the data.
  Iso230_2StudyResult run(const MeasurementTable& table) const;

 private:
  Iso230_2StudyOptions options_;
};

}  // namespace weilgen
