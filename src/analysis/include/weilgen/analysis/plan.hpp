// Measurement planning (`weilgen plan`, docs/planning.md): the fewest poses and instrument
// set-ups that identify a machine's error parameters, with their predicted uncertainty. The plan
// is for the identification `weilgen identify` will run: the same parameterisation
// (ErrorParameterisation, --pdge, --fix), the same observation models and set-up references
// (identify.hpp: points, ballbar traces, 6D lines, R-test files) and the same estimator (the
// column-equilibrated minimum-norm least squares). Its templates are measurement files identify
// reads once their output columns are filled.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "weilgen/analysis/identify.hpp"
#include "weilgen/analysis/study.hpp"
#include "weilgen/base/output_paths.hpp"
#include "weilgen/measure/ballbar.hpp"
#include "weilgen/measure/measurement_csv.hpp"
#include "weilgen/uq/optimal_design.hpp"

namespace weilgen {

// ---- Instruments ------------------------------------------------------------------------------

// What one observation measures (docs/planning.md, "Instruments"):
//   points   dx, dy, dz of the tool point at a pose (a tracker, a probe on an artefact);
//   line6d   the six errors of a linear axis at a position along it (a 6D laser);
//   ballbar  dr at the angles of a circle of given plane, centre and radius (one unit = a circle);
//   rtest    dx, dy, dz of a sphere held at a nest while the rotary axes turn (R-test).
enum class Instrument { Points, Line6d, Ballbar, RTest };
// "points", "line6d", "ballbar", "rtest"; std::invalid_argument naming `flag` otherwise.
Instrument parse_instrument(const std::string& text, const std::string& flag = "--instrument");
const char* instrument_name(Instrument instrument);
// The observation kinds (identify.hpp: 0-2 dx dy dz, kRadialOutput, kLine*) an instrument measures.
std::vector<std::size_t> observed_kinds(Instrument instrument);

// The noise of each observation kind (identify.hpp kinds: dx … dc, dr, lin, str, ang), µm or µrad.
using KindNoise = std::array<double, kObservationKinds>;

// One set-up of an instrument: every unit of a set-up goes into one measurement file.
struct PlanSetup {
  Instrument instrument = Instrument::Points;
  std::string tag;                // short name of its file ("points", "X", "1")
  std::string what;               // "ballbar XY, centre X=250, Y=-200, Z=-150, radius 100 mm"
  BallbarCircle circle;           // ballbar
  std::string axis;               // line6d: the measured axis
  std::vector<double> nest_pose;  // rtest: the pose (axes order) at which the sphere is in the nest
  std::array<double, 3> nest_mm{};    // rtest: the nest in the workpiece frame (mm)
  std::vector<std::string> channels;  // line6d: the laser columns of the machine's errors
  KindNoise noise{};                  // this set-up's noise per kind (0: PlanInput::noise)
  double setup_s = 0, pose_s = 0;     // time budget: the set-up's time and each unit's
};

// One candidate unit: one step of an instrument.
struct PlanUnit {
  std::size_t setup = 0;     // index into PlanCandidates::setups
  std::vector<double> pose;  // the machine pose (axes order, axis units); ballbar: the centre
  double position = 0;       // line6d: along the axis (mm)
};

struct PlanCandidates {
  std::vector<PlanSetup> setups;
  std::vector<PlanUnit> units;
  std::vector<std::size_t> forced;  // units from --include
  std::size_t dropped = 0;          // candidates left out (out of travel, no R-test solution)
};

// R-test: moves the linear axes of `pose` so that the sphere sits at the set-up's nest; false when
// no solution within the travel (Newton on the exact chain at zero errors, to 1 nm).
bool hold_nest(const Model& model, const PlanSetup& setup, std::vector<double>& pose);

// The time an instrument takes (--times FILE, docs/planning.md "Several instruments"): each
// set-up (points: the instrument; line6d: an axis; ballbar: a circle's pivot; rtest: a nest) and
// each unit (a pose, a position, a circle run), in seconds.
struct InstrumentTimes {
  double setup_s = 0, pose_s = 0;
};
InstrumentTimes default_instrument_times(Instrument instrument);
// The defaults with a YAML file's entries over them ("" = the defaults):
//   points: {setup: 60 min, pose: 1 min}
//   ballbar: {setup: 5 min, pose: 2 min}
// InputError with file:line:column for bad entries.
std::map<Instrument, InstrumentTimes> read_instrument_times(const std::string& path);

// How many observation rows one unit of the instrument gives (ballbar: per circle point).
std::size_t rows_per_unit(Instrument instrument, const PlanSetup& setup, std::size_t angles);

// ---- Options ----------------------------------------------------------------------------------

// --noise: comma-separated or repeated items, each "Q" (a length sets every µm kind, an angle every
// µrad kind) or "KIND=Q" (dx dy dz da db dc dr lin str ang); defaults 1 µm and 1 µrad. Units as
// in docs/study-inputs.md (1um, 0.5 µm, 2urad, 1 arcsec). std::invalid_argument naming --noise.
KindNoise parse_noise(const std::vector<std::string>& items, KindNoise base = {});

struct PlanOptions {
  DesignCriterion criterion = DesignCriterion::D;
  std::size_t units = 0;    // --poses (0 with --target-sd or a time budget)
  double target_sd_um = 0;  // --target-sd (0: not given)
  std::size_t restarts = 8;
  std::uint64_t seed = 1;
  unsigned threads = 0;
  std::size_t random_sets = 20;  // the comparison "best of random sets"
  double rank_tolerance = IdentifyOptions{}.rank_tolerance;
  std::vector<std::string> fixed;  // --fix
  bool compare = true;             // evaluate the comparison layouts
  // --bound: iterations of the continuous design that bounds every design of the same size
  // (0: not computed).
  std::size_t bound_iterations = 0;
  // --time-budget (s): choose set-ups and units within it instead of a size (0: not given).
  double budget_s = 0;
  void validate() const;  // std::invalid_argument naming the flag
};

// ---- Results ----------------------------------------------------------------------------------

// What a layout (a set of units) gives, evaluated as identify will compute: the exact design
// with its set-up references, the equilibrated minimum-norm estimator, the given noise.
struct LayoutFigures {
  std::string name;                // "plan", "grid 4x4x4", "best of 20 random"
  std::vector<std::size_t> units;  // candidate indices (empty for layouts off the candidates)
  std::vector<PlanUnit> layout;
  std::size_t observations = 0, rank = 0;
  std::size_t lost = 0;  // combinations the candidates identify and this layout does not
  double condition = 0;
  // In the plan's frame (the candidates' estimable space, noise-weighted, each parameter scaled
  // by its RMS over the candidates): log det of the information, the criterion's value.
  double log_det = 0, criterion = 0;
  double prediction_sd_um = 0;       // √(mean over the 5-level grid and dx dy dz of the variance)
  std::vector<double> parameter_sd;  // per parameter, declared units; NaN: not identifiable/fixed
  ObservabilityIndices observability;
  double time_s = 0;  // time budget: the set-ups' and units' time
};

// Time budget: one set-up of the plan and its time.
struct TimeUse {
  std::size_t setup = 0;  // index into PlanCandidates::setups
  std::size_t units = 0;
  double setup_s = 0, units_s = 0;
};

// The plan's prediction SD over two axes (the others at the middle of their travel), µm:
// √(mean of the variance of dx, dy, dz) at each pose, sd_um[iy * x.size() + ix].
struct SdMap {
  std::string x_axis, y_axis, x_unit, y_unit;
  std::vector<double> x, y, sd_um;
  std::vector<double> middle;  // the pose of the other axes
};

struct PlanResult {
  Instrument instrument = Instrument::Points;
  PlanCandidates candidates;
  KindNoise noise{};
  std::size_t free_parameters = 0;
  std::size_t candidate_rank = 0;               // identify's rank on every candidate
  std::vector<NullCombination> unidentifiable;  // what no candidate set can determine
  std::size_t minimum_units = 0;                // fewest units reaching the rank (lower bound)
  std::size_t greedy_units = 0;                 // units the sequential design needed for it
  LayoutFigures plan;
  std::vector<LayoutFigures> compare;  // the regular layout, the best of the random sets
  std::vector<double> random_sd_um;    // prediction_sd_um of every random set
  ExchangeResult exchange;
  // --target-sd: the sizes tried and their prediction_sd_um.
  std::vector<std::pair<std::size_t, double>> target_search;
  SdMap sd_map;
  // Time budget (several instruments): the set-ups used and the time they take; `compare` holds
  // each instrument alone within the same budget.
  std::vector<Instrument> instruments;
  std::vector<TimeUse> time_use;
  double time_used_s = 0;
  // --bound: the best any design of the plan's size on these candidates can reach, in the frame
  // (uq/optimal_design.hpp, continuous_design): the criterion's bound, and the prediction SD's
  // (√ of the I bound: the prediction SD when the volumetric rows are estimable). NaN: not
  // computed.
  double criterion_bound = std::numeric_limits<double>::quiet_NaN();
  double prediction_sd_bound_um = std::numeric_limits<double>::quiet_NaN();
  std::size_t bound_iterations = 0;
  double seconds = 0;  // the planner's wall time
};

// ---- The request (flags as written) -----------------------------------------------------------

struct PlanRequest : MeasurementRequest {
  std::string instrument;                // --instrument ("" = points)
  std::vector<std::string> noise;        // --noise
  std::string criterion = "D";           // --criterion
  std::size_t poses = 0;                 // --poses
  std::string target_sd;                 // --target-sd
  std::vector<std::string> candidates;   // --candidates (grid items or one CSV file)
  std::vector<std::string> set;          // --set AXIS=VALUE (fixed axes)
  std::vector<std::string> include;      // --include FILE
  std::vector<std::string> pdge, fixed;  // --pdge, --fix
  double rank_tolerance = IdentifyOptions{}.rank_tolerance;  // --rank-tol
  std::string radius = "100 mm";                             // --radius (ballbar)
  std::size_t angles = 360;                                  // --angles (ballbar points per circle)
  std::vector<std::string> planes;  // --plane (ballbar; repeatable; none: every plane)
  std::vector<std::string> nests;   // --nest (rtest)
  std::size_t restarts = 8, random_sets = 20;
  std::size_t bound = 0;    // --bound: continuous-design iterations (0: no bound)
  std::string instruments;  // --instruments points:0.5um,ballbar:0.2um,line6d:1um
  std::string time_budget;  // --time-budget 4h
  std::string times;        // --times FILE.yaml
  std::uint64_t seed = 1;
  unsigned threads = 0;
  // The flags alone, before any file is read (std::invalid_argument naming the flag).
  void validate() const;
  // The files the plan reads (--candidates FILE, --include, --times), which no output may be.
  std::vector<PathArg> input_files() const;
};

struct PlanRun {
  std::shared_ptr<const Model> model;
  std::shared_ptr<const ErrorParameterisation> param;
  PlanOptions options;
  PlanResult result;
  // The plan as measurement templates, one per set-up used: (file tag, table); the output
  // columns empty.
  std::vector<std::pair<std::string, MeasurementTable>> templates;
};

// Validates the request, reads the files, builds the candidates and plans.
PlanRun run_plan(const PlanRequest& request);

// ---- The pieces (plan_instruments.cpp, plan.cpp) ------------------------------------------------

struct CandidateSpec {
  Instrument instrument = Instrument::Points;
  std::vector<std::string> grid;  // --candidates items
  std::string file;               // --candidates FILE.csv
  std::vector<std::string> set;   // --set
  std::vector<std::string> include;
  double radius_mm = 100;
  std::size_t angles = 360;
  std::vector<std::string> planes;
  std::vector<std::string> nests;
};
// The candidate units of an instrument on the machine (std::invalid_argument when the instrument
// cannot measure this machine, naming why; InputError for bad files).
PlanCandidates plan_candidates(const Model& model, const CandidateSpec& spec);

// The measurement templates of `units` (candidate-like units with their set-ups), one table per
// set-up used, in set-up order: (tag, table). `fill`: the output cells are 0 instead of empty
// (for evaluation through identify's readers).
std::vector<std::pair<std::string, MeasurementTable>> plan_tables(
    const Model& model, const PlanCandidates& candidates, const std::vector<PlanUnit>& units,
    std::size_t angles, bool fill);

// The observations identify reads from the filled templates of `units`, and which unit each
// observation belongs to.
PointData plan_observations(const Model& model, const PlanCandidates& candidates,
                            const std::vector<PlanUnit>& units, std::size_t angles,
                            std::vector<std::size_t>* unit_of_observation = nullptr);

// The planner over given candidates.
struct PlanInput {
  std::shared_ptr<const Model> model;
  std::shared_ptr<const ErrorParameterisation> param;
  PlanCandidates candidates;
  Instrument instrument = Instrument::Points;
  KindNoise noise{};
  std::size_t angles = 360;
  std::vector<Instrument> instruments;  // several (a time budget), each set-up its own noise
};

class Planner {
 public:
  explicit Planner(PlanOptions options);  // validates
  const PlanOptions& options() const { return options_; }
  PlanResult run(const PlanInput& input) const;

 private:
  PlanOptions options_;
};

}  // namespace weilgen
