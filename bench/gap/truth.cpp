#include "truth.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <stdexcept>

#include "weilgen/machine/iso_names.hpp"
#include "weilgen/machine/yaml_loader.hpp"

namespace weilgen::gapbench {

namespace {

constexpr double kTempNoiseK = 0.01;       // sensor noise of T_spindle
constexpr double kVisibleFraction = 0.02;  // below: the model absorbs the effect

std::uint64_t splitmix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Independent streams of one scenario seed: the truth machine, the layout and the noise do not
// depend on the effect, so two scenarios with one seed differ only by their effect.
enum Stream : std::uint64_t {
  kTruthStream = 1,
  kLayoutStream,
  kEffectStream,
  kNoiseStream,
  kGrossStream,
  kSecondEffectStream
};
Rng stream(std::uint64_t seed, Stream s) { return Rng(splitmix(seed * 8 + s)); }

struct Spread {
  double mean = 0, sd = 0;
};
Spread spread_of(const Distribution& d) {
  switch (d.kind) {
    case Distribution::Kind::Normal:
    case Distribution::Kind::TruncatedNormal:
      return {d.a, d.b};
    case Distribution::Kind::Uniform:
      return {(d.a + d.b) / 2, (d.b - d.a) / std::sqrt(12.0)};
    case Distribution::Kind::None:
      break;
  }
  return {};
}

double draw(const Distribution& d, Rng& rng) {
  switch (d.kind) {
    case Distribution::Kind::Normal:
      return d.a + d.b * rng.normal();
    case Distribution::Kind::Uniform:
      return rng.uniform(d.a, d.b);
    case Distribution::Kind::TruncatedNormal:
      for (int i = 0; i < 10000; ++i) {
        const double v = d.a + d.b * rng.normal();
        if (v >= d.lo && v <= d.hi) return v;
      }
      return std::clamp(d.a, d.lo, d.hi);
    case Distribution::Kind::None:
      break;
  }
  return 0;
}

double rms(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x * x;
  return v.empty() ? 0 : std::sqrt(s / static_cast<double>(v.size()));
}

double max_of(const std::vector<double>& v) {
  return v.empty() ? 0 : *std::max_element(v.begin(), v.end());
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

const std::map<std::string, std::string>& default_missing_error() {
  // Chosen by `weilgen_gap_synth --probe-missing`: errors whose signal the remaining errors'
  // polynomials cannot absorb in the grid layout (README.md, "missing_error").
  static const std::map<std::string, std::string> m = {{"vmc_3axis", "E_AX"},
                                                       {"gantry_grinder", "E_AX"},
                                                       {"five_axis_ac", "E_CY"},
                                                       {"head_head_bc", "E_ZC"}};
  return m;
}

// Central-difference Jacobian (3 × errors, mm per base unit) of the tool position of `chain`
// at `axes`, step h (mm, rad).
Eigen::MatrixXd position_jacobian(const NumericChain& chain, const std::vector<double>& axes,
                                  std::size_t n, double h) {
  Eigen::MatrixXd J(3, static_cast<Eigen::Index>(n));
  std::vector<double> e(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    e[i] = h;
    const Eigen::Vector3d plus = chain.tool_in_workpiece(axes, e).block<3, 1>(0, 3);
    e[i] = -h;
    const Eigen::Vector3d minus = chain.tool_in_workpiece(axes, e).block<3, 1>(0, 3);
    e[i] = 0;
    J.block<3, 1>(0, static_cast<Eigen::Index>(i)) = (plus - minus) / (2 * h);
  }
  return J;
}

}  // namespace

const std::vector<std::string>& library_effects() {
  static const std::vector<std::string> v = {"thermal_drift", "reversal",     "periodic",
                                             "pdge_shape",    "higher_order", "missing_error",
                                             "tool_offset",   "setup"};
  return v;
}

const std::vector<std::string>& all_effects() {
  static const std::vector<std::string> v = [] {
    std::vector<std::string> a = library_effects();
    a.push_back("step");
    a.push_back("none");
    return a;
  }();
  return v;
}

const std::vector<std::string>& layout_names() {
  static const std::vector<std::string> v = {"grid",    "sparse",     "small", "line",
                                             "ballbar", "ballbar_yz", "rtest", "rtest_small"};
  return v;
}

double Rng::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  const double u1 = uniform() + 0x1.0p-53;  // (0, 1]: log stays finite
  const double u2 = uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  spare_ = r * std::sin(2 * kPi * u2);
  has_spare_ = true;
  return r * std::cos(2 * kPi * u2);
}

std::uint64_t seed_from(const std::string& text) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

void legendre(int n, double u, double* out) {
  out[0] = 1;
  if (n >= 1) out[1] = u;
  for (int k = 1; k < n; ++k) out[k + 1] = ((2 * k + 1) * u * out[k] - k * out[k - 1]) / (k + 1);
}

int pdge_basis(int harmonics, int degree, double q, double a, double b, double* out) {
  if (harmonics <= 0) {
    legendre(degree, (2 * q - a - b) / (b - a), out);
    return degree + 1;
  }
  const double theta = 2 * 3.14159265358979323846 * q / 360;
  out[0] = 1;
  for (int h = 1; h <= harmonics; ++h) {
    out[2 * h - 1] = std::cos(h * theta);
    out[2 * h] = std::sin(h * theta);
  }
  return 2 * harmonics + 1;
}

Synthesiser::~Synthesiser() = default;

Synthesiser::Synthesiser(ScenarioSpec spec) : spec_(std::move(spec)) {
  const auto& layouts = layout_names();
  if (std::find(layouts.begin(), layouts.end(), spec_.layout) == layouts.end())
    throw fail("unknown layout '" + spec_.layout + "'");
  if (!(spec_.factor >= 0) || !(spec_.noise_um >= 0)) throw fail("factor and noise must be >= 0");
  if (spec_.truth_degree < 0 || spec_.truth_degree > 8 || spec_.fit_degree < 0 ||
      spec_.fit_degree > 8 || spec_.rotary_harmonics < 0 || spec_.rotary_harmonics > 7)
    throw fail("degrees must be within 0..8");
  if (spec_.outliers < 0) throw fail("outliers must be >= 0");
  std::vector<std::string> names;
  {
    std::string rest = spec_.effect;
    for (std::size_t p; (p = rest.find('+')) != std::string::npos; rest = rest.substr(p + 1))
      names.push_back(rest.substr(0, p));
    names.push_back(rest);
  }
  const auto& all = all_effects();
  for (const std::string& n : names)
    if (std::find(all.begin(), all.end(), n) == all.end()) throw fail("unknown effect '" + n + "'");
  if (names.size() > 2) throw fail("at most two effects at once");
  if (names.size() == 2) {
    const std::set<std::string> additive = {"thermal_drift", "reversal", "periodic", "pdge_shape"};
    if (!additive.count(names[0]) || !additive.count(names[1]) || names[0] == names[1])
      throw fail(
          "two effects at once: two different ones of thermal_drift, reversal, periodic, "
          "pdge_shape");
  }
  if (names.size() == 1 && names[0] == "none") {
    names.clear();
    spec_.factor = 0;
  }
  for (const std::string& n : names) {
    Effect e;
    e.name = n;
    effects_.push_back(e);
    tool_offset_ = tool_offset_ || n == "tool_offset";
    higher_order_ = higher_order_ || n == "higher_order";
    missing_ = missing_ || n == "missing_error";
  }

  truth_desc_ = load_machine_file(resolve_machine(spec_.machine));
  model_desc_ = truth_desc_;
  model_machine_ = spec_.machine;
  if (missing_) {
    if (spec_.missing_error.empty()) {
      const auto it = default_missing_error().find(truth_desc_.name);
      if (it == default_missing_error().end())
        throw fail("no default missing error for machine '" + truth_desc_.name +
                   "': give --missing");
      spec_.missing_error = it->second;
    }
    const int err = truth_desc_.error_index(spec_.missing_error);
    if (err < 0) throw fail("no error '" + spec_.missing_error + "' in the machine");
    effects_[0].error = err;
    spec_.missing_error = truth_desc_.errors[static_cast<std::size_t>(err)].name;
    const std::filesystem::path reduced =
        std::filesystem::path(WEILGEN_GAP_MACHINES_DIR) /
        (truth_desc_.name + "_no_" + spec_.missing_error.substr(2) + ".yaml");
    if (!std::filesystem::is_regular_file(reduced))
      throw fail("missing_error needs the reduced model machine " + reduced.string());
    model_machine_ = reduced.string();
    model_desc_ = load_machine_file(model_machine_);
    // The reduced file must be the truth minus exactly that error, or the benchmark would
    // withhold more than one effect.
    std::vector<std::string> expect = error_names(truth_desc_), got = error_names(model_desc_);
    expect.erase(expect.begin() + err);
    if (expect != got)
      throw fail(model_machine_ + ": errors differ from the truth minus " + spec_.missing_error);
  }
  truth_chain_ = std::make_unique<NumericChain>(truth_desc_);
  model_chain_ = std::make_unique<NumericChain>(model_desc_);
  for (const Parameter& p : truth_desc_.parameters) truth_params_.push_back(p.value);
  for (const Parameter& p : model_desc_.parameters) model_params_.push_back(p.value);

  for (int b : truth_desc_.axes()) {
    const Joint& j = truth_desc_.bodies[static_cast<std::size_t>(b)].joint;
    AxisInfo a;
    a.name = j.coordinate;
    a.body = b;
    a.linear = j.type == JointType::Prismatic;
    a.dim = static_cast<int>(
        std::max_element(j.axis.begin(), j.axis.end(),
                         [](double x, double y) { return std::abs(x) < std::abs(y); }) -
        j.axis.begin());
    a.min = j.min;
    a.max = j.max;
    a.home = std::clamp(0.0, a.min, a.max);
    axes_.push_back(a);
  }

  // The truth's errors: PIGEs constants drawn from their distributions, PDGEs Legendre series of
  // degree truth_degree on their axis' travel whose mean square over the travel is the error's
  // variance on average (c_k ~ N(0, sd^2 (2k+1)/(n+1)), since <P_k^2> = 1/(2k+1)).
  Rng truth_rng = stream(spec_.seed, kTruthStream);
  for (const ErrorDef& e : truth_desc_.errors) {
    TruthError t;
    for (std::size_t k = 0; k < axes_.size(); ++k) {
      if (axes_[k].body == e.body && e.dependence == Dependence::PDGE &&
          axes_[k].max > axes_[k].min)
        t.axis = static_cast<int>(k);
    }
    if (t.axis >= 0 && !axes_[static_cast<std::size_t>(t.axis)].linear)
      t.harmonics = spec_.rotary_harmonics;
    if (t.axis < 0) {
      t.coeff = {draw(e.distribution, truth_rng)};
    } else if (t.harmonics > 0) {
      // c_0 ~ N(0, sd²/(2H+1)), each cos and sin coefficient ~ N(0, 2 sd²/(2H+1)): the mean
      // square over a turn, c_0² + Σ (a_h² + b_h²)/2, is sd² on average.
      const Spread s = spread_of(e.distribution);
      const double m = 2.0 * t.harmonics + 1;
      t.coeff.push_back(s.mean + s.sd * truth_rng.normal() / std::sqrt(m));
      for (int k = 1; k < m; ++k) t.coeff.push_back(s.sd * truth_rng.normal() * std::sqrt(2 / m));
    } else {
      const Spread s = spread_of(e.distribution);
      const int n = spec_.truth_degree;
      for (int k = 0; k <= n; ++k)
        t.coeff.push_back(s.sd * truth_rng.normal() * std::sqrt((2.0 * k + 1) / (n + 1)));
      t.coeff[0] += s.mean;
    }
    errors_.push_back(t);
  }

  Rng layout_rng = stream(spec_.seed, kLayoutStream);
  build_layout(layout_rng);
  for (std::size_t k = 0; k < effects_.size(); ++k) {
    Rng effect_rng = stream(spec_.seed, k == 0 ? kEffectStream : kSecondEffectStream);
    build_effect(effects_[k], effect_rng);
  }
  build_regressors();
  draw_noise();
  scale_effects();
  place_gross_readings();
}

// ---------------------------------------------------------------------------------------------
// Kinematics

Eigen::Vector3d Synthesiser::tool_point(const NumericChain& chain, const std::vector<double>& q,
                                        const std::vector<double>& e) const {
  return chain.tool_in_workpiece(q, e).block<3, 1>(0, 3);
}

std::vector<int> Synthesiser::translation_errors(int axis) const {
  std::vector<int> out;
  for (std::size_t i = 0; i < truth_desc_.errors.size(); ++i) {
    const ErrorDef& e = truth_desc_.errors[i];
    if (e.body == axes_[axis].body && e.effect == ErrorEffect::Translation &&
        e.placement == ErrorPlacement::After && e.dependence == Dependence::PDGE)
      out.push_back(static_cast<int>(i));
  }
  return out;
}

// The error along (linear) or about (rotary) the axis' own direction: E_XX, E_CC.
int Synthesiser::positioning_error(int axis) const {
  const Vec3& ax = truth_desc_.bodies[static_cast<std::size_t>(axes_[axis].body)].joint.axis;
  const ErrorEffect want = axes_[axis].linear ? ErrorEffect::Translation : ErrorEffect::Rotation;
  for (std::size_t i = 0; i < truth_desc_.errors.size(); ++i) {
    const ErrorDef& e = truth_desc_.errors[i];
    if (e.body != axes_[axis].body || e.effect != want || e.placement != ErrorPlacement::After ||
        e.dependence != Dependence::PDGE)
      continue;
    const Vec3& d = e.direction;
    if (std::abs(d[0] * ax[0] + d[1] * ax[1] + d[2] * ax[2]) > 0.999) return static_cast<int>(i);
  }
  throw fail("axis " + axes_[axis].name + " has no positioning error in the machine file");
}

// ---------------------------------------------------------------------------------------------
// Effects

void Synthesiser::build_effect(Effect& e, Rng& rng) {
  const std::vector<int> linear = linear_axes();
  auto pick = [&](const std::vector<int>& v) {
    return v[static_cast<std::size_t>(rng.index(static_cast<int>(v.size())))];
  };
  // The axes an axis-bound effect may sit on: those the layout moves.
  std::vector<int> moving = linear;
  if (spec_.layout == "line") moving = {line_axis_};
  if (spec_.layout.rfind("ballbar", 0) == 0) moving = {plane_a_, plane_b_};
  if (spec_.layout.rfind("rtest", 0) == 0) {
    moving.clear();
    for (std::size_t k = 0; k < axes_.size(); ++k)
      if (distinct_positions(static_cast<int>(k)) > 1) moving.push_back(static_cast<int>(k));
  }
  std::set<int> measured_dims;
  if (column_dim_[0] < 0) {
    measured_dims = {axes_[plane_a_].dim, axes_[plane_b_].dim};
  } else {
    for (int d : column_dim_) measured_dims.insert(d);
  }
  auto dim_of = [&](int err) {
    const Vec3& d = truth_desc_.errors[static_cast<std::size_t>(err)].direction;
    return static_cast<int>(
        std::max_element(d.begin(), d.end(),
                         [](double x, double y) { return std::abs(x) < std::abs(y); }) -
        d.begin());
  };
  // A translation error of `axis` (line: its positioning error; a linear axis: along a measured
  // direction; a rotary axis: radial or axial, which the R-test sees in every direction).
  auto pick_error = [&](int axis) {
    if (spec_.layout == "line") return positioning_error(axis);
    std::vector<int> cand;
    for (int i : translation_errors(axis))
      if (!axes_[axis].linear || measured_dims.count(dim_of(i))) cand.push_back(i);
    if (cand.empty()) throw fail("axis " + axes_[axis].name + " has no measured translation error");
    return pick(cand);
  };

  if (e.name == "reversal") {
    // On an R-test, a rotary axis or a linear one with equal odds.
    std::vector<int> cand = moving;
    if (spec_.layout.rfind("rtest", 0) == 0) {
      std::vector<int> rot, lin;
      for (int k : moving) (axes_[k].linear ? lin : rot).push_back(k);
      cand = (rng.uniform() < 0.5 && !rot.empty()) || lin.empty() ? rot : lin;
    }
    e.axis = pick(cand);
    e.error = positioning_error(e.axis);
  } else if (e.name == "periodic" || e.name == "pdge_shape") {
    // A shape needs enough positions along its axis to be told from other shapes: on 7
    // positions a cubic PDGE leaves 3 shape degrees of freedom, which a period (amplitude,
    // phase, period) or a bump (height, centre, width) uses up, so no data could tell either
    // from a step there (docs/gap.md, "Verdict"). At least 9 positions; on an R-test the
    // turning axis (the linear axes follow the spheres, not a grid).
    std::vector<int> cand;
    for (int k : moving)
      if (distinct_positions(k) >= 9 && (spec_.layout.rfind("rtest", 0) != 0 || !axes_[k].linear))
        cand.push_back(k);
    if (cand.empty()) throw fail(e.name + ": no axis with 9 positions in layout " + spec_.layout);
    e.axis = pick(cand);
    e.error = pick_error(e.axis);
    const double step = axis_step(e.axis);
    const auto [lo, hi] = data_range(e.axis);
    if (e.name == "periodic") {
      e.period = 4 * step;  // 4 samples per period: resolved by every layout
      e.phase = rng.uniform(0, 2 * kPi);
    } else {
      e.width = std::max(step, (hi - lo) / 25);
      e.centre = rng.uniform(lo + 0.3 * (hi - lo), hi - 0.3 * (hi - lo));
    }
  } else if (e.name == "thermal_drift") {
    // The tool point grows in the tool's frame (the spindle) or in the machine's (the column,
    // the ram), and every linear axis' positioning scale grows from its reference point.
    e.machine_frame = rng.uniform() < 0.5;
    e.offset.assign(3, 0.0);
    for (double& v : e.offset) v = rng.normal();
    e.scale.assign(axes_.size(), 0.0);
    for (int k : linear) e.scale[static_cast<std::size_t>(k)] = rng.normal();
  } else if (e.name == "step") {
    e.step_in_time = rng.uniform() < 0.5;
    e.dim = *std::next(measured_dims.begin(), rng.index(static_cast<int>(measured_dims.size())));
    if (e.step_in_time) {
      e.step_at = std::round(rng.uniform(0.35, 0.65) * t_total_s_);
    } else {
      e.axis = pick(moving);
      const auto [lo, hi] = data_range(e.axis);
      e.step_at = std::round(rng.uniform(lo + 0.35 * (hi - lo), lo + 0.65 * (hi - lo)));
    }
  } else if (e.name == "tool_offset") {
    bool found = false;
    for (const Parameter& p : truth_desc_.parameters) found = found || p.name == "tool_length";
    if (!found) throw fail("tool_offset needs a parameter 'tool_length' in the machine");
  }
  if (e.error >= 0 && e.name != "missing_error") e.dim = dim_of(e.error);
}

std::vector<double> Synthesiser::errors_at(const Row& row, const std::vector<double>& amps,
                                           const std::vector<bool>& on) const {
  const std::size_t n = truth_desc_.errors.size();
  std::vector<double> e(n, 0.0);
  double p[16];
  for (std::size_t i = 0; i < n; ++i) {
    const TruthError& t = errors_[i];
    double v = t.coeff[0];
    if (t.axis >= 0) {
      const AxisInfo& a = axes_[static_cast<std::size_t>(t.axis)];
      const int terms = pdge_basis(t.harmonics, static_cast<int>(t.coeff.size()) - 1,
                                   row.axes[static_cast<std::size_t>(t.axis)], a.min, a.max, p);
      v = 0;
      for (int k = 0; k < terms; ++k) v += t.coeff[static_cast<std::size_t>(k)] * p[k];
    }
    e[i] = v * truth_desc_.errors[i].to_base;
  }
  for (std::size_t k = 0; k < effects_.size(); ++k) {
    const Effect& f = effects_[k];
    if (f.name == "higher_order") {
      for (double& v : e) v *= amps[k];  // both states: the exact chain against its linear part
      continue;
    }
    if (f.name == "missing_error") {
      e[static_cast<std::size_t>(f.error)] *= on[k] ? amps[k] : 0.0;
      continue;
    }
    if (!on[k] || f.error < 0) continue;
    const double q = f.axis >= 0 ? row.axes[static_cast<std::size_t>(f.axis)] : 0;
    // The amplitude in the error's base unit: µm -> mm, µrad -> rad.
    const bool rot =
        truth_desc_.errors[static_cast<std::size_t>(f.error)].effect == ErrorEffect::Rotation;
    const double amp = amps[k] * (rot ? 1e-6 : 1e-3);
    double add = 0;
    if (f.name == "reversal") {
      // Backlash: the axis stops short by half the lost motion in its direction of approach.
      add = -amp / 2 * row.dir[static_cast<std::size_t>(f.axis)];
    } else if (f.name == "periodic") {
      add = amp * std::sin(2 * kPi * q / f.period + f.phase);
    } else if (f.name == "pdge_shape") {
      const double z = (q - f.centre) / f.width;
      add = amp * std::exp(-0.5 * z * z);
    }
    e[static_cast<std::size_t>(f.error)] += add;
  }
  return e;
}

const Eigen::MatrixXd& Synthesiser::truth_jacobian(int pose) const {
  Eigen::MatrixXd& J = truth_jacobians_[static_cast<std::size_t>(pose)];
  if (J.size() != 0) return J;
  // h = 1e-5: truncation and round-off ~1e-9 relative.
  J = position_jacobian(*truth_chain_, poses_[static_cast<std::size_t>(pose)],
                        truth_desc_.errors.size(), 1e-5);
  return J;
}

Eigen::Vector3d Synthesiser::linear_deviation(const Row& row,
                                              const std::vector<double>& errors) const {
  const Eigen::Map<const Eigen::VectorXd> e(errors.data(),
                                            static_cast<Eigen::Index>(errors.size()));
  return truth_jacobian(row.pose) * e;
}

void Synthesiser::measure_row(std::size_t r, const Eigen::Vector3d& d_mm, double* out_um) const {
  const Row& row = rows_[r];
  const std::vector<double> zero(truth_desc_.errors.size(), 0.0);
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    if (column_dim_[c] >= 0) {
      out_um[c] = 1000 * d_mm[column_dim_[c]];
      continue;
    }
    // Ballbar: the distance between the balls minus the nominal one, exactly; the nominal
    // vector from the table ball to the tool ball from the chain.
    const Eigen::Vector3d v = tool_point(*truth_chain_, row.axes, zero) - centre_point_;
    out_um[c] = 1000 * ((v + d_mm).norm() - v.norm());
  }
}

