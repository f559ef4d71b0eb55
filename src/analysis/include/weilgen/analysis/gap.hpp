// Sim-to-real gap diagnosis (issue 6, docs/gap.md): identify the model on training data, predict
// held-out data, localise the held-out residual against the noise floor, and rank candidate
// unmodelled effects (each a parametrised augmentation of the linear model) by held-out
// improvement with a significance test that accounts for the extra parameters.
//
// Everything is linear least squares around the identified first-order model: the baseline
// design matrix A (identify.hpp) and, per effect, extra columns E. Per fold the SVD of A_train is
// computed once; an effect's columns are fitted on the baseline's training residual after
// projecting out A's column space, which is exactly the joint least-squares fit [A E].
#pragma once

#include <array>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "weilgen/analysis/identify.hpp"
#include "weilgen/measure/ballbar.hpp"
#include "weilgen/measure/measurement_csv.hpp"
#include "weilgen/model/model.hpp"

namespace weilgen {

// The measurement table as the diagnosis sees it: point observations plus, per table row, the
// covariates that candidate effects and the localisation use.
struct GapData {
  PointData points;                                // poses per row, observations
  std::vector<std::string> axes;                   // coordinate names (Description::axes())
  std::vector<std::string> axis_units;             // each coordinate's unit (mm, deg)
  std::vector<double> time_s;                      // per row; NaN when absent
  std::vector<double> cycle;                       // per row; NaN when absent
  std::map<std::string, std::vector<double>> dir;  // axis -> ±1 per row (dir or dir_<axis>)
  // The axes whose `dir` a ballbar trace's angle and feed gave (ballbar_travel_direction), not
  // a column.
  std::vector<std::string> derived_dir;
  std::map<std::string, std::vector<double>> temperature;  // T_<name> -> °C per row
  std::map<std::string, std::vector<double>> covariate;    // rpm, ... per row
  // Each covariate's unit as the measurement reader classifies its column (classify_column:
  // rpm 1/min, angle_deg deg, feed_mm_min mm/min); "" for none (a trace's feed direction).
  std::map<std::string, std::string> covariate_unit;
  std::vector<std::string> fixed_axes;  // coordinates not in the table, taken from `fixed`
  std::optional<BallbarCircle> circle;  // a ballbar trace: its circle (observations are dr)
};

// Reads a table. Coordinates missing from the table take `fixed` values (mm, deg; else
// InputError naming the missing column). InputError for: no deviation column, NaN coordinates,
// a covariate or temperature column that is constant (it cannot explain anything), fewer than
// 10 observations.
//
// A ballbar trace (a dr_um column; docs/data-format.md) gives one dr observation per row with a
// measured dr_um: the pose is the circle's at angle_deg (axis columns, if present, are not
// read), the circle comes from the `# plane/centre/radius/feed` keys with `ballbar` flags
// overriding, and the nominal kinematics from the machine with `parameters` (empty: defaults).
// A `dir` column there is the feed direction (covariate `feed`); `angle_deg` is a covariate.
GapData gap_data(const MeasurementTable& table, const Description& desc,
                 const std::map<std::string, double>& fixed = {}, const BallbarFlags& ballbar = {},
                 const std::vector<double>& parameters = {});

// --at NAME=VALUE items (mm, deg; units allowed): the coordinates the data do not list.
// std::invalid_argument naming --at for a bad item or an unknown coordinate.
std::map<std::string, double> parse_fixed_coordinates(const Description& desc,
                                                      const std::vector<std::string>& at);

// How observations are split into training and held-out parts (no observation in both parts of
// one split; every observation held out exactly once over the splits, except `forward`).
struct HoldoutScheme {
  enum class Kind { Cycle, Time, Space, Forward };
  Kind kind = Kind::Cycle;
  int folds = 5;            // Cycle/Time/Space: k-fold over groups (cycles, time blocks, spatial
                            // blocks along `axis`)
  std::string axis;         // Space: the coordinate (default: the one with most distinct values)
  double fraction = 0.7;    // Forward: train on the earliest fraction of time, hold out the rest
  std::string str() const;  // "cycle:5", "time:5", "space:X:5", "forward:0.7"
};

// Parses "cycle[:K]", "time[:K]", "space[:AXIS][:K]", "forward[:FRACTION]" or "auto" (nullopt).
// Throws std::invalid_argument.
std::optional<HoldoutScheme> parse_holdout(const std::string& text);

// The default from the columns present: cycle (>= 3 cycles), else time (t_s), else space.
HoldoutScheme default_holdout(const GapData& data);

struct Split {
  std::vector<std::size_t> train, test;  // observation indices
};
// Throws InputError when the data are too few for the scheme (a fold with < 3 held-out or the
// training part with fewer observations than baseline parameters + 5).
std::vector<Split> make_splits(const GapData& data, const HoldoutScheme& scheme,
                               std::size_t min_train);

struct NoiseFloor {
  double sigma_um = 0;  // pooled over outputs (µm or µrad as measured)
  std::array<double, kObservationKinds> per_output{};  // NaN where not measured
  double dof = 0;      // degrees of freedom of sigma² (for the F tests)
  std::string source;  // "repeats" or "small-scale"
  std::string detail;  // "412 successive differences of repeated poses"
};

// Where the held-out residual concentrates: a whole output (by "output"), or the worst region
// of one dimension (a coordinate, t_s, a direction, cycle, a temperature, a covariate) of one
// output. A dimension's p-value is the F test of its bins (between-bin against within-bin
// variance of the held-out residual, Bonferroni over every dimension and output tested) and
// `explained` the share of the residual's variation its bins explain: dimensions are ranked by
// it; the region is the dimension's worst bin, widened over neighbours nearly as bad.
struct GapRegion {
  std::string by;      // "output", a coordinate, "t_s", "dir_X", "cycle", "T_3", "rpm"
  std::string output;  // dx ... dc, dr
  std::string unit;    // of from/to: the coordinate's (mm, deg), s, °C, 1/min; "" else
  std::vector<std::string> same_as;  // dimensions with the very same bins (dir_Y = dir_X ...)
  double from = 0, to = 0;           // the region's range in `unit` (output: 0..0)
  std::size_t n = 0;
  double rms_um = 0, excess_um = 0, p_value = 1;
  double explained = 0;  // between-bin share of the residual's sum of squares (dimensions)
  bool significant = false;
  std::string source = "residual";  // "residual", or "effect": an accepted effect's own region
};

struct EffectFit {
  std::string name;     // thermal_drift, reversal, periodic, pdge_shape, higher_order,
                        // missing_error, tool_offset, setup
  std::string variant;  // "time lag tau 1.5 h", "X", "E_B0Z" ...
  std::string summary;  // physical units: "reversal 4.1 µm on X (dx)"
  std::map<std::string, double> params;  // named numbers in physical units
  std::optional<GapRegion> region;       // where along which coordinate, when the effect says
  std::size_t extra_parameters = 0;
  double tested_variants = 1;  // the multiplicity the p-value is corrected for
  double heldout_rms_before_um = 0, heldout_rms_after_um = 0, shrink_pct = 0;
  std::array<double, kObservationKinds> rms_before{}, rms_after{};  // held-out per output
  double f_statistic = 0, p_value = 1;  // training nested-model test, corrected
  bool significant = false;
  double explained_fraction = 0;  // of the held-out excess variance over the noise floor
  // Shapes along one coordinate (periodic, pdge_shape): the shape degrees of freedom the data
  // leave there beyond the model (distinct positions in this output, less what the model
  // absorbs) and those the effect uses (columns plus refined hyper-parameters, with the shapes
  // accepted before it along the same coordinate and output). When it uses them all it fits any
  // shape — a step as well as a bump — and the verdict cannot name it.
  std::size_t shape_dof_free = 0, shape_dof_used = 0;
  // False also for a bump over fewer than 3 sample positions (it cannot be told from a step).
  bool distinguishable = true;
  std::string indistinct_reason;  // why not, one clause
  // Shapes of several terms (a missing PDGE): the combinations of the terms that the model's own
  // errors absorb (less than 10 % of the shape's RMS outside the model's span), so the data do
  // not determine them; the reported size is that of the rest. All of them: size not determined.
  std::size_t terms = 0, terms_absorbed = 0;
};

// A gross reading: far outside the spread of the baseline's residual and unlike its neighbours
// (the observations nearest in the pose space, same output), so no smooth effect explains it.
// Removed before the diagnosis and reported.
struct GapOutlier {
  std::size_t observation = 0;  // index into GapData::points.observations
  int line = 0;                 // source line of its row
  std::string output;           // dx ... dc, dr
  double value_um = 0;          // as measured (µm, µrad)
  double residual_um = 0;       // from the baseline fitted on all data
  double sigmas = 0;            // |residual| / the robust spread of its output
};

// The held-out residual summarised, before or after the accepted effects.
struct HeldoutSummary {
  std::array<double, kObservationKinds> rms{}, max{};  // per output (µm, µrad); NaN: not measured
  double rms_um = 0;                                   // over every held-out residual
  // Over the noise floor, on the part of the held-out residual the folds can predict: the excess
  // RMS and the F test's p-value.
  double excess_um = 0, p_value = 1;
  // The held-out RMS a right model would leave: floor · sqrt(mean(1 + h)) over the held-out
  // residuals, h their held-out leverage (prediction error of the folds included), per output and
  // over all.
  std::array<double, kObservationKinds> ideal{};
  double ideal_um = 0;
};

// The verdict: no gap, an effect of the library, or a gap the library does not explain.
struct GapVerdict {
  enum class Kind { None, Effect, Unexplained };
  Kind kind = Kind::None;
  std::string effect;       // Kind::Effect: the effect's name
  std::string reason;       // one sentence: why this verdict
  std::string str() const;  // "none", "unexplained" or the effect's name
  bool names(const std::string& name) const { return kind == Kind::Effect && effect == name; }
};

struct GapResult {
  std::vector<GapOutlier> outliers;  // removed before everything below
  std::string holdout;               // the scheme used
  std::string holdout_reason;        // why (default choice) or "given"
  std::size_t observations = 0, parameters = 0, rank = 0;
  std::array<std::size_t, kObservationKinds> count{};
  NoiseFloor noise;
  HeldoutSummary baseline;  // the model alone
  // The baseline's lack of fit on all data (free offsets per output in bins of time and of every
  // moving axis, nested F test, Bonferroni over the coordinates) and the coordinate it is worst
  // along ("time" or an axis): a gap the held-out test misses when the folds cannot predict it.
  double baseline_lack_of_fit_p = 1;
  std::string baseline_lack_of_fit_along;
  std::vector<GapRegion> where;        // significant regions first (by p-value), then the rest
  std::vector<EffectFit> effects;      // ranked by held-out improvement (first step)
  std::vector<EffectFit> explanation;  // the greedy sequence that was accepted
  GapVerdict verdict;
  HeldoutSummary final;  // after the accepted effects
  // Held-out residuals for plots: per observation of the data given (NaN when never held out,
  // and for outliers).
  std::vector<double> residual_before, residual_after;
};

struct GapOptions {
  std::vector<std::string> effects;  // empty: the whole library
  double alpha = 0.01;               // family-wise false-positive rate per decision
  double explain_fraction = 0.9;     // named effects must remove this much of the excess
  int max_effects = 3;
  std::map<std::string, double> fixed;  // coordinates not in the data
  unsigned threads = 0;                 // 0 = every core; results identical for any count
  // alpha in (0, 0.5), explain_fraction in (0, 1], max_effects >= 1, every effect a library
  // name (std::invalid_argument naming the flag).
  void validate() const;
};

// One effect of the library (docs/gap.md, "Effect library").
struct GapEffectInfo {
  std::string name;         // thermal_drift, reversal, ...
  bool repeatable = false;  // the greedy search may accept it again (a second sensor or lag)
  std::string help;         // one line: what it models
};
// The effect library in report order, and its names.
const std::vector<GapEffectInfo>& gap_effects();
const std::vector<std::string>& gap_effect_names();

class GapDiagnosis {
 public:
  explicit GapDiagnosis(GapOptions options = {});  // validates the options
  const GapOptions& options() const { return options_; }
  // The diagnosis of `data` against the model with parameterisation `param`, held out by
  // `scheme`; `reason` says why that scheme (reported).
  GapResult run(const Model& model, const ErrorParameterisation& param, const GapData& data,
                const HoldoutScheme& scheme, const std::string& reason) const;

 private:
  GapOptions options_;
};

// Why the default scheme was chosen ("default: the data have cycles" ...), or "given".
std::string holdout_reason(const HoldoutScheme& scheme, bool given);

}  // namespace weilgen
