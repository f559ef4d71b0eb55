// The whole ISO 230-2 evaluation of one axis of a measurement table: the axis and deviation
// columns, the normalisation to 20 °C and air compensation (optional, normalisation.hpp), the
// runs, the classical figures (k = 2 and Student-t), Stejskal et al. 2017's drift-eliminated
// evaluation (with at least 2 targets) and the verdicts against tolerances. What
// `weilgen iso230-2` computes.
#pragma once

#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "weilgen/measure/iso230_2.hpp"
#include "weilgen/measure/iso230_2_uncertainty.hpp"
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

// The decision rule of ISO 14253-1 for an upper limit: conformance is proven when the value plus
// its expanded uncertainty U is within the limit, non-conformance when the value minus U is
// beyond it, and neither is proven in between. Without U the value is compared as it is.
enum class Decision { Conforms, DoesNotConform, NotProven };
const char* to_string(Decision decision);  // "conforms", "does not conform", "not proven"

// One verdict: a figure (or "band", the worst |x̄_i ± 2 s_i|) of the classical k = 2 set, its
// limit, and whether it holds (value <= limit; |B mean| for B_mean).
struct ToleranceCheck {
  std::string name;
  double value = 0, limit = 0;
  bool pass = false;  // value <= limit
  // The expanded uncertainty of the value (weilgen/measure/iso230_2_uncertainty.hpp); NaN
  // without an uncertainty budget.
  double U = std::numeric_limits<double>::quiet_NaN();
  Decision decision = Decision::DoesNotConform;
};
std::vector<ToleranceCheck> check_iso_tolerance(const IsoTolerance& tolerance,
                                                const IsoFigures& figures);

// A test condition of ISO 230-2:2014 the run does not meet (docs/iso230-2.md, "Conformance"):
// check "targets" (at least 5, and 5 per metre up to 2000 mm of travel, one per 250 mm beyond),
// "cycles" (5 in each direction), "bidirectional", "air" (the refractive index not compensated,
// about 271 um/m) or "temperature" (no material temperature and no normalisation: the nominal
// differential expansion is neither corrected nor stated).
struct ConformanceIssue {
  std::string check;
  std::string message;  // one sentence, ASCII units
};
std::vector<ConformanceIssue> iso230_2_conformance(const IsoRuns& runs, const IsoColumns& columns,
                                                   const NormalisationResult& normalisation);

struct Iso230_2StudyOptions {
  std::string axis;    // coordinate column; empty: the '# axis:' key or the only candidate
  std::string column;  // deviation column; empty: the axis's (dx_um for X ...)
  double target_tolerance_mm = 1e-6;   // positions closer than this are the same target
  DriftOptions drift;                  // alpha, reference position and cycle
  NormalisationOptions normalisation;  // unset fields come from the file's header keys
  IsoTolerance tolerance;              // verdicts (none: no verdict)
  // Only the figures ISO 230-2 defines: no Student-t set and no drift elimination (--iso-only).
  bool iso_only = false;
  // The uncertainty budget (--uncertainty); none: no uncertainty, tolerances compared as they are.
  std::optional<UncertaintyBudget> uncertainty;
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
  std::optional<DriftResult> drift;              // none with fewer than 2 targets
  std::optional<UncertaintyResult> uncertainty;  // with a budget
  std::vector<ToleranceCheck> tolerance;         // empty without --tolerance
  std::vector<ConformanceIssue> conformance;     // empty: the run meets ISO 230-2's conditions
  bool iso_only = false;                         // no Student-t set, no drift elimination
  // The overall decision on the tolerances (meaningful with checks): does not conform when one
  // check does not, else not proven when one is not or the air is not compensated, else
  // conforms; `verdict_reason` says why it is not proven.
  Decision verdict = Decision::Conforms;
  std::string verdict_reason;
  bool iso_conforming() const { return conformance.empty(); }
};

// The overall decision of `checks` (ISO 14253-1 per check when U is known) and, with the air not
// compensated, "not proven" whatever the figures say. Sets each check's decision.
void decide_iso_tolerance(Iso230_2StudyResult& result);

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