std::vector<double> Synthesiser::evaluate(const std::vector<double>& amps,
                                          const std::vector<bool>& on) const {
  std::unique_ptr<NumericChain> tool_chain;
  const NumericChain* chain = truth_chain_.get();
  for (std::size_t k = 0; k < effects_.size(); ++k)
    if (on[k] && effects_[k].name == "tool_offset") {
      // The truth's tool is `amplitude` mm longer than the model's parameter says.
      tool_chain = std::make_unique<NumericChain>(truth_desc_);
      std::vector<double> p = truth_params_;
      for (std::size_t i = 0; i < p.size(); ++i)
        if (truth_desc_.parameters[i].name == "tool_length") p[i] += amps[k];
      tool_chain->set_parameters(p);
      chain = tool_chain.get();
    }
  std::vector<double> out(obs_row_.size());
  const double dmax = *std::max_element(drift_table_.begin(), drift_table_.end());
  const std::size_t nc = columns_.size();
  const std::vector<double> zero(truth_desc_.errors.size(), 0.0);
  bool higher_on = false;
  for (std::size_t k = 0; k < effects_.size(); ++k)
    higher_on = higher_on || (on[k] && effects_[k].name == "higher_order");
  const Eigen::Vector3d first = tool_point(*truth_chain_, rows_[0].axes, zero);
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const Row& row = rows_[r];
    const std::vector<double> e = errors_at(row, amps, on);
    std::vector<double> q = row.axes;
    Eigen::Vector3d grow = Eigen::Vector3d::Zero();  // thermal growth of the tool point, mm
    for (std::size_t k = 0; k < effects_.size(); ++k) {
      const Effect& f = effects_[k];
      if (!on[k] || f.name != "thermal_drift") continue;
      const double w = drift(row.t_s) / dmax * amps[k] / 1000;  // mm
      for (std::size_t a = 0; a < axes_.size(); ++a)
        if (axes_[a].linear && axes_[a].max > axes_[a].min)
          q[a] +=
              w * f.scale[a] * (row.axes[a] - axes_[a].home) / ((axes_[a].max - axes_[a].min) / 2);
      const Eigen::Vector3d v(f.offset[0], f.offset[1], f.offset[2]);
      const Eigen::Matrix3d R =
          f.machine_frame
              ? Eigen::Matrix3d(
                    truth_chain_->workpiece_in_base(row.axes).block<3, 3>(0, 0).transpose())
              : Eigen::Matrix3d(truth_chain_->tool_in_workpiece(row.axes, zero).block<3, 3>(0, 0));
      grow += w * (R * v);
    }
    const Eigen::Vector3d nominal = tool_point(*truth_chain_, row.axes, zero);
    Eigen::Vector3d d;
    if (higher_order_ && !higher_on) {
      d = linear_deviation(row, e);
    } else {
      d = tool_point(*chain, q, e) - nominal + grow;
    }
    for (std::size_t k = 0; k < effects_.size(); ++k) {
      const Effect& f = effects_[k];
      if (!on[k] || f.name != "step") continue;
      const double x = f.step_in_time ? row.t_s : row.axes[static_cast<std::size_t>(f.axis)];
      if (x >= f.step_at) d[f.dim] += amps[k] / 1000;
    }
    double* o = &out[r * nc];
    measure_row(r, d, o);
    for (std::size_t k = 0; k < effects_.size(); ++k) {
      if (!on[k] || effects_[k].name != "setup") continue;
      // Instrument cosine error: it reads (1 - k) of every displacement from its zero (the first
      // pose; the ballbar's calibrated length), k = amplitude in ppm.
      const double kk = -amps[k] * 1e-6;
      for (std::size_t c = 0; c < nc; ++c)
        o[c] += column_dim_[c] < 0 ? 1000 * kk * radius_mm_
                                   : 1000 * kk * (nominal[column_dim_[c]] - first[column_dim_[c]]);
    }
  }
  return out;
}

