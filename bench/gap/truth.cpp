#include "truth.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <stdexcept>

#include "weilgen/machine/yaml_loader.hpp"

namespace weilgen::gapbench {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTemp0C = 22.0;           // room temperature
constexpr double kWarmupK = 3.0;           // spindle warm-up rise
constexpr double kTempNoiseK = 0.01;       // sensor noise of T_spindle
constexpr double kVisibleFraction = 0.02;  // below: the model absorbs the effect
const char* const kDimNames[3] = {"dx", "dy", "dz"};

std::runtime_error fail(const std::string& what) { return std::runtime_error(what); }

// Element-wise copy: GCC 12 reports a false -Wnonnull in vector<double>::operator= here.
template <typename T>
void copy_to(std::vector<T>& dst, const std::vector<T>& src) {
  dst.resize(src.size());
  for (std::size_t i = 0; i < src.size(); ++i) dst[i] = src[i];
}

std::uint64_t splitmix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Independent streams of one scenario seed: the truth machine, the layout and the noise do not
// depend on the effect, so two scenarios with one seed differ only by their effect.
enum Stream : std::uint64_t { kTruthStream = 1, kLayoutStream, kEffectStream, kNoiseStream };
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
                                                       {"gantry_grinder", "E_AX"}};
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
    J.col(static_cast<Eigen::Index>(i)) = (plus - minus) / (2 * h);
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
  static const std::vector<std::string> v = {"grid", "line", "ballbar"};
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

Synthesiser::~Synthesiser() = default;

