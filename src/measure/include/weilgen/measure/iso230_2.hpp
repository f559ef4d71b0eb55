// ISO 230-2:2014 evaluation of the positioning accuracy and repeatability of one numerically
// controlled axis, and the thermal-drift elimination of Stejskal et al. (2017), "Elimination of
// thermal drift in measuring the positioning accuracy of a three axis milling machine" (the drift
// seed). Definitions, formulas, the anomaly criterion and the JSON schema of `weilgen iso230-2`:
// docs/iso230-2.md.
//
// Algorithm objects (Iso230_2Evaluation, DriftElimination) are separate from their results
// (IsoFigures, DriftResult): construct with the data and options, run(), read result().
// Deviations are in the deviation column's unit (um for a linear axis); positions in mm.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "weilgen/measure/measurement_csv.hpp"

namespace weilgen {

// ---- Data ------------------------------------------------------------------------------------

// One observation of a line run.
struct IsoObservation {
  double position_mm = 0;  // target position P_i
  int direction = +1;      // approach direction: +1 (up, positive) or -1 (down, negative)
  long cycle = 0;          // repetition j
  double deviation = 0;    // x_ij = actual - target (um)
  double time_s = std::numeric_limits<double>::quiet_NaN();  // optional
  int line = 0;    // 1-based source line (messages), 0 when not from a file
  int column = 0;  // 1-based source column of the deviation cell (messages), 0 when unknown
  std::size_t row = static_cast<std::size_t>(-1);  // the table row it was read from (if any)
};

// Index of a direction in the per-direction arrays: 0 = up (+1), 1 = down (-1).
constexpr int kUp = 0, kDown = 1;

// The runs of one axis, grouped: targets ascending, every target of a direction measured in the
// same cycles, the same targets in both directions.
struct IsoRuns {
  std::string file;                         // for messages
  std::vector<double> positions_mm;         // targets P_i, ascending (m of them)
  std::array<std::vector<long>, 2> cycles;  // per direction: cycle ids, ascending (n of them)
  std::array<std::vector<std::vector<double>>, 2> x;  // [d][i][j]: deviation
  std::array<std::vector<std::vector<double>>, 2> t;  // [d][i][j]: time (s); NaN when absent
  bool has_time = false;                              // every observation has a time
  std::size_t targets() const { return positions_mm.size(); }
};

// Groups observations: targets are position values equal within `tolerance_mm` (the target is
// their mean). Throws InputError (file:line) for: a (target, direction, cycle) observed twice,
// fewer than 2 cycles at a target in a direction, a target missing in one direction, cycles
// missing at some targets of a direction, no observations. Observations with a NaN deviation
// (blanks: an empty cell) count for nothing but locate a missing observation (file:line:column).
IsoRuns group_iso_runs(const std::vector<IsoObservation>& observations, const std::string& file,
                       double tolerance_mm = 1e-6);

// Which columns of a measurement table hold one axis' runs.
struct IsoColumns {
  std::string axis;       // coordinate column (mm)
  std::string direction;  // dir_<axis> when present, else dir
  std::string cycle;      // cycle
  std::string deviation;  // dx_um for X (and U), dy_um for Y (V), dz_um for Z (W),
                          // da_urad / db_urad / dc_urad for A / B / C
  std::string time;       // t_s or "" when absent
  std::string unit;       // the deviation column's unit: "um" or "urad"
};

// The deviation along an axis: dx_um for X (and U), dy_um for Y (V), dz_um for Z (W), da_urad,
// db_urad, dc_urad for A, B, C; "" for any other name.
std::string axis_deviation_column(const std::string& axis);

// Chooses the columns: `axis` given, else the header key `# axis:`, else the only coordinate
// column, else the only coordinate column whose values vary. `deviation_column` overrides the
// deviation column. Throws std::invalid_argument for a bad choice (--axis names no coordinate
// column) and InputError for a table that cannot hold ISO runs (missing columns).
IsoColumns iso_columns(const MeasurementTable& table, const std::string& axis = "",
                       const std::string& deviation_column = "");

// The observations of `columns`. A row whose deviation cell is empty is "not measured": a blank
// (NaN deviation, for group_iso_runs' messages) when it names target, direction and cycle, else
// skipped; an empty position, direction or cycle cell is an InputError naming its cell.
std::vector<IsoObservation> iso_observations(const MeasurementTable& table,
                                             const IsoColumns& columns);

// ---- Figures -----------------------------------------------------------------------------------

// The ISO 230-2 figures of a set of per-target unidirectional means and estimators, with the
// coverage factors k (2 in the standard; Student-t widened values for Stejskal et al. 2017's
// variant).
struct IsoFigures {
  double k_up = 2, k_down = 2;
  // Per target (ascending positions).
  std::vector<double> mean_up, mean_down;  // x̄_i↑, x̄_i↓
  std::vector<double> s_up, s_down;        // s_i↑, s_i↓
  std::vector<double> mean_bi;             // x̄_i = (x̄_i↑ + x̄_i↓)/2
  std::vector<double> B_i;                 // x̄_i↑ − x̄_i↓
  std::vector<double> R_i_up, R_i_down;    // 2k s_i↑, 2k s_i↓
  std::vector<double> R_i;                 // max(k s_i↑ + k s_i↓ + |B_i|, R_i↑, R_i↓)
  // Axis.
  double B = 0, B_mean = 0;            // max |B_i|, mean B_i
  double R_up = 0, R_down = 0, R = 0;  // max R_i↑, max R_i↓, max R_i
  double E_up = 0, E_down = 0, E = 0;  // systematic positional deviations
  double M = 0;                        // range of x̄_i
  double A_up = 0, A_down = 0, A = 0;  // accuracies
};

// The standard's formulas (docs/iso230-2.md). All vectors the same size >= 1.
IsoFigures iso_figures(const std::vector<double>& mean_up, const std::vector<double>& mean_down,
                       const std::vector<double>& s_up, const std::vector<double>& s_down,
                       double k_up = 2, double k_down = 2);

// The Student-t coverage factor that replaces k = 2 for an estimator with `dof` degrees of
// freedom: t_{p, dof} with p = Φ(2) = 0.97725 (the one-sided level of the normal k = 2, so the
// two-sided coverage 95.45 % is kept and k_t → 2 as dof → ∞). dof >= 1.
double student_coverage_factor(std::size_t dof, double k_normal = 2.0);

// ---- Classical evaluation --------------------------------------------------------------------

struct Iso230_2Options {
  double coverage = 2.0;  // k of the standard
  bool student = true;    // also compute the Student-t widened set
  void validate() const;  // coverage > 0 (std::invalid_argument)
};

struct Iso230_2Result {
  IsoFigures figures;                 // k = 2
  std::optional<IsoFigures> student;  // k = t_{Φ(2), n−1} per direction
};

class Iso230_2Evaluation {
 public:
  explicit Iso230_2Evaluation(Iso230_2Options options = {});  // validates the options
  const Iso230_2Options& options() const { return options_; }
  Iso230_2Result run(const IsoRuns& runs) const;