std::vector<double> Synthesiser::measured(bool with_effect) const {
  std::vector<double> amps;
  for (const Effect& e : effects_) amps.push_back(e.amplitude);
  return evaluate(amps, std::vector<bool>(effects_.size(), with_effect));
}

std::vector<double> Synthesiser::signal(std::size_t k, double amplitude) const {
  std::vector<double> amps;
  for (const Effect& e : effects_) amps.push_back(e.amplitude);
  amps[k] = amplitude;
  std::vector<bool> on(effects_.size(), false);
  std::vector<double> off = evaluate(amps, on);
  on[k] = true;
  std::vector<double> s = evaluate(amps, on);
  for (std::size_t i = 0; i < s.size(); ++i) s[i] -= off[i];
  return s;
}

std::vector<double> Synthesiser::effect_signal(std::size_t k) const {
  return signal(k, effects_[k].amplitude);
}
// ---------------------------------------------------------------------------------------------
// What the model can absorb: the first-order model of the model machine (its Jacobian at zero
// error, from the exact chain) with every PIGE a constant and every PDGE a Legendre series of
// degree fit_degree on its axis' travel. Any identification of that model fits at least as well
// on the training data, so only the residual of an effect on these regressors can show in
// held-out data.

namespace {
struct RegressorLayout {
  std::vector<int> error;  // model error of each column
  std::vector<int> term;   // basis term of each column
};
}  // namespace