Synthesiser::Synthesiser(ScenarioSpec spec) : spec_(std::move(spec)) {
  const auto& effects = all_effects();
  if (std::find(effects.begin(), effects.end(), spec_.effect) == effects.end())
    throw fail("unknown effect '" + spec_.effect + "'");
  const auto& layouts = layout_names();
  if (std::find(layouts.begin(), layouts.end(), spec_.layout) == layouts.end())
    throw fail("unknown layout '" + spec_.layout + "' (grid, line or ballbar)");
  if (!(spec_.factor >= 0) || !(spec_.noise_um >= 0)) throw fail("factor and noise must be >= 0");
  if (spec_.truth_degree < 0 || spec_.truth_degree > 8 || spec_.fit_degree < 0 ||
      spec_.fit_degree > 8)
    throw fail("degrees must be within 0..8");
  effect_ = spec_.effect;
  if (effect_ == "none") spec_.factor = 0;

  truth_desc_ = load_machine_file(resolve_machine(spec_.machine));
  model_desc_ = truth_desc_;
  model_machine_ = spec_.machine;
  if (effect_ == "missing_error") {
    if (spec_.missing_error.empty()) {
      const auto it = default_missing_error().find(truth_desc_.name);
      if (it == default_missing_error().end())
        throw fail("no default missing error for machine '" + truth_desc_.name +
                   "': give --missing");
      spec_.missing_error = it->second;
    }
    effect_error_ = truth_desc_.error_index(spec_.missing_error);
    if (effect_error_ < 0) throw fail("no error '" + spec_.missing_error + "' in the machine");
    spec_.missing_error = truth_desc_.errors[static_cast<std::size_t>(effect_error_)].name;
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
    expect.erase(expect.begin() + effect_error_);
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
    if (t.axis < 0) {
      t.coeff = {draw(e.distribution, truth_rng)};
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
  Rng effect_rng = stream(spec_.seed, kEffectStream);
  build_effect(effect_rng);
  build_regressors();
  draw_noise();
  scale_effect();
}

// ---------------------------------------------------------------------------------------------
// Layouts

void Synthesiser::build_layout(Rng& rng) {
  std::vector<int> linear;
  for (std::size_t k = 0; k < axes_.size(); ++k)
    if (axes_[k].linear && axes_[k].max > axes_[k].min) linear.push_back(static_cast<int>(k));
  if (linear.empty()) throw fail("the machine has no linear axis with a travel");
  std::vector<double> home(axes_.size(), 0.0);
  for (std::size_t k = 0; k < axes_.size(); ++k)
    home[k] = std::clamp(0.0, axes_[k].min, axes_[k].max);
  auto travel = [&](int k) { return axes_[k].max - axes_[k].min; };
  // The layout's own number of cycles, or as many as --observations needs (one value a row at
  // least; the rows beyond it are cut below).
  auto cycles = [&](int own, std::size_t rows_per_cycle) {
    if (spec_.observations <= 0) return own;
    const auto n = static_cast<std::size_t>(spec_.observations);
    return static_cast<int>(std::max<std::size_t>(1, (n + rows_per_cycle - 1) / rows_per_cycle));
  };
  auto add_row = [&](Row r) {
    r.dir.resize(axes_.size(), 1);
    rows_.push_back(std::move(r));
  };

  if (spec_.layout == "grid") {
    // Volumetric grid (laser tracker), revisited in 3 cycles, boustrophedon at every level;
    // even cycles run the sequence backwards so every pose is approached from both sides.
    double longest = 0;
    for (int k : linear) longest = std::max(longest, travel(k));
    std::vector<int> n(axes_.size(), 1);
    grid_step_.assign(axes_.size(), 0.0);
    for (int k : linear) {
      n[k] = std::clamp(1 + static_cast<int>(std::lround(10 * travel(k) / longest)), 5, 11);
      grid_step_[k] = travel(k) / (n[k] - 1);
    }
    std::vector<int> order = linear;  // outermost first: fewest points
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return n[a] < n[b]; });
    std::vector<std::vector<int>> seq;
    std::vector<int> idx(axes_.size(), 0), starts(order.size(), 0);
    auto rec = [&](auto&& self, std::size_t level) -> void {
      const int k = order[level];
      const bool back = starts[level]++ % 2 == 1;
      for (int j = 0; j < n[k]; ++j) {
        idx[k] = back ? n[k] - 1 - j : j;
        if (level + 1 == order.size()) {
          seq.push_back(idx);
        } else {
          self(self, level + 1);
        }
      }
    };
    rec(rec, 0);
    std::map<std::vector<int>, int> pose_of;
    for (const auto& s : seq) {
      const int id = static_cast<int>(pose_of.size());
      pose_of.emplace(s, id);
      std::vector<double> p = home;
      for (int k : linear) p[k] = axes_[k].min + s[k] * grid_step_[k];
      poses_.push_back(p);
    }
    const int kCycles = cycles(3, seq.size());
    constexpr double kDwellS = 8;
    std::vector<int> dir(axes_.size(), 1);
    std::vector<double> prev = poses_[0];
    for (int c = 1; c <= kCycles; ++c) {
      for (std::size_t i = 0; i < seq.size(); ++i) {
        const auto& s = seq[c % 2 == 1 ? i : seq.size() - 1 - i];
        Row r;
        r.pose = pose_of.at(s);
        copy_to(r.axes, poses_[static_cast<std::size_t>(r.pose)]);
        for (std::size_t k = 0; k < axes_.size(); ++k)
          if (r.axes[k] != prev[k]) dir[k] = r.axes[k] > prev[k] ? 1 : -1;
        copy_to(prev, r.axes);
        copy_to(r.dir, dir);
        r.cycle = c;
        r.t_s = static_cast<double>(rows_.size()) * kDwellS;
        add_row(r);
      }
    }
    std::set<int> dims;
    for (int k : linear) dims.insert(axes_[k].dim);
    for (int d : dims) {
      columns_.push_back(std::string(kDimNames[d]) + "_um");
      column_dim_.push_back(d);
    }
  } else if (spec_.layout == "line") {
    // ISO 230-2 bidirectional runs of one axis: 101 targets, 5 cycles, up then down; the other
    // axes parked at random positions in the middle half of their travel.
    line_axis_ = linear[static_cast<std::size_t>(rng.index(static_cast<int>(linear.size())))];
    std::vector<double> park = home;
    for (int k : linear)
      park[k] =
          std::round(rng.uniform(axes_[k].min + 0.25 * travel(k), axes_[k].max - 0.25 * travel(k)));
    constexpr int kTargets = 101;
    const int kCycles = cycles(5, 2 * kTargets);
    constexpr double kDwellS = 15;
    for (int i = 0; i < kTargets; ++i) {
      std::vector<double> p = park;
      p[line_axis_] = axes_[line_axis_].min + travel(line_axis_) * i / (kTargets - 1);
      poses_.push_back(p);
    }
    for (int c = 1; c <= kCycles; ++c) {
      for (int pass = 0; pass < 2; ++pass) {
        for (int j = 0; j < kTargets; ++j) {
          Row r;
          r.pose = pass == 0 ? j : kTargets - 1 - j;
          copy_to(r.axes, poses_[static_cast<std::size_t>(r.pose)]);
          r.feed_dir = pass == 0 ? 1 : -1;
          r.dir.assign(axes_.size(), 1);
          r.dir[line_axis_] = r.feed_dir;
          r.cycle = c;
          r.t_s = static_cast<double>(rows_.size()) * kDwellS;
          add_row(r);
        }
      }
    }
    const int d = axes_[line_axis_].dim;
    columns_ = {std::string(kDimNames[d]) + "_um"};
    column_dim_ = {d};
  } else {
    // Ballbar (ISO 230-4) circles in the plane of the first two linear axes by direction
    // (XY for vmc_3axis): 2 deg steps, ccw then cw, 6 cycles 30 min apart (a warm-up series).
    std::vector<int> plane = linear;
    std::stable_sort(plane.begin(), plane.end(),
                     [&](int a, int b) { return axes_[a].dim < axes_[b].dim; });
    if (plane.size() < 2) throw fail("the ballbar layout needs two linear axes");
    plane_a_ = plane[0];
    plane_b_ = plane[1];
    copy_to(centre_, home);
    for (int k : linear) centre_[k] = std::round((axes_[k].min + axes_[k].max) / 2);
    radius_mm_ = 10 * std::floor(0.03 * std::min(travel(plane_a_), travel(plane_b_)));
    constexpr int kPoints = 180;
    const int kCycles = cycles(6, 2 * kPoints);
    constexpr double kPointS = 0.25, kCycleS = 1800;
    for (int i = 0; i < kPoints; ++i) {
      const double th = 2.0 * i * kPi / 180;
      std::vector<double> p = centre_;
      p[plane_a_] += radius_mm_ * std::cos(th);
      p[plane_b_] += radius_mm_ * std::sin(th);
      poses_.push_back(p);
    }
    for (int c = 1; c <= kCycles; ++c) {
      double t = (c - 1) * kCycleS;
      for (int pass = 0; pass < 2; ++pass) {
        for (int j = 0; j < kPoints; ++j) {
          Row r;
          r.pose = pass == 0 ? j : (kPoints - j) % kPoints;
          copy_to(r.axes, poses_[static_cast<std::size_t>(r.pose)]);
          r.feed_dir = pass == 0 ? 1 : -1;
          r.angle_deg = 2.0 * r.pose;
          // Each axis' direction of motion just before the point (1 deg back along the feed).
          const double th = (r.angle_deg - r.feed_dir * 1.0) * kPi / 180;
          r.dir.assign(axes_.size(), 1);
          r.dir[plane_a_] = -r.feed_dir * std::sin(th) > 0 ? 1 : -1;
          r.dir[plane_b_] = r.feed_dir * std::cos(th) > 0 ? 1 : -1;
          r.cycle = c;
          r.t_s = t;
          t += kPointS;
          add_row(r);
        }
        t += 5;  // reversal of the feed
      }
    }
    columns_ = {"dr_um"};
    column_dim_ = {-1};
  }
  if (spec_.observations > 0)
    rows_.resize(std::min(
        rows_.size(),
        (static_cast<std::size_t>(spec_.observations) + columns_.size() - 1) / columns_.size()));
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    for (std::size_t c = 0; c < columns_.size(); ++c) {
      obs_row_.push_back(static_cast<int>(r));
      obs_col_.push_back(static_cast<int>(c));
    }
  }
  t_total_s_ = rows_.back().t_s;

  // The lagged temperature rise on a fine grid (exact step response of the first-order lag for
  // an input held over each step).
  constexpr int kSteps = 20000;
  const double dt = t_total_s_ / kSteps, tau = t_total_s_ / 12;
  const double a = 1 - std::exp(-dt / tau);
  drift_table_.assign(kSteps + 1, 0.0);
  for (int i = 0; i < kSteps; ++i)
    drift_table_[i + 1] =
        drift_table_[i] + (temperature((i + 0.5) * dt) - kTemp0C - drift_table_[i]) * a;
  truth_jacobians_.resize(poses_.size());
}

