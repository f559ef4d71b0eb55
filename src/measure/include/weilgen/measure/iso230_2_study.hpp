// The whole ISO 230-2 evaluation of one axis of a measurement table: the axis and deviation
// columns, the normalisation to 20 °C and air compensation (optional, normalisation.hpp), the
// runs, the classical figures (k = 2 and Student-t), the drift seed's drift-eliminated
// evaluation (with at least 2 targets) and the verdicts against tolerances. What
// `weilgen iso230-2` computes.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "weilgen/measure/iso230_2.hpp"
#include "weilgen/measure/measurement_csv.hpp"
#include "weilgen/measure/normalisation.hpp"

namespace weilgen {

// Tolerances of an axis, in the deviation column's unit (µm, µrad): a band ±T for the deviation
// chart (every x̄_i ± 2 s_i of both directions within it) and limits of the axis figures.
struct IsoTolerance {
  std::optional<double> band;                           // T of ±T
  std::vector<std::pair<std::string, double>> figures;  // {"A", 12}, {"R_up", 5} ... in order
  bool empty() const { return !band && figures.empty(); }
};
// "10" (a band ±10), "A=12,R=6,B=4" (figure limits: B, B_mean, R_up, R_down, R, E_up, E_down,
// E, M, A_up, A_down, A), or both: "10,A=12". Limits > 0. Throws std::invalid_argument naming
// --tolerance.
IsoTolerance parse_iso_tolerance(const std::string& text);

// One verdict: a figure (or "band", the worst |x̄_i ± 2 s_i|) of the classical k = 2 set, its
// limit, and whether it holds (value <= limit; |B mean| for B_mean).
struct ToleranceCheck {
  std::string name;
  double value = 0, limit = 0;
  bool pass = false;
};
std::vector<ToleranceCheck> check_iso_tolerance(const IsoTolerance& tolerance,
                                                const IsoFigures& figures);

struct Iso230_2StudyOptions {
  std::string axis;    // coordinate column; empty: the '# axis:' key or the only candidate
  std::string column;  // deviation column; empty: the axis's (dx_um for X ...)
  double target_tolerance_mm = 1e-6;   // positions closer than this are the same target
  DriftOptions drift;                  // alpha, reference position and cycle
  NormalisationOptions normalisation;  // unset fields come from the file's header keys
  IsoTolerance tolerance;              // verdicts (none: no verdict)
  // alpha in (0, 1), a target tolerance > 0, the normalisation's constants in range
  // (std::invalid_argument naming the flag).
  void validate() const;
};

struct Iso230_2StudyResult {
  std::map<std::string, std::string> header_keys;  // of the data file: machine, date, operator ...
  IsoColumns columns;
  NormalisationResult normalisation;  // what was corrected (possibly nothing), from what
  IsoRuns runs;
  Iso230_2Result classical;
  std::optional<DriftResult> drift;       // none with fewer than 2 targets
  std::vector<ToleranceCheck> tolerance;  // empty without --tolerance
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