void Synthesiser::build_regressors() {
  const std::size_t nm = model_desc_.errors.size();
  const std::vector<int> model_axes = model_desc_.axes();
  std::vector<int> axis_of(nm, -1);  // index into axes_ of a PDGE's axis
  for (std::size_t i = 0; i < nm; ++i) {
    const ErrorDef& e = model_desc_.errors[i];
    if (e.dependence != Dependence::PDGE) continue;
    for (std::size_t k = 0; k < model_axes.size(); ++k) {
      const Joint& j = model_desc_.bodies[static_cast<std::size_t>(model_axes[k])].joint;
      if (model_axes[k] == e.body && j.max > j.min) {
        for (std::size_t a = 0; a < axes_.size(); ++a)
          if (axes_[a].name == j.coordinate) axis_of[i] = static_cast<int>(a);
      }
    }
  }
  // Model Jacobian per pose by central differences of the exact chain. With h = 1e-4 (mm, rad)
  // truncation (h^2/6 relative) and round-off (eps * 1000 mm / h) both stay near 1e-9, far
  // below the rank threshold below: exactly dependent columns (E_XY[1] and E_XX[1] both move dx)
  // must stay dependent, or their round-off would "absorb" signal with huge coefficients.
  std::vector<Eigen::MatrixXd> jac(poses_.size());
  for (std::size_t p = 0; p < poses_.size(); ++p) {
    // The model's axes are the truth's (same bodies); map by coordinate name to be safe.
    std::vector<double> ax(model_axes.size());
    for (std::size_t k = 0; k < model_axes.size(); ++k) {
      const std::string& name =
          model_desc_.bodies[static_cast<std::size_t>(model_axes[k])].joint.coordinate;
      for (std::size_t a = 0; a < axes_.size(); ++a)
        if (axes_[a].name == name) ax[k] = poses_[p][a];
    }
    jac[p] = position_jacobian(*model_chain_, ax, nm, 1e-4);
  }
  RegressorLayout lay;
  for (std::size_t i = 0; i < nm; ++i) {
    // A rotary axis' PDGE in Fourier (rotary_harmonics), others Legendre of fit_degree.
    const int harmonics = axis_of[i] >= 0 && !axes_[static_cast<std::size_t>(axis_of[i])].linear
                              ? spec_.rotary_harmonics
                              : 0;
    const int terms = axis_of[i] < 0 ? 1 : harmonics > 0 ? 2 * harmonics + 1 : spec_.fit_degree + 1;
    for (int k = 0; k < terms; ++k) {
      lay.error.push_back(static_cast<int>(i));
      lay.term.push_back(k);
    }
  }
  const Eigen::Index n = static_cast<Eigen::Index>(obs_row_.size());
  Eigen::MatrixXd A(n, static_cast<Eigen::Index>(lay.error.size()));
  const std::vector<double> zero(model_desc_.errors.size(), 0.0);
  double phi[16];
  for (Eigen::Index o = 0; o < n; ++o) {
    const Row& row = rows_[static_cast<std::size_t>(obs_row_[static_cast<std::size_t>(o)])];
    const int dim = column_dim_[static_cast<std::size_t>(obs_col_[static_cast<std::size_t>(o)])];
    const Eigen::MatrixXd& J = jac[static_cast<std::size_t>(row.pose)];
    Eigen::RowVectorXd g;
    if (dim >= 0) {
      g = J.row(dim);
    } else {
      // dr sees the deviation along the nominal ball-to-ball direction.
      const Eigen::Vector3d u =
          (tool_point(*model_chain_, row.axes, zero) - centre_point_).normalized();
      g = u.transpose() * J;
    }
    int last_error = -1;
    for (std::size_t c = 0; c < lay.error.size(); ++c) {
      const int i = lay.error[c];
      if (i != last_error && axis_of[static_cast<std::size_t>(i)] >= 0) {
        const auto ai = static_cast<std::size_t>(axis_of[static_cast<std::size_t>(i)]);
        const AxisInfo& a = axes_[ai];
        pdge_basis(a.linear ? 0 : spec_.rotary_harmonics, spec_.fit_degree, row.axes[ai], a.min,
                   a.max, phi);
      }
      last_error = i;
      const double basis = axis_of[static_cast<std::size_t>(i)] >= 0 ? phi[lay.term[c]] : 1.0;
      A(o, static_cast<Eigen::Index>(c)) = g[i] * basis;
    }
  }
  // Drop columns the layout does not see (e.g. E_AZ at tool_length 0) and normalise the rest.
  double biggest = 0;
  for (Eigen::Index c = 0; c < A.cols(); ++c) biggest = std::max(biggest, A.col(c).norm());
  std::vector<Eigen::Index> keep;
  for (Eigen::Index c = 0; c < A.cols(); ++c)
    if (A.col(c).norm() > 1e-7 * biggest) keep.push_back(c);
  regressors_.resize(n, static_cast<Eigen::Index>(keep.size()));
  regressor_error_.clear();
  for (std::size_t c = 0; c < keep.size(); ++c) {
    regressors_.col(static_cast<Eigen::Index>(c)) = A.col(keep[c]) / A.col(keep[c]).norm();
    regressor_error_.push_back(lay.error[static_cast<std::size_t>(keep[c])]);
  }
  span_ = Span(regressors_);
}

