// A ballbar trace evaluated on its own (ISO 230-4 and the usual ballbar diagnosis): no machine
// model, only the traces. The ISO 230-4 figures per run (circular deviation G with the
// least-squares and the minimum-zone centre, radial deviation F, centre offset, radius
// deviation) and the circular hysteresis H between the directions; and the causes a ballbar
// shows, fitted jointly by least squares on every run: backlash, reversal spikes, lateral play
// and cyclic error per axis, servo mismatch, squareness, straightness per axis, scale mismatch —
// each with its size, standard error, significance and contribution to the trace, ranked.
// Models of the causes, their sign conventions and the recovery proof: docs/ballbar.md,
// "weilgen ballbar".
//
// The axes are the plane's first and second coordinates (θ from the first toward the second).
// Each cause is an error of an axis along its own motion (d1 along the first, d2 along the
// second, µm), which the ballbar sees as dr = d1 cos θ + d2 sin θ whatever the machine's
// kinematics (the motions are orthonormal, ballbar.hpp). dir1, dir2: each axis' direction of
// travel at the point (ballbar_travel_direction).
#pragma once

#include <array>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "weilgen/measure/ballbar.hpp"

namespace weilgen {

struct BallbarDiagnosisOptions {
  // Family-wise false-positive rate of the significance tests (Bonferroni over the causes and,
  // for a cause with a searched width or pitch, over its grid): a trace of noise reads clean
  // with probability 1 − alpha.
  double alpha = 0.01;
  // A significant cause is reported only when its contribution (max − min of its part of dr)
  // is at least this (µm): sizes below it are beyond what a ballbar test resolves.
  double min_contribution_um = 0.05;
  int max_harmonic = 4;  // of the ISO 230-4 evaluation's harmonics (ballbar.hpp)
  // alpha in (0, 1), min_contribution_um >= 0, max_harmonic >= 1 (std::invalid_argument).
  void validate() const;
};

struct BallbarDiagnosisInput {
  std::vector<BallbarTrace> traces;  // one per run (direction and cycle)
  double radius_mm = 0;
  std::string first = "X", second = "Y";  // the plane's coordinates, for names
  double feedrate_mm_min = std::numeric_limits<double>::quiet_NaN();  // servo mismatch in ms
};

// One run's ISO 230-4 figures.
struct BallbarRun {
  int feed = 1, cycle = 0;
  BallbarEvaluation evaluation;  // G (LSQ and minimum zone), F, centre, radius, harmonics
};

// One cause, fitted on every run at once.
struct BallbarCause {
  std::string id;    // "backlash_X", "reversal_spike_Y", "squareness", "cyclic_X" ...
  std::string name;  // "backlash X", "squareness XY" ...
  std::string axis;  // "X", "Y" or "" (a cause of the pair)
  double size = 0;   // the cause's value in `unit`, signed (docs/ballbar.md: sign conventions)
  double se = std::numeric_limits<double>::quiet_NaN();  // its standard error
  std::string unit;                                      // "um", "urad", "um/m"
  // A second figure where the cause has one: the spike's width (deg), the cyclic error's pitch
  // (mm), the servo mismatch's time lag (ms, with a feedrate); NaN otherwise.
  double detail = std::numeric_limits<double>::quiet_NaN();
  std::string detail_name, detail_unit;  // "width", "deg"; "pitch", "mm"; "lag", "ms"
  double contribution_um = 0;  // max − min of the cause's fitted part of dr over the runs
  double p_value = 1;          // partial F test, the cause against the full model without it
  double threshold_p = 0;      // alpha over the tests (Bonferroni, grids counted)
  bool significant = false;    // p < threshold and contribution >= min_contribution_um
  bool separable = true;       // false: the runs cannot tell it from the others (not fitted)
  std::string note;            // why it is not separable, or what its size means
};

struct BallbarDiagnosisResult {
  std::vector<BallbarRun> runs;
  // H between the first ccw and the first cw run (ISO 230-4's circular hysteresis, µm); NaN
  // with one direction.
  double hysteresis_um = std::numeric_limits<double>::quiet_NaN();
  std::vector<BallbarCause> causes;  // every cause, ranked: significant first by contribution
  double residual_rms_um = 0;        // of the full model: the noise the tests measure against
  std::size_t points = 0, parameters = 0;
  double alpha = 0.01;
  bool clean() const;  // no significant cause
  // The fitted model and the residual at every point of every run (run order, point order).
  std::vector<std::vector<double>> fitted_um, residual_um;
};

class BallbarDiagnosis {
 public:
  explicit BallbarDiagnosis(BallbarDiagnosisOptions options = {});  // validates
  const BallbarDiagnosisOptions& options() const { return options_; }
  // std::invalid_argument for no runs, a radius <= 0 or a run with fewer than 8 distinct
  // angles. A partial arc is diagnosed for what it shows: a cause its arc cannot separate from
  // the others is reported as not separable.
  BallbarDiagnosisResult run(const BallbarDiagnosisInput& input) const;

 private:
  BallbarDiagnosisOptions options_;
};

}  // namespace weilgen