// Spindle warm-up to kWarmupK with time constant T/4, spindle off at 0.6 T, cooling with T/5:
// a profile that rises and falls, so a drift is not a monotone function of time.
double Synthesiser::temperature(double t_s) const {
  const double T = t_total_s_, t_off = 0.6 * T;
  auto warm = [&](double t) { return kWarmupK * (1 - std::exp(-t / (T / 4))); };
  if (t_s <= t_off) return kTemp0C + warm(t_s);
  return kTemp0C + warm(t_off) * std::exp(-(t_s - t_off) / (T / 5));
}

double Synthesiser::drift(double t_s) const {
  const double x = std::clamp(t_s / t_total_s_, 0.0, 1.0) * (drift_table_.size() - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(x), drift_table_.size() - 2);
  const double f = x - static_cast<double>(i);
  return drift_table_[i] * (1 - f) + drift_table_[i + 1] * f;
}

double Synthesiser::axis_step(int axis) const {
  if (spec_.layout == "grid") return grid_step_[static_cast<std::size_t>(axis)];
  if (spec_.layout == "line") return (axes_[axis].max - axes_[axis].min) / 100;
  return radius_mm_ * 2 * kPi / 180;  // 2 deg of arc
}

std::pair<double, double> Synthesiser::data_range(int axis) const {
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& p : poses_) {
    lo = std::min(lo, p[static_cast<std::size_t>(axis)]);
    hi = std::max(hi, p[static_cast<std::size_t>(axis)]);
  }
  return {lo, hi};
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

int Synthesiser::positioning_error(int axis) const {
  const Vec3& ax = truth_desc_.bodies[static_cast<std::size_t>(axes_[axis].body)].joint.axis;
  for (int i : translation_errors(axis)) {
    const Vec3& d = truth_desc_.errors[static_cast<std::size_t>(i)].direction;
    if (std::abs(d[0] * ax[0] + d[1] * ax[1] + d[2] * ax[2]) > 0.999) return i;
  }
  throw fail("axis " + axes_[axis].name + " has no positioning error in the machine file");
}

// ---------------------------------------------------------------------------------------------
// Effects

void Synthesiser::build_effect(Rng& rng) {
  std::vector<int> linear;
  for (std::size_t k = 0; k < axes_.size(); ++k)
    if (axes_[k].linear && axes_[k].max > axes_[k].min) linear.push_back(static_cast<int>(k));
  auto pick = [&](const std::vector<int>& v) {
    return v[static_cast<std::size_t>(rng.index(static_cast<int>(v.size())))];
  };
  // The axes an axis-bound effect may sit on: those the layout moves.
  std::vector<int> moving = linear;
  if (spec_.layout == "line") moving = {line_axis_};
  if (spec_.layout == "ballbar") moving = {plane_a_, plane_b_};
  std::set<int> measured_dims;
  if (spec_.layout == "ballbar") {
    measured_dims = {axes_[plane_a_].dim, axes_[plane_b_].dim};
  } else {
    for (int d : column_dim_) measured_dims.insert(d);
  }
  // A translation error of `axis` along a measured direction (the line: the positioning error).
  auto pick_error = [&](int axis) {
    if (spec_.layout == "line") return positioning_error(axis);
    std::vector<int> cand;
    for (int i : translation_errors(axis)) {
      const Vec3& d = truth_desc_.errors[static_cast<std::size_t>(i)].direction;
      const int dim = static_cast<int>(
          std::max_element(d.begin(), d.end(),
                           [](double x, double y) { return std::abs(x) < std::abs(y); }) -
          d.begin());
      if (measured_dims.count(dim)) cand.push_back(i);
    }
    if (cand.empty()) throw fail("axis " + axes_[axis].name + " has no measured translation error");
    return pick(cand);
  };

  if (effect_ == "none") {
    expected_ = "none";
    return;
  }
  expected_ = effect_ == "step" ? "unexplained" : effect_;
  if (effect_ == "reversal") {
    effect_axis_ = pick(moving);
    effect_error_ = positioning_error(effect_axis_);
  } else if (effect_ == "periodic" || effect_ == "pdge_shape") {
    std::vector<int> cand = moving;
    if (spec_.layout == "grid") {
      // A local bump needs enough grid points along its axis to be local, and a period enough
      // to be told from other shapes: on 7 positions a cubic PDGE leaves 3 shape degrees of
      // freedom, which a period (amplitude, phase, period) or a bump (height, centre, width)
      // uses up, so no data could tell either from a step there (docs/gap.md, "Verdict").
      std::vector<int> fine;
      for (int k : moving)
        if ((axes_[k].max - axes_[k].min) / grid_step_[k] >= 8 - 1e-9) fine.push_back(k);
      if (!fine.empty()) cand = fine;
    }
    effect_axis_ = pick(cand);
    effect_error_ = pick_error(effect_axis_);
    const double step = axis_step(effect_axis_);
    const auto [lo, hi] = data_range(effect_axis_);
    if (effect_ == "periodic") {
      period_mm_ = 4 * step;  // 4 samples per period: resolved by every layout
      phase_rad_ = rng.uniform(0, 2 * kPi);
    } else {
      width_mm_ = std::max(step, (hi - lo) / 25);
      centre_mm_ = rng.uniform(lo + 0.3 * (hi - lo), hi - 0.3 * (hi - lo));
    }
  } else if (effect_ == "thermal_drift") {
    thermal_offset_.assign(3, 0.0);
    thermal_scale_.assign(3, 0.0);
    for (int d : measured_dims) {
      thermal_offset_[d] = rng.normal();
      thermal_scale_[d] = rng.normal();
    }
  } else if (effect_ == "step") {
    step_in_time_ = rng.uniform() < 0.5;
    effect_dim_ =
        *std::next(measured_dims.begin(), rng.index(static_cast<int>(measured_dims.size())));
    if (step_in_time_) {
      step_at_ = std::round(rng.uniform(0.35, 0.65) * t_total_s_);
    } else {
      effect_axis_ = pick(moving);
      const auto [lo, hi] = data_range(effect_axis_);
      step_at_ = std::round(rng.uniform(lo + 0.35 * (hi - lo), lo + 0.65 * (hi - lo)));
    }
  } else if (effect_ == "tool_offset") {
    bool found = false;
    for (const Parameter& p : truth_desc_.parameters) found = found || p.name == "tool_length";
    if (!found) throw fail("tool_offset needs a parameter 'tool_length' in the machine");
  }
  if (effect_error_ >= 0 && effect_ != "missing_error") {
    const Vec3& d = truth_desc_.errors[static_cast<std::size_t>(effect_error_)].direction;
    effect_dim_ = static_cast<int>(
        std::max_element(d.begin(), d.end(),
                         [](double x, double y) { return std::abs(x) < std::abs(y); }) -
        d.begin());
  }
}

