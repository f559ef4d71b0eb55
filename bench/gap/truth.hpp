// The truth generator of the sim-to-real gap benchmark (bench/gap/README.md): a shipped machine
// with random geometric errors within its spreads, evaluated with the exact numeric chain
// (weilgen/model/numeric_chain.hpp), plus exactly one effect withheld from the model (or none),
// sampled in one measurement layout and written as a measurement CSV (docs/data-format.md) with a
// truth.json. Nothing here calls or mirrors the diagnosis code (src/cli/verb_gap.cpp): the only
// shared pieces are the machine description, the exact chain and the CSV format.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "weilgen/machine/description.hpp"
#include "weilgen/model/numeric_chain.hpp"

namespace weilgen::gapbench {

// The diagnosis library's candidate effects, in confusion-matrix order.
const std::vector<std::string>& library_effects();
// Everything the generator can withhold: the library, "step" (outside it) and "none".
const std::vector<std::string>& all_effects();
const std::vector<std::string>& layout_names();  // grid, line, ballbar

struct ScenarioSpec {
  std::string machine = "vmc_3axis";  // truth machine: shipped name or path
  std::string effect = "none";
  double factor = 0;      // held-out signal RMS of the effect / noise sigma
  double noise_um = 1.0;  // noise sigma of every measured value
  std::string layout = "grid";
  std::uint64_t seed = 1;
  int truth_degree = 3;  // degree of the truth's PDGE polynomials
  int fit_degree = 3;    // degree of the model's PDGE bases that define "absorbable"
  // missing_error: the error left out of the model machine; empty = the machine's default.
  std::string missing_error;
  // Size (the speed benchmark, bench/gap/speed.sh): 0 = the layout's own cycles; else the layout
  // is repeated for as many cycles as needed and cut after the row that reaches this many
  // observations.
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

// A 64-bit seed from text (FNV-1a): stable scenario seeds from scenario ids.
std::uint64_t seed_from(const std::string& text);

// Legendre polynomials P_0..P_n at u, into out[0..n].
void legendre(int n, double u, double* out);

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
  // Builds the truth machine, the layout and the effect, and scales the effect so that its
  // held-out signal is factor * noise_um. Throws std::runtime_error / InputError on bad specs.
  explicit Synthesiser(ScenarioSpec spec);
  ~Synthesiser();

  // The measurement file; the variants without effect or noise serve the self-check.
  std::string csv(bool with_effect = true, bool with_noise = true) const;
  nlohmann::json truth() const;
  // Path or shipped name of the model machine `weilgen gap` is given.
  const std::string& model_machine() const { return model_machine_; }

  // Noise-free measured values (um), one per observation (row-major, measured columns in
  // measured_columns() order).
  std::vector<double> measured(bool with_effect) const;
  const std::vector<std::string>& measured_columns() const { return columns_; }
  std::size_t num_observations() const { return obs_row_.size(); }
  // Per measured column: RMS of the signal's part the model cannot absorb (least-squares residual
  // on the model's regressors over all observations), and of the signal itself.
  std::vector<double> unabsorbed_rms(const std::vector<double>& signal_um) const;
  std::vector<double> raw_rms(const std::vector<double>& signal_um) const;

  // Probe: for every error of the truth machine, the fraction of its (unit-shape) signal the
  // model could not absorb if the error were missing from it ("visible fraction").
  std::vector<std::pair<std::string, double>> missing_error_visibility() const;

 private:
  struct AxisInfo {
    std::string name;
    int body = -1;
    bool linear = true;
    int dim = 0;  // output component of a linear axis (x, y, z) in the workpiece frame
    double min = 0, max = 0;
  };
  struct TruthError {
    int axis = -1;              // index into axes_ of a PDGE's axis; -1: constant (PIGE)
    std::vector<double> coeff;  // Legendre coefficients in the declared unit (PIGE: one)
  };

  void build_layout(Rng& rng);
  void build_effect(Rng& rng);
  void build_regressors();
  void scale_effect();
  void draw_noise();

  std::vector<double> errors_at(const Row& row, double amplitude, bool with_effect) const;
  std::vector<double> evaluate(double amplitude, bool with_effect) const;
  std::vector<double> signal(double amplitude) const;
  // A 3-vector deviation (mm) to the values measured at one row (um), before instrument effects.
  void measure_row(std::size_t r, const Eigen::Vector3d& d_mm, double* out_um) const;
  // First-order deviation of the truth machine: J(pose) * errors (positions, mm).
  Eigen::Vector3d linear_deviation(const Row& row, const std::vector<double>& errors) const;
  const Eigen::MatrixXd& truth_jacobian(int pose) const;
  double drift(double t_s) const;  // thermal: lagged temperature rise, degC
  nlohmann::json signal_bins(int axis, std::size_t column) const;
  double temperature(double t_s) const;
  std::vector<int> translation_errors(int axis) const;  // "after" translations of an axis body
  int positioning_error(int axis) const;
  double axis_step(int axis) const;  // sample spacing of the layout along an axis, mm
  std::pair<double, double> data_range(int axis) const;

  ScenarioSpec spec_;
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
  std::vector<double> grid_step_;  // per axis (grid layout)
  int line_axis_ = -1;
  int plane_a_ = -1, plane_b_ = -1;  // ballbar plane axes
  double radius_mm_ = 0;
  std::vector<double> centre_;
  double t_total_s_ = 0;
  std::vector<double> drift_table_;  // lagged temperature on a fine time grid

  // Effect.
  std::string effect_;
  std::string expected_ = "none";
  int effect_axis_ = -1, effect_error_ = -1, effect_dim_ = -1;
  double period_mm_ = 0, phase_rad_ = 0, centre_mm_ = 0, width_mm_ = 0;
  double step_at_ = 0;
  bool step_in_time_ = true;
  std::vector<double> thermal_offset_, thermal_scale_;  // per dimension (unit-less shapes)
  double amplitude_ = 0;    // the effect's physical amplitude (unit per effect, see truth())
  bool observable_ = true;  // the effect reaches the measured values at all
  bool identifiable_ = true;
  double unabsorbed_rms_um_ = 0, raw_rms_um_ = 0;
  std::vector<double> unabsorbed_by_column_, raw_by_column_;
  Eigen::VectorXd residual_;  // the held-out signal per observation

  // Noise.
  std::vector<double> noise_um_, temp_noise_;
  double noise_rms_um_ = 0;

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