 private:
  Iso230_2Options options_;
};

// ---- Drift elimination (Stejskal et al. 2017)
// ----------------------------------------------------

struct DriftOptions {
  std::optional<double> reference_position_mm;  // default: the first (lowest) target
  std::optional<long> reference_cycle;          // default: the lowest cycle id of both directions
  double alpha = 0.01;  // family-wise false-positive rate of the anomaly test
  double coverage = 2.0;
  bool student = true;
  double tolerance_mm = 1e-6;  // to match reference_position_mm with a target
  // alpha in (0, 1), coverage > 0, tolerance_mm > 0 (std::invalid_argument naming the field).
  void validate() const;
};

// Adjacent-position differences of one direction: element q (q = 0..m−2) is the difference
// between targets q and q+1 (ascending), Δ_{q,j} = x_{q+1,j} − x_{q,j}, over the cycles j.
struct AdjacentDifferences {
  std::vector<double> mean;  // Δ̄_k (Stejskal et al. 2017, eq. (4), with the opposite sign)
  std::vector<double> s;     // sample standard deviation of Δ_{k,j} over j (n − 1)
  std::vector<double> sem;   // s / √n: Stejskal et al. 2017, eq. (6)
  // Anomaly test: F_q = s_q² / (mean of s_l² over the other differences l of the same parity
  // as q: they share no target with q), F(n−1, p(n−1)) under H0; p-value; flagged when
  // p < alpha / (number of tests of both directions).
  std::vector<double> F, p_value;  // NaN when not tested (no same-parity partner)
  std::vector<int> pool;           // p: number of differences pooled in the denominator
  std::vector<bool> flagged;
};

// The drift-eliminated chart of one direction.
struct DriftChart {
  std::vector<double> value;  // x̂_i: the reference value accumulated with the mean differences
  std::vector<double> s;      // s*_i = s_k/√2 of the difference that links i toward the
                              // reference (the reference takes its neighbour's)
  std::vector<double>
      s_diff;  // that s_k itself (Stejskal et al. 2017's ±2s band uses it: √2 wider)
  std::vector<std::vector<double>> shifted;  // [i][j]: x_ij − x_rj + x_{r,j0} (seed Fig. 13)
};

struct AnomalousDifference {
  int direction = +1;
  std::size_t from = 0, to = 0;  // target indices (0-based, to = from + 1)
  double s = 0, F = 0, p_value = 0;
};
struct AnomalousPosition {
  int direction = +1;
  std::size_t target = 0;  // 0-based
};

struct DriftPerCycle {
  std::vector<long> cycles;  // union of both directions' cycles, ascending
  // Offset of each cycle: the mean over targets of x_ij − x̄_i, relative to the reference
  // cycle's; NaN when the cycle is absent in that direction. `offset` averages the directions.
  std::vector<double> offset_up, offset_down, offset;
  std::vector<double> time_h;  // mean time of the cycle's observations (h from the first one);
                               // empty without times
  // Within-group least-squares slope of x against time (groups: target × direction) and its
  // standard error; NaN without times.
  double rate_per_h = std::numeric_limits<double>::quiet_NaN();
  double rate_per_h_se = std::numeric_limits<double>::quiet_NaN();
  // The same against the cycle id (per cycle).
  double rate_per_cycle = std::numeric_limits<double>::quiet_NaN();
  double rate_per_cycle_se = std::numeric_limits<double>::quiet_NaN();
};

struct DriftResult {
  std::size_t reference_target = 0;
  long reference_cycle = 0;
  std::array<AdjacentDifferences, 2> differences;  // [kUp], [kDown]
  std::array<DriftChart, 2> chart;
  IsoFigures figures;                 // from chart values and s*, k = 2
  std::optional<IsoFigures> student;  // k = t_{Φ(2), n−1}
  std::size_t tests = 0;              // anomaly tests performed (both directions)
  double alpha = 0.01;
  std::vector<AnomalousDifference> anomalous_differences;
  std::vector<AnomalousPosition> anomalous_positions;
  DriftPerCycle per_cycle;
  // Pooled s of the adjacent differences over pooled classical s, per direction (√2 without
  // drift: Stejskal et al. 2017, eq. (10); smaller when drift inflates the classical s).
  std::array<double, 2> s_ratio{};
};

class DriftElimination {
 public:
  explicit DriftElimination(DriftOptions options = {});  // validates the options
  const DriftOptions& options() const { return options_; }
  // Needs at least 2 targets (InputError otherwise). Throws std::invalid_argument when the
  // reference position or cycle is not in the data.
  DriftResult run(const IsoRuns& runs) const;

 private:
  DriftOptions options_;
};

// ---- Helpers ---------------------------------------------------------------------------------

// Sample mean and standard deviation (n − 1); NaN for n < 2 (s).
double sample_mean(const std::vector<double>& v);
double sample_sd(const std::vector<double>& v);

// Stejskal et al. 2017, eqs. (7)–(10): b_n = a_n − a_{n+1}; returns sd(b)/sd(a) (√2 for independent
// a_n).
double difference_sd_ratio(const std::vector<double>& a);

}  // namespace weilgen