// An orthonormal basis of the regressors' column space: the left singular vectors whose singular
// values exceed 1e-7 of the largest. Those are either O(1) or round-off (identification
// condition numbers are ~40), so any cut between 1e-12 and 1e-3 gives the same space;
// `smallest_kept` and `largest_dropped` record the gap.
Synthesiser::Span::Span(const Eigen::MatrixXd& A) {
  // Jacobi, not Eigen 3.4.0's BDCSVD (out-of-bounds read on rank-deficient input: src/uq/lsq.cpp).
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU);
  const Eigen::VectorXd& sv = svd.singularValues();
  Eigen::Index k = 0;
  while (k < sv.size() && sv[k] > 1e-7 * sv[0]) ++k;
  basis = svd.matrixU().leftCols(k);
  smallest_kept = k > 0 ? sv[k - 1] / sv[0] : 0.0;
  largest_dropped = k < sv.size() ? sv[k] / sv[0] : 0.0;
}

Eigen::VectorXd Synthesiser::Span::residual(const Eigen::VectorXd& s) const {
  return s - basis * (basis.transpose() * s);
}

std::vector<double> Synthesiser::unabsorbed_rms(const std::vector<double>& signal_um) const {
  const Eigen::Map<const Eigen::VectorXd> s(signal_um.data(),
                                            static_cast<Eigen::Index>(signal_um.size()));
  const Eigen::VectorXd r = span_.residual(s);
  std::vector<double> sum(columns_.size(), 0.0), count(columns_.size(), 0.0);
  for (std::size_t o = 0; o < signal_um.size(); ++o) {
    sum[static_cast<std::size_t>(obs_col_[o])] +=
        r[static_cast<Eigen::Index>(o)] * r[static_cast<Eigen::Index>(o)];
    count[static_cast<std::size_t>(obs_col_[o])] += 1;
  }
  for (std::size_t c = 0; c < sum.size(); ++c) sum[c] = std::sqrt(sum[c] / count[c]);
  return sum;
}

std::vector<double> Synthesiser::raw_rms(const std::vector<double>& signal_um) const {
  std::vector<double> sum(columns_.size(), 0.0), count(columns_.size(), 0.0);
  for (std::size_t o = 0; o < signal_um.size(); ++o) {
    sum[static_cast<std::size_t>(obs_col_[o])] += signal_um[o] * signal_um[o];
    count[static_cast<std::size_t>(obs_col_[o])] += 1;
  }
  for (std::size_t c = 0; c < sum.size(); ++c) sum[c] = std::sqrt(sum[c] / count[c]);
  return sum;
}

// The noise: N(0, sigma_i^2) on every measured value; heteroscedastic, sigma_i grows 4x with the
// distance of the pose from the first one (a tracker's range), scaled so that the RMS of
// sigma_i over the observations is the nominal sigma. T_spindle carries N(0, 0.01^2) K.
void Synthesiser::draw_noise() {
  Rng rng = stream(spec_.seed, kNoiseStream);
  sigma_.assign(obs_row_.size(), spec_.noise_um);
  if (spec_.heteroscedastic) {
    const std::vector<double> zero(truth_desc_.errors.size(), 0.0);
    const Eigen::Vector3d p0 = tool_point(*truth_chain_, rows_[0].axes, zero);
    std::vector<double> dist(poses_.size());
    double far = 0;
    for (std::size_t p = 0; p < poses_.size(); ++p) {
      dist[p] = (tool_point(*truth_chain_, poses_[p], zero) - p0).norm();
      far = std::max(far, dist[p]);
    }
    double ss = 0;
    for (std::size_t o = 0; o < sigma_.size(); ++o) {
      const double rho =
          far > 0
              ? dist[static_cast<std::size_t>(rows_[static_cast<std::size_t>(obs_row_[o])].pose)] /
                    far
              : 0;
      sigma_[o] = 1 + 3 * rho;
      ss += sigma_[o] * sigma_[o];
    }
    const double scale = spec_.noise_um / std::sqrt(ss / static_cast<double>(sigma_.size()));
    for (double& s : sigma_) s *= scale;
  }
  noise_um_.resize(obs_row_.size());
  for (std::size_t o = 0; o < noise_um_.size(); ++o) noise_um_[o] = sigma_[o] * rng.normal();
  temp_noise_.resize(rows_.size());
  for (double& v : temp_noise_) v = kTempNoiseK * rng.normal();
  noise_rms_um_ = rms(noise_um_);
}

// Gross readings: `outliers` distinct observations, each off by 30-60 sigma with a random sign
// (a laser beam interrupted, a probe that slipped).
void Synthesiser::place_gross_readings() {
  Rng rng = stream(spec_.seed, kGrossStream);
  std::set<std::size_t> used;
  while (static_cast<int>(gross_.size()) < spec_.outliers && used.size() < obs_row_.size()) {
    const std::size_t o = static_cast<std::size_t>(rng.index(static_cast<int>(obs_row_.size())));
    if (!used.insert(o).second) continue;
    const double size = rng.uniform(30, 60) * spec_.noise_um * (rng.uniform() < 0.5 ? -1 : 1);
    gross_.push_back({o, size});
  }
  std::sort(gross_.begin(), gross_.end(), [](const GrossReading& a, const GrossReading& b) {
    return a.observation < b.observation;
  });
}