std::vector<double> Synthesiser::errors_at(const Row& row, double amplitude,
                                           bool with_effect) const {
  const std::size_t n = truth_desc_.errors.size();
  std::vector<double> e(n, 0.0);
  double p[16];
  for (std::size_t i = 0; i < n; ++i) {
    const TruthError& t = errors_[i];
    double v = t.coeff[0];
    if (t.axis >= 0) {
      const AxisInfo& a = axes_[static_cast<std::size_t>(t.axis)];
      const double u =
          (2 * row.axes[static_cast<std::size_t>(t.axis)] - a.min - a.max) / (a.max - a.min);
      const int deg = static_cast<int>(t.coeff.size()) - 1;
      legendre(deg, u, p);
      v = 0;
      for (int k = 0; k <= deg; ++k) v += t.coeff[static_cast<std::size_t>(k)] * p[k];
    }
    e[i] = v * truth_desc_.errors[i].to_base;
  }
  if (effect_ == "higher_order") {
    for (double& v : e) v *= amplitude;  // both states: the exact chain against its linear part
    return e;
  }
  if (effect_ == "missing_error") {
    e[static_cast<std::size_t>(effect_error_)] *= with_effect ? amplitude : 0.0;
    return e;
  }
  if (!with_effect || effect_error_ < 0) return e;
  const double q = effect_axis_ >= 0 ? row.axes[static_cast<std::size_t>(effect_axis_)] : 0;
  const double amp_mm = amplitude / 1000;
  double add = 0;
  if (effect_ == "reversal") {
    // Backlash: the carriage stops short by half the lost motion in its direction of approach.
    add = -amp_mm / 2 * row.dir[static_cast<std::size_t>(effect_axis_)];
  } else if (effect_ == "periodic") {
    add = amp_mm * std::sin(2 * kPi * q / period_mm_ + phase_rad_);
  } else if (effect_ == "pdge_shape") {
    const double z = (q - centre_mm_) / width_mm_;
    add = amp_mm * std::exp(-0.5 * z * z);
  }
  e[static_cast<std::size_t>(effect_error_)] += add;  // error in base units (mm)
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
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    if (column_dim_[c] >= 0) {
      out_um[c] = 1000 * d_mm[column_dim_[c]];
      continue;
    }
    // Ballbar: the distance between the balls minus the nominal radius, exactly.
    const double th = row.angle_deg * kPi / 180;
    Eigen::Vector3d p = d_mm;
    p[axes_[plane_a_].dim] += radius_mm_ * std::cos(th);
    p[axes_[plane_b_].dim] += radius_mm_ * std::sin(th);
    out_um[c] = 1000 * (p.norm() - radius_mm_);
  }
}

