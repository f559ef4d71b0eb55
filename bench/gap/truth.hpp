// The truth generator of the sim-to-real gap benchmark (bench/gap/README.md): a shipped machine
// with random geometric errors within its spreads, evaluated with the exact numeric chain
// (weilgen/model/numeric_chain.hpp), plus one or two effects withheld from the model (or none),
// sampled in one measurement layout and written as a measurement CSV (docs/data-format.md) with
// a truth.json. Every effect is a physical perturbation inside the chain (an error's shape, an
// axis' position, the tool length, the tool point's growth) or at the instrument (a cosine
// error, a step, gross readings). Nothing here calls or mirrors the diagnosis code
// (src/analysis/gap/): the only shared pieces are the machine description, the exact chain and
// the CSV format.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "weilgen/machine/description.hpp"
#include "weilgen/model/numeric_chain.hpp"

namespace weilgen::gapbench {

// The diagnosis library's candidate effects, in confusion-matrix order.
const std::vector<std::string>& library_effects();
// Everything the generator can withhold: the library, "step" (outside it) and "none".
const std::vector<std::string>& all_effects();
// grid, sparse, small, line, ballbar, ballbar_yz, rtest, rtest_small.
const std::vector<std::string>& layout_names();

// The effects the generator can withhold (one row each in Synthesiser::effect_table()).
enum class EffectKind {
  ThermalDrift,
  Reversal,
  Periodic,
  PdgeShape,
  HigherOrder,
  MissingError,
  ToolOffset,
  Setup,
  Step
};

// A measurement layout (truth_layout.cpp), parsed once from its name.
struct Layout {
  enum class Kind { Grid, Sparse, Small, Line, Ballbar, BallbarYz, Rtest, RtestSmall };
  Kind kind = Kind::Grid;
  // Throws std::runtime_error on a name not in layout_names().
  static Layout parse(const std::string& name);
  bool line() const { return kind == Kind::Line; }
  bool ballbar() const { return kind == Kind::Ballbar || kind == Kind::BallbarYz; }
  bool rtest() const { return kind == Kind::Rtest || kind == Kind::RtestSmall; }
};

struct ScenarioSpec {
  std::string machine = "vmc_3axis";  // truth machine: shipped name or path
  // A library effect, "step", "none", or two library effects joined by '+' (both withheld, each
  // scaled to `factor` on its own).
  std::string effect = "none";
  double factor = 0;      // held-out signal RMS of each effect / noise sigma
  double noise_um = 1.0;  // noise sigma (RMS over the observations) of every measured value
  std::string layout = "grid";
  std::uint64_t seed = 1;
  int truth_degree = 3;  // degree of the truth's PDGE polynomials
  int fit_degree = 3;    // degree of the model's PDGE bases that define "absorbable"
  // > 0: a rotary axis' PDGEs are Fourier series of this many harmonics over one turn (360 deg),
  // in the truth and in the bases that define "absorbable" (weilgen's default on a rotary axis
  // is fourier:2); 0: Legendre series on the travel, like a linear axis'.
  int rotary_harmonics = 0;
  // missing_error: the error left out of the model machine; empty = the machine's default.
  std::string missing_error;
  int outliers = 0;              // gross readings (30-60 sigma) added to random observations
  bool heteroscedastic = false;  // noise sigma growing 4x with the distance from the first pose
  // Size (the speed benchmark, bench/gap/speed.sh): 0 = the layout's own cycles; else the grid
  // is repeated for as many cycles as needed, and any layout is cut after the row that reaches
  // this many observations.
  int observations = 0;
};

// Deterministic uniform and normal deviates (Box-Muller on mt19937_64): the same numbers with
// every standard library, unlike std::normal_distribution.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : g_(seed) {}
  double uniform() { return static_cast<double>(g_() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int index(int n) { return static_cast<int>(uniform() * n) % n; }
  double normal();

 private:
  std::mt19937_64 g_;
  double spare_ = 0;
  bool has_spare_ = false;
};

// Helpers of the generator's files.
inline constexpr double kPi = 3.14159265358979323846;
inline constexpr const char* kDimNames[3] = {"dx", "dy", "dz"};
inline std::runtime_error fail(const std::string& what) { return std::runtime_error(what); }
// Element-wise copy: GCC 12 reports a false -Wnonnull in vector<double>::operator= here.
template <typename T>
void copy_to(std::vector<T>& dst, const std::vector<T>& src) {
  dst.resize(src.size());
  for (std::size_t i = 0; i < src.size(); ++i) dst[i] = src[i];
}

// The largest element (0 when empty), and a number printed with a printf format.
double max_of(const std::vector<double>& v);
std::string fmt(const char* f, double v);
// Central-difference Jacobian (3 × errors, mm per base unit) of the tool position of `chain`
// at `axes`, step h (mm, rad).
Eigen::MatrixXd position_jacobian(const NumericChain& chain, const std::vector<double>& axes,
                                  std::size_t n, double h);

// A 64-bit seed from text (FNV-1a): stable scenario seeds from scenario ids.
std::uint64_t seed_from(const std::string& text);

// Legendre polynomials P_0..P_n at u, into out[0..n].
void legendre(int n, double u, double* out);

// A PDGE's basis at position q of an axis with travel [a, b]: with harmonics > 0 (a rotary axis
// in deg) 1, cos θ, sin θ, … cos Hθ, sin Hθ with θ = 2π q / 360 (2H + 1 terms), else the
// Legendre polynomials P_0..P_degree of u = (2q − a − b)/(b − a). Returns the number of terms.
int pdge_basis(int harmonics, int degree, double q, double a, double b, double* out);

// One measured pose.
struct Row {
  std::vector<double> axes;  // joint coordinates in Description::axes() order (mm, deg)
  std::vector<int> dir;      // approach direction of each axis (last move), same order
  double t_s = 0;
  int cycle = 1;
  int feed_dir = 1;  // line: the moving axis' direction; ballbar: +1 ccw, -1 cw
  double angle_deg = 0;
  int pose = 0;  // index of the distinct pose (Jacobians are cached per pose)
};

class Synthesiser {
 public:
  // Builds the truth machine, the layout and the effects, and scales each effect so that its
  // held-out signal is factor * noise_um. Throws std::runtime_error / InputError on bad specs.
  explicit Synthesiser(ScenarioSpec spec);
  ~Synthesiser();

  // The measurement file; the variants without effect or noise serve the self-check (gross
  // readings come with the noise unless with_gross is false). csv(false, true, false) is the
  // oracle file: the same truth machine, poses and noise with the withheld effects and the gross
  // readings removed exactly (what a model that knew the effects would be left with).
  std::string csv(bool with_effect = true, bool with_noise = true, bool with_gross = true) const;
  nlohmann::json truth() const;
  // Path or shipped name of the model machine `weilgen gap` is given.
  const std::string& model_machine() const { return model_machine_; }

  // Noise-free measured values (µm), one per observation (row-major, measured columns in
  // measured_columns() order).
  std::vector<double> measured(bool with_effect) const;
  const std::vector<std::string>& measured_columns() const { return columns_; }
  std::size_t num_observations() const { return obs_row_.size(); }
  // Per measured column: RMS of the signal's part the model cannot absorb (least-squares residual
  // on the model's regressors over all observations), and of the signal itself.
  std::vector<double> unabsorbed_rms(const std::vector<double>& signal_um) const;
  std::vector<double> raw_rms(const std::vector<double>& signal_um) const;
  // The noise-free signal of effect k alone at its scaled amplitude (µm per observation).
  std::vector<double> effect_signal(std::size_t k) const;
  std::size_t num_effects() const { return effects_.size(); }
  // The truth's noise sigma of each observation (µm; all equal unless heteroscedastic).
  const std::vector<double>& noise_sigma() const { return sigma_; }

  // Probe: for every error of the truth machine, the fraction of its (unit-shape) signal the
  // model could not absorb if the error were missing from it ("visible fraction").
  std::vector<std::pair<std::string, double>> missing_error_visibility() const;

 private:
  struct AxisInfo {
    std::string name;
    int body = -1;
    bool linear = true;
    int dim = 0;  // principal direction of the joint axis (x, y, z)
    double min = 0, max = 0;
    double home = 0;  // the reference position: 0 clamped into the travel
  };
  struct TruthError {
    int axis = -1;              // index into axes_ of a PDGE's axis; -1: constant (PIGE)
    std::vector<double> coeff;  // pdge_basis coefficients in the declared unit (PIGE: one)
    int harmonics = 0;          // > 0: a Fourier series over one turn (pdge_basis)
  };
  // One withheld effect and its realisation.
  struct Effect {
    EffectKind kind = EffectKind::Step;
    std::string name;
    int axis = -1, error = -1, dim = -1;  // the axis, error and measured direction it acts on
    double period = 0, phase = 0, centre = 0, width = 0;  // periodic, pdge_shape (axis unit)
    double step_at = 0;                                   // step: s or axis unit
    bool step_in_time = true;
    bool machine_frame = false;  // thermal: the growth is fixed in the machine frame, else tool
    std::vector<double> offset, scale;  // thermal: per direction of its frame; per axis
    double amplitude = 0;               // physical amplitude (unit per effect, see truth())
    bool observable = true, identifiable = true;
    double unabsorbed_rms = 0, raw_rms = 0;
    std::vector<double> unabsorbed_by_column, raw_by_column;
    Eigen::VectorXd residual;  // the held-out signal per observation
  };
  struct GrossReading {
    std::size_t observation = 0;
    double size_um = 0;
  };

  // Layouts (truth_layout.cpp).
  void build_layout(Rng& rng);
  void grid_layout(int lo, int hi, double per_travel, int cycles, double dwell_s);
  void small_layout();
  void line_layout(Rng& rng);
  void ballbar_layout(int dim_a, int dim_b);
  void rtest_layout(bool small);
  void finish_layout();
  // Appends a pass over poses (indices into poses_), approach directions following the moves.
  void add_pass(const std::vector<int>& sequence, int cycle, double dwell_s);
  std::vector<int> linear_axes() const;  // indices of linear axes with a travel

 public:
  // Effects (truth_effects.cpp): each effect's placement on the layout (its axis, error,
  // direction, shape; the draws from the effect's stream) and its truth.json parameters and
  // localisation, one row per effect in effect_table().
  struct Placement;
  struct Labels;
  using PlaceFn = void (Synthesiser::*)(Effect&, Rng&, const Placement&) const;
  using DescribeFn = void (Synthesiser::*)(const Effect&, const Labels&, nlohmann::json& params,
                                           nlohmann::json& localise) const;
  struct EffectDef {
    EffectKind kind;
    const char* name;
    bool library;              // a candidate of the diagnosis library (else: outside it, "step")
    bool additive;             // may be withheld together with another additive effect
    double nominal_amplitude;  // the scaling's start (µm, µrad, ppm, mm or a factor)
    PlaceFn place;             // nullptr: nothing to place
    DescribeFn describe;
  };
  static const std::vector<EffectDef>& effect_table();
  static const EffectDef& effect_def(EffectKind kind);
  static const EffectDef* find_effect(const std::string& name);

 private:
  void build_effect(Effect& e, Rng& rng);
  int pick_error(int axis, Rng& rng, const Placement& at) const;
  void place_reversal(Effect& e, Rng& rng, const Placement& at) const;
  void place_shape(Effect& e, Rng& rng, const Placement& at) const;  // periodic, pdge_shape
  void place_thermal(Effect& e, Rng& rng, const Placement& at) const;
  void place_step(Effect& e, Rng& rng, const Placement& at) const;
  void place_tool_offset(Effect& e, Rng& rng, const Placement& at) const;
  void describe_reversal(const Effect& f, const Labels& n, nlohmann::json& params,
                         nlohmann::json& loc) const;
  void describe_periodic(const Effect& f, const Labels& n, nlohmann::json& params,
                         nlohmann::json& loc) const;
  void describe_pdge_shape(const Effect& f, const Labels& n, nlohmann::json& params,
                           nlohmann::json& loc) const;
  void describe_thermal(const Effect& f, const Labels& n, nlohmann::json& params,
                        nlohmann::json& loc) const;
  void describe_step(const Effect& f, const Labels& n, nlohmann::json& params,
                     nlohmann::json& loc) const;
  void describe_higher_order(const Effect& f, const Labels& n, nlohmann::json& params,
                             nlohmann::json& loc) const;
  void describe_missing_error(const Effect& f, const Labels& n, nlohmann::json& params,
                              nlohmann::json& loc) const;
  void describe_tool_offset(const Effect& f, const Labels& n, nlohmann::json& params,
                            nlohmann::json& loc) const;
  void describe_setup(const Effect& f, const Labels& n, nlohmann::json& params,
                      nlohmann::json& loc) const;
  std::string output_name(std::size_t column) const;  // dx, dy, dz or dr
  void build_regressors();
  void scale_effects();
  void draw_noise();
  void place_gross_readings();

  std::vector<double> errors_at(const Row& row, const std::vector<double>& amps,
                                const std::vector<bool>& on) const;
  std::vector<double> evaluate(const std::vector<double>& amps, const std::vector<bool>& on) const;
  std::vector<double> signal(std::size_t k, double amplitude) const;
  // Tool position (mm, workpiece frame) of `chain` at axes q with errors e.
  Eigen::Vector3d tool_point(const NumericChain& chain, const std::vector<double>& q,
                             const std::vector<double>& e) const;
  // A 3-vector deviation (mm) to the values measured at one row (µm), before instrument effects.
  void measure_row(std::size_t r, const Eigen::Vector3d& d_mm, double* out_um) const;
  // First-order deviation of the truth machine: J(pose) * errors (positions, mm).
  Eigen::Vector3d linear_deviation(const Row& row, const std::vector<double>& errors) const;
  const Eigen::MatrixXd& truth_jacobian(int pose) const;
  double drift(double t_s) const;  // thermal: lagged temperature rise, degC
  nlohmann::json signal_bins(const Effect& e, int axis, std::size_t column) const;
  nlohmann::json effect_json(const Effect& e) const;
  std::vector<std::string> comment_lines() const;  // the CSV's "# key: value" lines
  double temperature(double t_s) const;
  std::vector<int> translation_errors(int axis) const;  // "after" translations of an axis body
  int positioning_error(int axis) const;
  double axis_step(int axis) const;  // sample spacing of the layout along an axis
  std::pair<double, double> data_range(int axis) const;
  std::size_t distinct_positions(int axis) const;
  std::string expected_of(const Effect& e) const;
  std::size_t dominant_column(const Effect& e) const;

  ScenarioSpec spec_;
  Layout layout_;
  Description truth_desc_, model_desc_;
  std::string model_machine_;
  std::unique_ptr<NumericChain> truth_chain_, model_chain_;
  std::vector<double> truth_params_, model_params_;
  std::vector<AxisInfo> axes_;
  std::vector<TruthError> errors_;

  // Layout.
  std::vector<Row> rows_;
  std::vector<int> obs_row_, obs_col_;  // observation -> row, measured column
  std::vector<std::string> columns_;    // measured columns: dx_um ... or dr_um
  std::vector<int> column_dim_;         // dimension of each measured column; -1 for dr_um
  std::vector<std::vector<double>> poses_;
  std::vector<double> grid_step_;             // per axis (grid layouts)
  std::vector<std::vector<double>> spheres_;  // rtest: the spheres' centres (workpiece, mm)
  int line_axis_ = -1;
  int plane_a_ = -1, plane_b_ = -1;  // ballbar plane axes
  double radius_mm_ = 0;
  std::vector<double> centre_;
  Eigen::Vector3d centre_point_ = Eigen::Vector3d::Zero();  // ballbar: the table ball (mm)
  double t_total_s_ = 0;
  std::vector<double> drift_table_;  // lagged temperature on a fine time grid

  // Effects.
  std::vector<Effect> effects_;
  bool tool_offset_ = false, higher_order_ = false, missing_ = false;

  // Noise.
  std::vector<double> sigma_, noise_um_, temp_noise_;
  double noise_rms_um_ = 0;
  std::vector<GrossReading> gross_;

  // Model regressors, column-normalised, and their column space.
  Eigen::MatrixXd regressors_;
  std::vector<int> regressor_error_;  // model error of each regressor column
  struct Span {
    Span() = default;
    explicit Span(const Eigen::MatrixXd& A);
    Eigen::VectorXd residual(const Eigen::VectorXd& s) const;  // s minus its projection
    Eigen::MatrixXd basis;                                     // orthonormal columns
    double smallest_kept = 0, largest_dropped = 0;             // relative singular values
  };
  Span span_;
  mutable std::vector<Eigen::MatrixXd> truth_jacobians_;  // per pose, 3 x errors (lazy)
};

}  // namespace weilgen::gapbench