// Each effect's amplitude so that its held-out (unabsorbable) signal RMS, in its most affected
// measured column, is factor * noise. Effects the model absorbs entirely (visible fraction below
// 2 %) are scaled on their raw signal instead and are expected to be diagnosed as `none`.
void Synthesiser::scale_effects() {
  for (std::size_t k = 0; k < effects_.size(); ++k) {
    Effect& f = effects_[k];
    double amp = 1;  // µm or µrad (backlash, amplitudes, step), ppm (setup), mm (tool), x (scales)
    if (f.name == "setup") amp = 10;
    if (f.name == "tool_offset") amp = 100;
    if (f.name == "higher_order") amp = 100;  // second-order terms of about a micrometre
    f.amplitude = amp;
    std::vector<double> s = signal(k, amp);
    const double v0 = max_of(unabsorbed_rms(s)), r0 = max_of(raw_rms(s));
    // An effect that does not reach the measured values (E_AX in a line run of X measures
    // nothing of it) keeps its nominal amplitude: the data are effect-free in all but name.
    f.observable = r0 > 1e-3;
    f.identifiable = f.observable && v0 >= kVisibleFraction * r0;
    const double target = f.observable ? spec_.factor * spec_.noise_um : 0.0;
    auto metric = [&](const std::vector<double>& sig) {
      return f.identifiable ? max_of(unabsorbed_rms(sig)) : max_of(raw_rms(sig));
    };
    if (target > 0) {
      // Secant iteration on log(metric) against log(amplitude); slope 1 for effects linear in
      // their amplitude, about 2 for higher_order (second-order terms of scaled errors).
      double la = std::log(amp), lm = std::log(metric(s));
      double slope = f.name == "higher_order" ? 2 : 1;
      for (int it = 0; it < 60 && std::abs(lm - std::log(target)) > 1e-7; ++it) {
        const double la_new = la + (std::log(target) - lm) / slope;
        const double lm_new = std::log(metric(signal(k, std::exp(la_new))));
        if (std::abs(la_new - la) > 1e-12) {
          const double sl = (lm_new - lm) / (la_new - la);
          if (sl > 0.5 && sl < 4) slope = sl;
        }
        la = la_new;
        lm = lm_new;
      }
      f.amplitude = std::exp(la);
      if (std::abs(lm - std::log(target)) > 1e-4)
        throw fail("could not scale effect '" + f.name + "' to its target signal");
    }
    s = signal(k, f.amplitude);
    f.residual = span_.residual(
        Eigen::Map<const Eigen::VectorXd>(s.data(), static_cast<Eigen::Index>(s.size())));
    f.unabsorbed_by_column = unabsorbed_rms(s);
    f.raw_by_column = raw_rms(s);
    f.unabsorbed_rms = max_of(f.unabsorbed_by_column);
    f.raw_rms = max_of(f.raw_by_column);
  }
}

std::vector<std::pair<std::string, double>> Synthesiser::missing_error_visibility() const {
  // First-order signal of each error alone (its drawn shape), projected on the regressors of
  // every other error: what a model without that error could not absorb.
  std::vector<std::pair<std::string, double>> out;
  const std::size_t n = truth_desc_.errors.size();
  const std::vector<double> amps(effects_.size(), 1.0);
  const std::vector<bool> off(effects_.size(), false);
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<double> sig(obs_row_.size());
    for (std::size_t o = 0; o < sig.size(); ++o) {
      const Row& row = rows_[static_cast<std::size_t>(obs_row_[o])];
      std::vector<double> e = errors_at(row, amps, off);
      for (std::size_t k = 0; k < n; ++k)
        if (k != i) e[k] = 0;
      const Eigen::Vector3d d = linear_deviation(row, e);
      double v[1];
      measure_row(static_cast<std::size_t>(obs_row_[o]), d, v);
      const int dim = column_dim_[static_cast<std::size_t>(obs_col_[o])];
      sig[o] = dim >= 0 ? 1000 * d[dim] : v[0];
    }
    std::vector<Eigen::Index> keep;
    for (std::size_t c = 0; c < regressor_error_.size(); ++c)
      if (regressor_error_[c] != static_cast<int>(i)) keep.push_back(static_cast<Eigen::Index>(c));
    Eigen::MatrixXd A(regressors_.rows(), static_cast<Eigen::Index>(keep.size()));
    for (std::size_t c = 0; c < keep.size(); ++c)
      A.col(static_cast<Eigen::Index>(c)) = regressors_.col(keep[c]);
    const Eigen::Map<const Eigen::VectorXd> s(sig.data(), static_cast<Eigen::Index>(sig.size()));
    const Eigen::VectorXd r = Span(A).residual(s);
    std::vector<double> res(r.data(), r.data() + r.size());
    // Below 1e-9 um the error does not reach the measured values at all (E_AZ at tool length 0).
    const double raw = max_of(raw_rms(sig));
    out.emplace_back(truth_desc_.errors[i].name, raw > 1e-9 ? max_of(raw_rms(res)) / raw : 0.0);
  }
  return out;
}

// The held-out signal of one effect in one measured column binned along a coordinate (an axis,
// or time when axis < 0): one bin per distinct position when there are at most 25, else 20
// equal bins. Each bin gives its data range, size and RMS; bins with at least half the largest
// RMS are "hot".
nlohmann::json Synthesiser::signal_bins(const Effect& e, int axis, std::size_t column) const {
  std::vector<std::pair<double, double>> v;  // coordinate, residual
  for (std::size_t o = 0; o < obs_row_.size(); ++o) {
    if (static_cast<std::size_t>(obs_col_[o]) != column) continue;
    const Row& row = rows_[static_cast<std::size_t>(obs_row_[o])];
    v.emplace_back(axis < 0 ? row.t_s : row.axes[static_cast<std::size_t>(axis)],
                   e.residual[static_cast<Eigen::Index>(o)]);
  }
  std::sort(v.begin(), v.end());
  std::vector<double> distinct;
  for (const auto& p : v)
    if (distinct.empty() || p.first > distinct.back() + 1e-9) distinct.push_back(p.first);
  const bool per_value = distinct.size() <= 25;
  const double lo = v.front().first, hi = v.back().first;
  struct Bin {
    double from = INFINITY, to = -INFINITY, ss = 0;
    std::size_t n = 0;
  };
  std::vector<Bin> bins(per_value ? distinct.size() : 20);
  std::size_t d = 0;
  for (const auto& [x, r] : v) {
    std::size_t b = 0;
    if (per_value) {
      while (x > distinct[d] + 1e-9) ++d;
      b = d;
    } else {
      b = std::min<std::size_t>(19, static_cast<std::size_t>(20 * (x - lo) / (hi - lo)));
    }
    bins[b].from = std::min(bins[b].from, x);
    bins[b].to = std::max(bins[b].to, x);
    bins[b].ss += r * r;
    ++bins[b].n;
  }
  double peak = 0;
  for (const Bin& b : bins)
    if (b.n) peak = std::max(peak, std::sqrt(b.ss / static_cast<double>(b.n)));
  nlohmann::json out = nlohmann::json::array();
  for (const Bin& b : bins) {
    if (!b.n) continue;
    const double r = std::sqrt(b.ss / static_cast<double>(b.n));
    out.push_back(
        {{"from", b.from}, {"to", b.to}, {"n", b.n}, {"rms_um", r}, {"hot", r >= 0.5 * peak}});
  }
  return out;
}

std::string Synthesiser::expected_of(const Effect& e) const {
  if (!e.identifiable) return "none";
  return e.name == "step" ? "unexplained" : e.name;
}

std::size_t Synthesiser::dominant_column(const Effect& e) const {
  const auto& v = e.identifiable ? e.unabsorbed_by_column : e.raw_by_column;
  return static_cast<std::size_t>(std::max_element(v.begin(), v.end()) - v.begin());
}

// ---------------------------------------------------------------------------------------------
// Output

std::vector<std::string> Synthesiser::comment_lines() const {
  std::vector<std::string> head_lines;
  head_lines.push_back(
      "# Synthetic measurement written by weilgen_gap_synth (bench/gap/README.md)");
  head_lines.push_back("# machine: " + model_desc_.name);
  head_lines.push_back("# layout: " + spec_.layout);
  const bool ballbar = column_dim_[0] < 0;
  if (spec_.layout == "line") {
    head_lines.push_back("# instrument: synthetic laser interferometer");
    head_lines.push_back("# axis: " + axes_[static_cast<std::size_t>(line_axis_)].name);
  } else if (ballbar) {
    head_lines.push_back("# instrument: synthetic ballbar");
    head_lines.push_back("# plane: " + axes_[static_cast<std::size_t>(plane_a_)].name +
                         axes_[static_cast<std::size_t>(plane_b_)].name);
    std::string centre;
    for (std::size_t k = 0; k < axes_.size(); ++k)
      centre += (k ? ", " : "") + axes_[k].name + "=" + fmt("%.10g", centre_[k]);
    head_lines.push_back("# centre: " + centre);
    head_lines.push_back("# radius: " + fmt("%.10g", radius_mm_) + " mm");
    head_lines.push_back("# feed: ccw");
  } else if (spec_.layout.rfind("rtest", 0) == 0) {
    head_lines.push_back("# instrument: synthetic R-test (sphere centre relative to the tool)");
  } else {
    head_lines.push_back("# instrument: synthetic laser tracker");
  }
  return head_lines;
}