std::vector<double> Synthesiser::evaluate(double amplitude, bool with_effect) const {
  const bool on = with_effect && effect_ != "none";
  std::unique_ptr<NumericChain> tool_chain;
  const NumericChain* chain = truth_chain_.get();
  if (on && effect_ == "tool_offset") {
    // The truth's tool is `amplitude` mm longer than the model's parameter says.
    tool_chain = std::make_unique<NumericChain>(truth_desc_);
    std::vector<double> p = truth_params_;
    for (std::size_t i = 0; i < p.size(); ++i)
      if (truth_desc_.parameters[i].name == "tool_length") p[i] += amplitude;
    tool_chain->set_parameters(p);
    chain = tool_chain.get();
  }
  std::vector<double> out(obs_row_.size());
  std::vector<double> mid(3, 0.0), half(3, 1.0);
  for (const AxisInfo& a : axes_) {
    if (!a.linear || a.max <= a.min) continue;
    mid[a.dim] = (a.min + a.max) / 2;
    half[a.dim] = (a.max - a.min) / 2;
  }
  const double dmax = *std::max_element(drift_table_.begin(), drift_table_.end());
  const std::size_t nc = columns_.size();
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const Row& row = rows_[r];
    const std::vector<double> e = errors_at(row, amplitude, on);
    Eigen::Vector3d d;
    if (effect_ == "higher_order" && !on) {
      d = linear_deviation(row, e);
    } else {
      const std::array<double, 6> dev = chain->deviation(row.axes, e);
      d = {dev[0], dev[1], dev[2]};
    }
    Eigen::Vector3d nominal = Eigen::Vector3d::Zero();  // nominal position per dimension, mm
    for (std::size_t k = 0; k < axes_.size(); ++k)
      if (axes_[k].linear) nominal[axes_[k].dim] = row.axes[k];
    if (on && effect_ == "thermal_drift") {
      // Drift of the tool relative to the workpiece: an offset and a scale (expansion) term per
      // direction, both following the lagged spindle temperature.
      const double w = drift(row.t_s) / dmax * amplitude / 1000;
      for (int k = 0; k < 3; ++k)
        d[k] += w * (thermal_offset_[k] + thermal_scale_[k] * (nominal[k] - mid[k]) / half[k]);
    }
    if (on && effect_ == "step") {
      const double x = step_in_time_ ? row.t_s : row.axes[static_cast<std::size_t>(effect_axis_)];
      if (x >= step_at_) d[effect_dim_] += amplitude / 1000;
    }
    double* o = &out[r * nc];
    measure_row(r, d, o);
    if (on && effect_ == "setup") {
      // Instrument cosine error: it reads (1 - k) of every displacement from its zero (the first
      // pose; the ballbar's calibrated length), k = amplitude in ppm.
      const double k = -amplitude * 1e-6;
      for (std::size_t c = 0; c < nc; ++c) {
        if (column_dim_[c] < 0) {
          o[c] += 1000 * k * radius_mm_;
        } else {
          Eigen::Vector3d first = Eigen::Vector3d::Zero();
          for (std::size_t kk = 0; kk < axes_.size(); ++kk)
            if (axes_[kk].linear) first[axes_[kk].dim] = rows_[0].axes[kk];
          o[c] += 1000 * k * (nominal[column_dim_[c]] - first[column_dim_[c]]);
        }
      }
    }
  }
  return out;
}

std::vector<double> Synthesiser::measured(bool with_effect) const {
  return evaluate(amplitude_, with_effect);
}

