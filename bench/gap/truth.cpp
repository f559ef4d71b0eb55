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

const std::map<std::string, std::string>& default_missing_error() {
  // Chosen by `weilgen_gap_synth --probe-missing`: errors whose signal the remaining errors'
  // polynomials cannot absorb in the grid layout (README.md, "missing_error").
  static const std::map<std::string, std::string> m = {{"vmc_3axis", "E_AX"},
                                                       {"gantry_grinder", "E_AX"},
                                                       {"five_axis_ac", "E_CY"},
                                                       {"head_head_bc", "E_ZC"}};
  return m;
}

}  // namespace

double max_of(const std::vector<double>& v) {
  return v.empty() ? 0 : *std::max_element(v.begin(), v.end());
}

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
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
  layout_ = Layout::parse(spec_.layout);
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
  for (const std::string& n : names)
    if (n != "none" && !find_effect(n)) throw fail("unknown effect '" + n + "'");
  if (names.size() > 2) throw fail("at most two effects at once");
  if (names.size() == 2) {
    auto additive = [](const std::string& n) {
      const EffectDef* d = find_effect(n);
      return d && d->additive;
    };
    if (!additive(names[0]) || !additive(names[1]) || names[0] == names[1])
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
    e.kind = find_effect(n)->kind;
    e.name = n;
    effects_.push_back(e);
    tool_offset_ = tool_offset_ || e.kind == EffectKind::ToolOffset;
    higher_order_ = higher_order_ || e.kind == EffectKind::HigherOrder;
    missing_ = missing_ || e.kind == EffectKind::MissingError;
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
    if (f.kind == EffectKind::HigherOrder) {
      for (double& v : e) v *= amps[k];  // both states: the exact chain against its linear part
      continue;
    }
    if (f.kind == EffectKind::MissingError) {
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
    if (f.kind == EffectKind::Reversal) {
      // Backlash: the axis stops short by half the lost motion in its direction of approach.
      add = -amp / 2 * row.dir[static_cast<std::size_t>(f.axis)];
    } else if (f.kind == EffectKind::Periodic) {
      add = amp * std::sin(2 * kPi * q / f.period + f.phase);
    } else if (f.kind == EffectKind::PdgeShape) {
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
    if (on[k] && effects_[k].kind == EffectKind::ToolOffset) {
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
    higher_on = higher_on || (on[k] && effects_[k].kind == EffectKind::HigherOrder);
  const Eigen::Vector3d first = tool_point(*truth_chain_, rows_[0].axes, zero);
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const Row& row = rows_[r];
    const std::vector<double> e = errors_at(row, amps, on);
    std::vector<double> q = row.axes;
    Eigen::Vector3d grow = Eigen::Vector3d::Zero();  // thermal growth of the tool point, mm
    for (std::size_t k = 0; k < effects_.size(); ++k) {
      const Effect& f = effects_[k];
      if (!on[k] || f.kind != EffectKind::ThermalDrift) continue;
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
      if (!on[k] || f.kind != EffectKind::Step) continue;
      const double x = f.step_in_time ? row.t_s : row.axes[static_cast<std::size_t>(f.axis)];
      if (x >= f.step_at) d[f.dim] += amps[k] / 1000;
    }
    double* o = &out[r * nc];
    measure_row(r, d, o);
    for (std::size_t k = 0; k < effects_.size(); ++k) {
      if (!on[k] || effects_[k].kind != EffectKind::Setup) continue;
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
    // µm or µrad (backlash, amplitudes, step), ppm (setup), mm (tool), x (scales).
    const double amp = effect_def(f.kind).nominal_amplitude;
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
      double slope = f.kind == EffectKind::HigherOrder ? 2 : 1;
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

}  // namespace weilgen::gapbench