std::string Synthesiser::csv(bool with_effect, bool with_noise, bool with_gross) const {
  std::vector<double> v = measured(with_effect);
  if (with_noise) {
    for (std::size_t i = 0; i < v.size(); ++i) v[i] += noise_um_[i];
    if (with_gross)
      for (const GrossReading& g : gross_) v[g.observation] += g.size_um;
  }
  const std::vector<std::string> head_lines = comment_lines();
  const bool ballbar = column_dim_[0] < 0;
  std::vector<std::string> head;
  for (const AxisInfo& a : axes_) head.push_back(a.name);
  head.push_back("t_s");
  if (spec_.layout == "line") {
    head.push_back("dir");
  } else if (ballbar) {
    head.push_back("dir");
    head.push_back("dir_" + axes_[static_cast<std::size_t>(plane_a_)].name);
    head.push_back("dir_" + axes_[static_cast<std::size_t>(plane_b_)].name);
  } else {
    for (const AxisInfo& a : axes_) head.push_back("dir_" + a.name);
  }
  head.push_back("cycle");
  head.push_back("T_spindle");
  if (ballbar) head.push_back("angle_deg");
  for (const std::string& c : columns_) head.push_back(c);
  std::string s;
  for (const std::string& l : head_lines) s += l + "\n";
  for (std::size_t i = 0; i < head.size(); ++i) s += (i ? "," : "") + head[i];
  s += "\n";
  const std::size_t nc = columns_.size();
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const Row& row = rows_[r];
    std::string line;
    for (double a : row.axes) line += fmt("%.10g", a) + ",";
    line += fmt("%.2f", row.t_s) + ",";
    if (spec_.layout == "line") {
      line += std::to_string(row.feed_dir) + ",";
    } else if (ballbar) {
      line += std::to_string(row.feed_dir) + "," +
              std::to_string(row.dir[static_cast<std::size_t>(plane_a_)]) + "," +
              std::to_string(row.dir[static_cast<std::size_t>(plane_b_)]) + ",";
    } else {
      for (int d : row.dir) line += std::to_string(d) + ",";
    }
    line += std::to_string(row.cycle) + ",";
    line += fmt("%.4f", temperature(row.t_s) + temp_noise_[r]);
    if (ballbar) line += "," + fmt("%.10g", row.angle_deg);
    for (std::size_t c = 0; c < nc; ++c) line += "," + fmt("%.6f", v[r * nc + c]);
    s += line + "\n";
  }
  return s;
}

nlohmann::json Synthesiser::effect_json(const Effect& f) const {
  using nlohmann::json;
  auto output_name = [&](std::size_t c) {
    return column_dim_[c] >= 0 ? std::string(kDimNames[column_dim_[c]]) : std::string("dr");
  };
  json eff;
  eff["name"] = f.name;
  eff["observable"] = f.observable;
  eff["identifiable"] = f.identifiable;
  eff["expected"] = expected_of(f);
  eff["heldout_signal_rms_um"] = f.unabsorbed_rms;
  eff["raw_signal_rms_um"] = f.raw_rms;
  eff["visible_fraction"] = f.raw_rms > 0 ? f.unabsorbed_rms / f.raw_rms : 0.0;
  eff["snr"] = spec_.noise_um > 0 ? f.unabsorbed_rms / spec_.noise_um : 0.0;
  json by_out = json::object(), raw_out = json::object();
  for (std::size_t c = 0; c < f.unabsorbed_by_column.size(); ++c) {
    by_out[output_name(c)] = f.unabsorbed_by_column[c];
    raw_out[output_name(c)] = f.raw_by_column[c];
  }
  eff["heldout_signal_rms_by_output_um"] = by_out;
  eff["raw_signal_rms_by_output_um"] = raw_out;
  const std::size_t dominant = dominant_column(f);
  json params = json::object();
  const std::string out_name = output_name(dominant);
  json loc = {{"kind", "output"}, {"by", json::array()}, {"output", out_name}};
  const std::string axis_name =
      f.axis >= 0 ? axes_[static_cast<std::size_t>(f.axis)].name : std::string();
  const std::string error_name =
      f.error >= 0 ? truth_desc_.errors[static_cast<std::size_t>(f.error)].name : std::string();
  const bool rot = f.error >= 0 && truth_desc_.errors[static_cast<std::size_t>(f.error)].effect ==
                                       ErrorEffect::Rotation;
  const std::string axis_unit =
      f.axis >= 0 && !axes_[static_cast<std::size_t>(f.axis)].linear ? "deg" : "mm";
  if (f.name == "reversal") {
    params = {{"axis", axis_name},
              {"error", error_name},
              {rot ? "backlash_urad" : "backlash_um", f.amplitude},
              {"model", "error += -backlash/2 * dir (approach direction of the axis)"}};
    loc = {{"kind", "direction"}, {"by", {"dir_" + axis_name, "dir"}}, {"output", out_name}};
  } else if (f.name == "periodic") {
    params = {{"axis", axis_name},
              {"error", error_name},
              {"period_" + axis_unit, f.period},
              {rot ? "amplitude_urad" : "amplitude_um", f.amplitude},
              {"phase_rad", f.phase}};
    const auto [lo, hi] = data_range(f.axis);
    loc = {{"kind", "whole"}, {"by", {axis_name}}, {"output", out_name}, {"from", lo}, {"to", hi}};
  } else if (f.name == "pdge_shape") {
    params = {{"axis", axis_name},
              {"error", error_name},
              {"centre_" + axis_unit, f.centre},
              {"width_" + axis_unit, f.width},
              {rot ? "amplitude_urad" : "amplitude_um", f.amplitude},
              {"shape", "a exp(-(q-c)^2/(2 w^2))"}};
    const auto [lo, hi] = data_range(f.axis);
    loc = {{"kind", "interval"},
           {"by", {axis_name}},
           {"output", out_name},
           {"from", std::max(lo, f.centre - 2 * f.width)},
           {"to", std::min(hi, f.centre + 2 * f.width)},
           {"at", f.centre}};
  } else if (f.name == "thermal_drift") {
    const double dmax = *std::max_element(drift_table_.begin(), drift_table_.end());
    json scale = json::object();
    for (std::size_t a = 0; a < axes_.size(); ++a)
      if (axes_[a].linear && axes_[a].max > axes_[a].min)
        scale[axes_[a].name] =
            1000 * f.amplitude * f.scale[a] / (dmax * (axes_[a].max - axes_[a].min) / 2);
    json offset = json::object();
    for (int d = 0; d < 3; ++d)
      offset[std::string(1, "xyz"[d])] = f.amplitude * f.offset[static_cast<std::size_t>(d)] / dmax;
    params = {{"temperature", "T_spindle"},
              {"frame", f.machine_frame ? "machine" : "tool"},
              {"model",
               "the tool point moves by D(t) offset (in the frame), each linear axis by D(t) "
               "scale (q - home); D: first-order lag of T_spindle - 22 degC"},
              {"tau_lag_s", t_total_s_ / 12},
              {"drift_max_K", dmax},
              {"offset_um_per_K", offset},
              {"scale_um_per_m_per_K", scale}};
    // Where the lagged rise is at least half its peak.
    double from = t_total_s_, to = 0, at = 0, best = -1;
    for (std::size_t i = 0; i < drift_table_.size(); ++i) {
      const double t = t_total_s_ * i / (drift_table_.size() - 1);
      if (drift_table_[i] >= 0.5 * dmax) {
        from = std::min(from, t);
        to = std::max(to, t);
      }
      if (drift_table_[i] > best) {
        best = drift_table_[i];
        at = t;
      }
    }
    loc = {{"kind", "interval"}, {"by", {"t_s", "T_spindle", "cycle"}},
           {"output", out_name}, {"from", from},
           {"to", to},           {"at", at}};
  } else if (f.name == "step") {
    const std::string coord = f.step_in_time ? "t_s" : axis_name;
    double hi = t_total_s_;
    if (!f.step_in_time) hi = data_range(f.axis).second;
    params = {{"kind", f.step_in_time ? "time" : "position"},
              {"coordinate", coord},
              {"at", f.step_at},
              {"output", kDimNames[f.dim]},
              {"step_um", f.amplitude}};
    json by = json::array({coord});
    if (f.step_in_time) by.push_back("cycle");
    loc = {{"kind", "interval"}, {"by", by}, {"output", out_name},
           {"from", f.step_at},  {"to", hi}, {"at", f.step_at}};
  } else if (f.name == "higher_order") {
    params = {{"error_scale", f.amplitude},
              {"model_order", model_desc_.algebra.order},
              {"how",
               "every truth error multiplied by error_scale; the exact chain minus its "
               "first-order part is the effect"}};
  } else if (f.name == "missing_error") {
    params = {{"error", spec_.missing_error},
              {"unit", truth_desc_.errors[static_cast<std::size_t>(f.error)].unit},
              {"scale_of_drawn", f.amplitude},
              {"model_machine", model_machine_}};
  } else if (f.name == "tool_offset") {
    double model_len = 0;
    for (std::size_t i = 0; i < model_desc_.parameters.size(); ++i)
      if (model_desc_.parameters[i].name == "tool_length") model_len = model_params_[i];
    params = {{"tool_length_model_mm", model_len},
              {"tool_length_truth_mm", model_len + f.amplitude},
              {"offset_mm", f.amplitude}};
  } else if (f.name == "setup") {
    params = {{"scale_ppm", -f.amplitude},
              {"cosine_angle_mrad", 1e3 * std::acos(1 - f.amplitude * 1e-6)},
              {"model", "reading = (1 - k) x displacement from the instrument zero (first pose)"}};
  }
  eff["params"] = params;
  // Where the held-out signal is, along the primary coordinate: what a localisation is judged by.
  if (loc["kind"] == "interval" || loc["kind"] == "whole") {
    const std::string by = loc["by"][0].get<std::string>();
    int axis = -1;
    for (std::size_t k = 0; k < axes_.size(); ++k)
      if (axes_[k].name == by) axis = static_cast<int>(k);
    loc["bins"] = signal_bins(f, axis, dominant);
  }
  eff["localise"] = loc;
  return eff;
}