std::vector<double> Synthesiser::signal(double amplitude) const {
  std::vector<double> on = evaluate(amplitude, true), off = evaluate(amplitude, false);
  for (std::size_t i = 0; i < on.size(); ++i) on[i] -= off[i];
  return on;
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
    const int terms = axis_of[i] >= 0 ? spec_.fit_degree + 1 : 1;
    for (int k = 0; k < terms; ++k) {
      lay.error.push_back(static_cast<int>(i));
      lay.term.push_back(k);
    }
  }
  const Eigen::Index n = static_cast<Eigen::Index>(obs_row_.size());
  Eigen::MatrixXd A(n, static_cast<Eigen::Index>(lay.error.size()));
  double phi[16];
  for (Eigen::Index o = 0; o < n; ++o) {
    const Row& row = rows_[static_cast<std::size_t>(obs_row_[static_cast<std::size_t>(o)])];
    const int dim = column_dim_[static_cast<std::size_t>(obs_col_[static_cast<std::size_t>(o)])];
    const Eigen::MatrixXd& J = jac[static_cast<std::size_t>(row.pose)];
    Eigen::RowVectorXd g;
    if (dim >= 0) {
      g = J.row(dim);
    } else {
      const double th = row.angle_deg * kPi / 180;
      g = std::cos(th) * J.row(axes_[plane_a_].dim) + std::sin(th) * J.row(axes_[plane_b_].dim);
    }
    int last_error = -1;
    for (std::size_t c = 0; c < lay.error.size(); ++c) {
      const int i = lay.error[c];
      if (i != last_error && axis_of[static_cast<std::size_t>(i)] >= 0) {
        const AxisInfo& a = axes_[static_cast<std::size_t>(axis_of[static_cast<std::size_t>(i)])];
        const double u =
            (2 * row.axes[static_cast<std::size_t>(axis_of[static_cast<std::size_t>(i)])] - a.min -
             a.max) /
            (a.max - a.min);
        legendre(spec_.fit_degree, u, phi);
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
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU);
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

void Synthesiser::draw_noise() {
  Rng rng = stream(spec_.seed, kNoiseStream);
  noise_um_.resize(obs_row_.size());
  for (double& v : noise_um_) v = spec_.noise_um * rng.normal();
  temp_noise_.resize(rows_.size());
  for (double& v : temp_noise_) v = kTempNoiseK * rng.normal();
  noise_rms_um_ = rms(noise_um_);
}

// The amplitude whose held-out (unabsorbable) signal RMS, in the most affected measured column,
// is factor * noise. Effects the model absorbs entirely (visible fraction below 2 %) are scaled
// on their raw signal instead and expected to be diagnosed as `none`.
void Synthesiser::scale_effect() {
  if (effect_ == "none") return;
  double amp = 1;  // um (backlash, amplitudes, step), ppm (setup), mm (tool), x (scales)
  if (effect_ == "setup") amp = 10;
  if (effect_ == "tool_offset") amp = 100;
  if (effect_ == "higher_order") amp = 100;  // second-order terms of about a micrometre
  std::vector<double> s = signal(amp);
  const double v0 = max_of(unabsorbed_rms(s)), r0 = max_of(raw_rms(s));
  // An effect that does not reach the measured values (E_AX in a line run of X measures nothing
  // of it) keeps its nominal amplitude: the data are effect-free in all but name.
  observable_ = r0 > 1e-3;
  identifiable_ = observable_ && v0 >= kVisibleFraction * r0;
  const double target = observable_ ? spec_.factor * spec_.noise_um : 0.0;
  amplitude_ = amp;
  auto metric = [&](const std::vector<double>& sig) {
    return identifiable_ ? max_of(unabsorbed_rms(sig)) : max_of(raw_rms(sig));
  };
  if (target > 0) {
    // Secant iteration on log(metric) against log(amplitude); slope 1 for effects linear in
    // their amplitude, about 2 for higher_order (second-order terms of scaled errors).
    double la = std::log(amp), lm = std::log(metric(s));
    double slope = effect_ == "higher_order" ? 2 : 1;
    for (int it = 0; it < 60 && std::abs(lm - std::log(target)) > 1e-7; ++it) {
      const double la_new = la + (std::log(target) - lm) / slope;
      const double lm_new = std::log(metric(signal(std::exp(la_new))));
      if (std::abs(la_new - la) > 1e-12) {
        const double sl = (lm_new - lm) / (la_new - la);
        if (sl > 0.5 && sl < 4) slope = sl;
      }
      la = la_new;
      lm = lm_new;
    }
    amplitude_ = std::exp(la);
    if (std::abs(lm - std::log(target)) > 1e-4)
      throw fail("could not scale effect '" + effect_ + "' to its target signal");
  }
  s = signal(amplitude_);
  residual_ = span_.residual(
      Eigen::Map<const Eigen::VectorXd>(s.data(), static_cast<Eigen::Index>(s.size())));
  unabsorbed_by_column_ = unabsorbed_rms(s);
  raw_by_column_ = raw_rms(s);
  unabsorbed_rms_um_ = max_of(unabsorbed_by_column_);
  raw_rms_um_ = max_of(raw_by_column_);
  if (!identifiable_) expected_ = effect_ == "step" ? "unexplained" : "none";
}

std::vector<std::pair<std::string, double>> Synthesiser::missing_error_visibility() const {
  // First-order signal of each error alone (its drawn shape), projected on the regressors of
  // every other error: what a model without that error could not absorb.
  std::vector<std::pair<std::string, double>> out;
  const std::size_t n = truth_desc_.errors.size();
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<double> sig(obs_row_.size());
    for (std::size_t o = 0; o < sig.size(); ++o) {
      const Row& row = rows_[static_cast<std::size_t>(obs_row_[o])];
      std::vector<double> e = errors_at(row, 1.0, false);
      for (std::size_t k = 0; k < n; ++k)
        if (k != i) e[k] = 0;
      const Eigen::Vector3d d = linear_deviation(row, e);
      const int dim = column_dim_[static_cast<std::size_t>(obs_col_[o])];
      if (dim >= 0) {
        sig[o] = 1000 * d[dim];
      } else {
        const double th = row.angle_deg * kPi / 180;
        sig[o] =
            1000 * (std::cos(th) * d[axes_[plane_a_].dim] + std::sin(th) * d[axes_[plane_b_].dim]);
      }
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

// The held-out signal of one measured column binned along a coordinate (an axis, or time when
// axis < 0): one bin per distinct position when there are at most 25, else 20 equal bins. Each
// bin gives its data range, size and RMS; bins with at least half the largest RMS are "hot".
nlohmann::json Synthesiser::signal_bins(int axis, std::size_t column) const {
  std::vector<std::pair<double, double>> v;  // coordinate, residual
  for (std::size_t o = 0; o < obs_row_.size(); ++o) {
    if (static_cast<std::size_t>(obs_col_[o]) != column) continue;
    const Row& row = rows_[static_cast<std::size_t>(obs_row_[o])];
    v.emplace_back(axis < 0 ? row.t_s : row.axes[static_cast<std::size_t>(axis)],
                   residual_[static_cast<Eigen::Index>(o)]);
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

// ---------------------------------------------------------------------------------------------
// Output

std::string Synthesiser::csv(bool with_effect, bool with_noise) const {
  std::vector<double> v = evaluate(amplitude_, with_effect);
  if (with_noise)
    for (std::size_t i = 0; i < v.size(); ++i) v[i] += noise_um_[i];
  std::string s;
  s += "# Synthetic measurement written by weilgen_gap_synth (bench/gap/README.md)\n";
  s += "# machine: " + model_desc_.name + "\n";
  s += "# layout: " + spec_.layout + "\n";
  if (spec_.layout == "grid") {
    s += "# instrument: synthetic laser tracker\n";
  } else if (spec_.layout == "line") {
    s += "# instrument: synthetic laser interferometer\n";
    s += "# axis: " + axes_[static_cast<std::size_t>(line_axis_)].name + "\n";
  } else {
    s += "# instrument: synthetic ballbar\n";
    s += "# plane: " + axes_[static_cast<std::size_t>(plane_a_)].name +
         axes_[static_cast<std::size_t>(plane_b_)].name + "\n";
    std::string centre;
    for (std::size_t k = 0; k < axes_.size(); ++k)
      centre += (k ? ", " : "") + axes_[k].name + "=" + fmt("%.10g", centre_[k]);
    s += "# centre: " + centre + "\n";
    s += "# radius: " + fmt("%.10g", radius_mm_) + " mm\n";
    s += "# feed: ccw\n";
  }
  std::vector<std::string> head;
  for (const AxisInfo& a : axes_) head.push_back(a.name);
  head.push_back("t_s");
  if (spec_.layout == "grid") {
    for (const AxisInfo& a : axes_) head.push_back("dir_" + a.name);
  } else if (spec_.layout == "line") {
    head.push_back("dir");
  } else {
    head.push_back("dir");
    head.push_back("dir_" + axes_[static_cast<std::size_t>(plane_a_)].name);
    head.push_back("dir_" + axes_[static_cast<std::size_t>(plane_b_)].name);
  }
  head.push_back("cycle");
  head.push_back("T_spindle");
  if (spec_.layout == "ballbar") head.push_back("angle_deg");
  for (const std::string& c : columns_) head.push_back(c);
  for (std::size_t i = 0; i < head.size(); ++i) s += (i ? "," : "") + head[i];
  s += "\n";
  const std::size_t nc = columns_.size();
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const Row& row = rows_[r];
    std::string line;
    for (double a : row.axes) line += fmt("%.10g", a) + ",";
    line += fmt("%.2f", row.t_s) + ",";
    if (spec_.layout == "grid") {
      for (int d : row.dir) line += std::to_string(d) + ",";
    } else if (spec_.layout == "line") {
      line += std::to_string(row.feed_dir) + ",";
    } else {
      line += std::to_string(row.feed_dir) + "," +
              std::to_string(row.dir[static_cast<std::size_t>(plane_a_)]) + "," +
              std::to_string(row.dir[static_cast<std::size_t>(plane_b_)]) + ",";
    }
    line += std::to_string(row.cycle) + ",";
    line += fmt("%.4f", temperature(row.t_s) + temp_noise_[r]);
    if (spec_.layout == "ballbar") line += "," + fmt("%.10g", row.angle_deg);
    for (std::size_t c = 0; c < nc; ++c) line += "," + fmt("%.6f", v[r * nc + c]);
    s += line + "\n";
  }
  return s;
}

nlohmann::json Synthesiser::truth() const {
  using nlohmann::json;
  auto output_name = [&](std::size_t c) {
    return column_dim_[c] >= 0 ? std::string(kDimNames[column_dim_[c]]) : std::string("dr");
  };
  json j;
  j["generator"] = "weilgen_gap_synth";
  j["format"] = 1;
  j["scenario"] = {{"machine", truth_desc_.name},
                   {"model_machine", model_machine_},
                   {"effect", effect_},
                   {"factor", spec_.factor},
                   {"noise_sigma_um", spec_.noise_um},
                   {"layout", spec_.layout},
                   {"seed", spec_.seed},
                   {"truth_degree", spec_.truth_degree},
                   {"fit_degree", spec_.fit_degree}};
  j["expected_verdict"] = expected_;
  j["noise_sigma_um"] = spec_.noise_um;
  j["noise_rms_um"] = noise_rms_um_;
  j["rows"] = rows_.size();
  j["observations"] = obs_row_.size();
  j["duration_s"] = t_total_s_;
  json cols = json::array();
  for (std::size_t c = 0; c < columns_.size(); ++c) cols.push_back(columns_[c]);
  j["measured_columns"] = cols;
  j["model_regressors"] = {{"columns", regressors_.cols()},
                           {"rank", span_.basis.cols()},
                           {"smallest_kept_singular_value", span_.smallest_kept},
                           {"largest_dropped_singular_value", span_.largest_dropped}};

  json eff;
  eff["name"] = effect_;
  eff["observable"] = observable_;
  eff["identifiable"] = identifiable_;
  eff["heldout_signal_rms_um"] = unabsorbed_rms_um_;
  eff["raw_signal_rms_um"] = raw_rms_um_;
  eff["visible_fraction"] = raw_rms_um_ > 0 ? unabsorbed_rms_um_ / raw_rms_um_ : 0.0;
  eff["snr"] = spec_.noise_um > 0 ? unabsorbed_rms_um_ / spec_.noise_um : 0.0;
  json by_out = json::object(), raw_out = json::object();
  std::size_t dominant = 0;
  for (std::size_t c = 0; c < unabsorbed_by_column_.size(); ++c) {
    by_out[output_name(c)] = unabsorbed_by_column_[c];
    raw_out[output_name(c)] = raw_by_column_[c];
    const auto& v = identifiable_ ? unabsorbed_by_column_ : raw_by_column_;
    if (v[c] > v[dominant]) dominant = c;
  }
  eff["heldout_signal_rms_by_output_um"] = by_out;
  eff["raw_signal_rms_by_output_um"] = raw_out;

  json params = json::object();
  json loc = {{"kind", "none"}, {"by", json::array()}};
  const std::string out_name = effect_ == "none" ? std::string() : output_name(dominant);
  if (effect_ != "none") loc = {{"kind", "output"}, {"by", json::array()}, {"output", out_name}};
  const std::string axis_name =
      effect_axis_ >= 0 ? axes_[static_cast<std::size_t>(effect_axis_)].name : std::string();
  const std::string error_name =
      effect_error_ >= 0 ? truth_desc_.errors[static_cast<std::size_t>(effect_error_)].name
                         : std::string();
  if (effect_ == "reversal") {
    params = {{"axis", axis_name},
              {"error", error_name},
              {"backlash_um", amplitude_},
              {"model", "error += -backlash/2 * dir (approach direction of the axis)"}};
    loc = {{"kind", "direction"}, {"by", {"dir_" + axis_name, "dir"}}, {"output", out_name}};
  } else if (effect_ == "periodic") {
    params = {{"axis", axis_name},
              {"error", error_name},
              {"period_mm", period_mm_},
              {"amplitude_um", amplitude_},
              {"phase_rad", phase_rad_}};
    const auto [lo, hi] = data_range(effect_axis_);
    loc = {{"kind", "whole"}, {"by", {axis_name}}, {"output", out_name}, {"from", lo}, {"to", hi}};
  } else if (effect_ == "pdge_shape") {
    params = {{"axis", axis_name},          {"error", error_name},
              {"centre_mm", centre_mm_},    {"width_mm", width_mm_},
              {"amplitude_um", amplitude_}, {"shape", "a exp(-(q-c)^2/(2 w^2))"}};
    const auto [lo, hi] = data_range(effect_axis_);
    loc = {{"kind", "interval"},
           {"by", {axis_name}},
           {"output", out_name},
           {"from", std::max(lo, centre_mm_ - 2 * width_mm_)},
           {"to", std::min(hi, centre_mm_ + 2 * width_mm_)},
           {"at", centre_mm_}};
  } else if (effect_ == "thermal_drift") {
    const double dmax = *std::max_element(drift_table_.begin(), drift_table_.end());
    std::vector<double> mid(3, 0.0), half(3, 1.0);
    for (const AxisInfo& a : axes_) {
      if (!a.linear || a.max <= a.min) continue;
      mid[a.dim] = (a.min + a.max) / 2;
      half[a.dim] = (a.max - a.min) / 2;
    }
    json per = json::object();
    for (int d = 0; d < 3; ++d) {
      if (thermal_offset_[d] == 0 && thermal_scale_[d] == 0) continue;
      per[kDimNames[d]] = {
          {"offset_um_per_K", amplitude_ * thermal_offset_[d] / dmax},
          {"scale_um_per_K_per_m", 1000 * amplitude_ * thermal_scale_[d] / (dmax * half[d])},
          {"scale_reference_mm", mid[d]}};
    }
    params = {{"temperature", "T_spindle"},
              {"model",
               "d = D(t) (offset + scale (P - reference)); D: first-order lag of "
               "T_spindle - 22 degC"},
              {"tau_lag_s", t_total_s_ / 12},
              {"drift_max_K", dmax},
              {"per_output", per}};
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
  } else if (effect_ == "step") {
    const std::string coord = step_in_time_ ? "t_s" : axis_name;
    double hi = t_total_s_;
    if (!step_in_time_) hi = data_range(effect_axis_).second;
    params = {{"kind", step_in_time_ ? "time" : "position"},
              {"coordinate", coord},
              {"at", step_at_},
              {"output", kDimNames[effect_dim_]},
              {"step_um", amplitude_}};
    json by = json::array({coord});
    if (step_in_time_) by.push_back("cycle");
    loc = {{"kind", "interval"}, {"by", by}, {"output", out_name},
           {"from", step_at_},   {"to", hi}, {"at", step_at_}};
  } else if (effect_ == "higher_order") {
    double max_t = 0, max_r = 0;
    for (const Row& row : rows_) {
      const std::vector<double> e = errors_at(row, amplitude_, true);
      for (std::size_t i = 0; i < e.size(); ++i) {
        const bool rot = truth_desc_.errors[i].effect == ErrorEffect::Rotation;
        (rot ? max_r : max_t) = std::max(rot ? max_r : max_t, std::abs(e[i]));
      }
    }
    params = {{"error_scale", amplitude_},
              {"largest_translation_error_um", 1000 * max_t},
              {"largest_rotation_error_urad", 1e6 * max_r},
              {"model_order", model_desc_.algebra.order},
              {"how",
               "every truth error multiplied by error_scale; the exact chain minus its "
               "first-order part is the effect"}};
  } else if (effect_ == "missing_error") {
    double ss = 0;
    for (const Row& row : rows_) {
      const double v = errors_at(row, amplitude_, true)[static_cast<std::size_t>(effect_error_)] /
                       truth_desc_.errors[static_cast<std::size_t>(effect_error_)].to_base;
      ss += v * v;
    }
    params = {{"error", spec_.missing_error},
              {"unit", truth_desc_.errors[static_cast<std::size_t>(effect_error_)].unit},
              {"rms_over_rows", std::sqrt(ss / rows_.size())},
              {"scale_of_drawn", amplitude_},
              {"model_machine", model_machine_}};
  } else if (effect_ == "tool_offset") {
    double model_len = 0;
    for (std::size_t i = 0; i < model_desc_.parameters.size(); ++i)
      if (model_desc_.parameters[i].name == "tool_length") model_len = model_params_[i];
    params = {{"tool_length_model_mm", model_len},
              {"tool_length_truth_mm", model_len + amplitude_},
              {"offset_mm", amplitude_}};
  } else if (effect_ == "setup") {
    params = {{"scale_ppm", -amplitude_},
              {"cosine_angle_mrad", 1e3 * std::acos(1 - amplitude_ * 1e-6)},
              {"model", "reading = (1 - k) x displacement from the instrument zero (first pose)"}};
  }
  eff["params"] = params;
  j["effect"] = eff;
  // Where the held-out signal is, along the primary coordinate: what a localisation is judged by.
  if (loc["kind"] == "interval" || loc["kind"] == "whole") {
    const std::string by = loc["by"][0].get<std::string>();
    int axis = -1;
    for (std::size_t k = 0; k < axes_.size(); ++k)
      if (axes_[k].name == by) axis = static_cast<int>(k);
    loc["bins"] = signal_bins(axis, dominant);
  }
  j["localise"] = loc;

  json errs = json::array();
  for (std::size_t i = 0; i < truth_desc_.errors.size(); ++i) {
    const ErrorDef& e = truth_desc_.errors[i];
    const TruthError& t = errors_[i];
    double scale = 1;
    if (effect_ == "higher_order") scale = amplitude_;
    if (effect_ == "missing_error" && static_cast<int>(i) == effect_error_) scale = amplitude_;
    json c = json::array();
    for (double v : t.coeff) c.push_back(v * scale);
    json je = {{"name", e.name}, {"unit", e.unit}, {"to_base", e.to_base}};
    if (t.axis >= 0) {
      const AxisInfo& a = axes_[static_cast<std::size_t>(t.axis)];
      je["dependence"] = "PDGE";
      je["axis"] = a.name;
      je["travel"] = {a.min, a.max};
      je["legendre"] = c;
    } else {
      je["dependence"] = "PIGE";
      je["value"] = c[0];
    }
    errs.push_back(je);
  }
  j["truth_errors"] = errs;
  json tp = json::object();
  for (std::size_t i = 0; i < truth_desc_.parameters.size(); ++i)
    tp[truth_desc_.parameters[i].name] =
        truth_params_[i] +
        (effect_ == "tool_offset" && truth_desc_.parameters[i].name == "tool_length" ? amplitude_
                                                                                     : 0.0);
  j["truth_parameters"] = tp;
  return j;
}

}  // namespace weilgen::gapbench