nlohmann::json Synthesiser::truth() const {
  using nlohmann::json;
  json j;
  j["generator"] = "weilgen_gap_synth";
  j["format"] = 2;
  j["scenario"] = {{"machine", truth_desc_.name},
                   {"model_machine", model_machine_},
                   {"effect", spec_.effect},
                   {"factor", spec_.factor},
                   {"noise_sigma_um", spec_.noise_um},
                   {"layout", spec_.layout},
                   {"seed", spec_.seed},
                   {"truth_degree", spec_.truth_degree},
                   {"fit_degree", spec_.fit_degree},
                   {"rotary_harmonics", spec_.rotary_harmonics},
                   {"outliers", spec_.outliers},
                   {"heteroscedastic", spec_.heteroscedastic}};
  // The verdict expected: every identifiable library effect named; a step makes it unexplained.
  std::vector<std::string> expected;
  bool step = false;
  for (const Effect& f : effects_) {
    const std::string e = expected_of(f);
    if (e == "unexplained") step = true;
    if (e != "none" && e != "unexplained") expected.push_back(e);
  }
  std::string verdict = step ? "unexplained" : expected.empty() ? "none" : expected[0];
  if (!step)
    for (std::size_t k = 1; k < expected.size(); ++k) verdict += "+" + expected[k];
  j["expected_verdict"] = verdict;
  j["expected_effects"] = step ? json::array() : json(expected);
  j["noise_sigma_um"] = spec_.noise_um;
  j["noise_rms_um"] = noise_rms_um_;
  j["noise_sigma_range_um"] = {*std::min_element(sigma_.begin(), sigma_.end()),
                               *std::max_element(sigma_.begin(), sigma_.end())};
  j["rows"] = rows_.size();
  j["observations"] = obs_row_.size();
  j["duration_s"] = t_total_s_;
  j["measured_columns"] = columns_;
  j["model_regressors"] = {{"columns", regressors_.cols()},
                           {"rank", span_.basis.cols()},
                           {"smallest_kept_singular_value", span_.smallest_kept},
                           {"largest_dropped_singular_value", span_.largest_dropped}};
  if (!spheres_.empty()) j["rtest_spheres_mm"] = spheres_;
  json effs = json::array();
  for (const Effect& f : effects_) effs.push_back(effect_json(f));
  j["effects"] = effs;
  // The first effect as `effect` (format 1 readers), or an empty one.
  if (!effects_.empty()) {
    j["effect"] = effs[0];
    j["localise"] = effs[0]["localise"];
  } else {
    j["effect"] = {{"name", "none"},
                   {"observable", true},
                   {"identifiable", true},
                   {"heldout_signal_rms_um", 0},
                   {"raw_signal_rms_um", 0},
                   {"visible_fraction", 0},
                   {"snr", 0}};
    j["localise"] = {{"kind", "none"}, {"by", json::array()}};
  }
  json gross = json::array();
  for (const GrossReading& g : gross_) {
    const std::size_t row = static_cast<std::size_t>(obs_row_[g.observation]);
    gross.push_back({{"observation", g.observation},
                     {"line", comment_lines().size() + 1 + row + 1},
                     {"output", columns_[static_cast<std::size_t>(obs_col_[g.observation])]},
                     {"size_um", g.size_um}});
  }
  j["gross_readings"] = gross;

  json errs = json::array();
  for (std::size_t i = 0; i < truth_desc_.errors.size(); ++i) {
    const ErrorDef& e = truth_desc_.errors[i];
    const TruthError& t = errors_[i];
    double scale = 1;
    for (const Effect& f : effects_) {
      if (f.name == "higher_order") scale = f.amplitude;
      if (f.name == "missing_error" && static_cast<int>(i) == f.error) scale = f.amplitude;
    }
    json c = json::array();
    for (double v : t.coeff) c.push_back(v * scale);
    json je = {{"name", e.name}, {"unit", e.unit}, {"to_base", e.to_base}};
    if (t.axis >= 0) {
      const AxisInfo& a = axes_[static_cast<std::size_t>(t.axis)];
      je["dependence"] = "PDGE";
      je["axis"] = a.name;
      je["travel"] = {a.min, a.max};
      if (t.harmonics > 0)
        je["fourier"] = c;  // 1, cos θ, sin θ, cos 2θ … with θ = 2π q / 360 (q in deg)
      else
        je["legendre"] = c;
    } else {
      je["dependence"] = "PIGE";
      je["value"] = c[0];
    }
    errs.push_back(je);
  }
  j["truth_errors"] = errs;
  json tp = json::object();
  for (std::size_t i = 0; i < truth_desc_.parameters.size(); ++i) {
    double v = truth_params_[i];
    for (const Effect& f : effects_)
      if (f.name == "tool_offset" && truth_desc_.parameters[i].name == "tool_length")
        v += f.amplitude;
    tp[truth_desc_.parameters[i].name] = v;
  }
  j["truth_parameters"] = tp;
  return j;
}

}  // namespace weilgen::gapbench
