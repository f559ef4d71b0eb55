// The ISO 230-9 / GUM budget of the ISO 230-2 figures and its Monte Carlo propagation
// (GUM Supplement 1). The model, the classes' defaults and the hand-worked example:
// docs/iso230-2.md, "Measurement uncertainty".
#include "weilgen/measure/iso230_2_uncertainty.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <stdexcept>

#include "weilgen/base/constants.hpp"
#include "weilgen/base/error.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/measure/air_refraction.hpp"
#include "weilgen/measure/measurement_csv.hpp"

namespace weilgen {

namespace {

struct Key {
  const char* name;
  // Defaults of laser-compensated, laser-edlen, laser-manual, scale.
  double defaults[4];
};

// The budget's keys. The instrument's figures are expanded (k = 2) values from its certificate;
// sensors' and set-up figures are limits of error (rectangular half-widths) unless said.
const std::vector<Key>& keys() {
  static const std::vector<Key> k = {
      {"coverage_factor", {2, 2, 2, 2}},
      {"instrument_ppm", {0.5, 0.05, 0.05, 1.0}},       // k = 2; a compensated laser's includes its
                                                        // weather station
      {"instrument_um", {0, 0, 0, 0.5}},                // k = 2, the constant part
      {"resolution_um", {0.001, 0.001, 0.001, 0.005}},  // full width of one count
      {"air_temperature_C", {0, 0.2, 1.0, 0}},
      {"air_pressure_Pa", {0, 100, 300, 0}},
      {"air_humidity_pct", {0, 6, 20, 0}},
      {"edlen_ppm", {0, 0.03, 0.03, 0}},  // the equation's 3-sigma uncertainty (Birch & Downs)
      {"material_temperature_C", {0.1, 0.1, 0.1, 0.1}},
      {"expansion_relative", {0.1, 0.1, 0.1, 0.1}},  // alpha's relative half-width
      {"nominal_expansion_ppm_per_K", {11.7, 11.7, 11.7, 11.7}},
      {"misalignment_mm", {0.1, 0.1, 0.1, 0}},  // the beam's lateral walk-off over the travel
      {"dead_path_mm", {0, 0, 0, 0}},
      {"dead_path_air_change_C", {1, 1, 1, 1}},
      {"abbe_offset_mm", {0, 0, 0, 0}},
      {"abbe_angle_urad", {0, 0, 0, 0}},  // range of the pitch or yaw along the travel
      {"eve_um", {0, 0, 0, 0}},           // range of an environmental variation test
      {"monte_carlo_trials", {200000, 200000, 200000, 200000}},
      {"seed", {1, 1, 1, 1}}};
  return k;
}

std::size_t class_index(const std::string& c) {
  const auto& names = uncertainty_classes();
  const auto it = std::find(names.begin(), names.end(), c);
  if (it == names.end())
    throw std::invalid_argument("uncertainty class '" + c + "' (classes: auto, " + join(names) +
                                ")");
  return static_cast<std::size_t>(it - names.begin());
}

std::string key_list() {
  std::vector<std::string> names = {"class"};
  for (const Key& k : keys()) names.push_back(k.name);
  return join(names);
}

// c4(n): E[s] = c4 σ for a normal sample of n; the standard deviation of s is σ √(1 − c4²).
double c4(std::size_t n) {
  if (n < 2) return kNaN;
  const double v = static_cast<double>(n);
  return std::sqrt(2 / (v - 1)) * std::exp(std::lgamma(v / 2) - std::lgamma((v - 1) / 2));
}

// Everything the sensitivities and the Monte Carlo perturb: per direction and target.
struct Point {
  std::array<std::vector<double>, 2> mean, s;
};

IsoFigures figures_at(const Point& p, double k_up, double k_down) {
  return iso_figures(p.mean[kUp], p.mean[kDown], p.s[kUp], p.s[kDown], k_up, k_down);
}

// A deterministic normal deviate: Box-Muller on the 53-bit uniform of a mt19937_64, the same on
// every standard library.
class Normal {
 public:
  explicit Normal(std::uint64_t seed) : rng_(seed) {}
  double uniform() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }
  double operator()() {
    if (has_) {
      has_ = false;
      return next_;
    }
    double u1 = uniform();
    while (u1 <= 0) u1 = uniform();
    const double u2 = uniform(), r = std::sqrt(-2 * std::log(u1)), t = 6.283185307179586 * u2;
    next_ = r * std::sin(t);
    has_ = true;
    return r * std::cos(t);
  }

 private:
  std::mt19937_64 rng_;
  double next_ = 0;
  bool has_ = false;
};

double draw(Normal& g, BudgetDistribution d, double u) {
  switch (d) {
    case BudgetDistribution::Rectangular:
      return (2 * g.uniform() - 1) * u * std::sqrt(3.0);
    case BudgetDistribution::OneSided:
      return g.uniform() * u * std::sqrt(12.0);
    case BudgetDistribution::Normal:
      break;
  }
  return g() * u;
}

// The budget's contributions from its inputs, one method per source (ISO 230-9 annex C): the
// instrument, the air, the material, the set-up, the environment and the run itself. A
// contribution of zero standard uncertainty is left out.
class BudgetContributions {
 public:
  BudgetContributions(const std::map<std::string, double>& in, const NormalisationResult& n,
                      const std::string& unit, double travel, std::vector<std::string>& notes)
      : in_(in), n_(n), unit_(unit), travel_(travel), notes_(notes) {}

  std::vector<UncertaintyContribution> build(bool linear, bool laser) {
    instrument();
    if (linear && laser) {
      const double dT = air();
      material();
      setup(dT);
    } else if (!linear) {
      notes_.push_back(
          "A rotary axis: the budget holds the instrument, the resolution, the environmental "
          "variation and the run's repeatability.");
    }
    environment_and_run();
    return std::move(C_);
  }

 private:
  void add(const std::string& name, const std::string& input, BudgetDistribution d,
           ContributionKind kind, double u, const std::string& u_unit) {
    if (!(u > 0)) return;
    UncertaintyContribution c;
    c.name = name;
    c.input = input;
    c.distribution = d;
    c.kind = kind;
    c.u = u;
    c.unit = u_unit;
    C_.push_back(c);
  }
  // A key the class' defaults do not name counts as 0.
  double in(const std::string& key) const {
    const auto it = in_.find(key);
    return it == in_.end() ? 0.0 : it->second;
  }
  std::string scale_unit() const { return unit_ == "um" ? "um/m" : "urad/rad"; }

  void instrument() {
    add("instrument calibration",
        format_significant(in("instrument_ppm"), 3) + " " + scale_unit() + " (k = 2)",
        BudgetDistribution::Normal, ContributionKind::Scale, in("instrument_ppm") / 2,
        scale_unit());
    add("instrument, constant part",
        format_significant(in("instrument_um"), 3) + " " + unit_ + " (k = 2)",
        BudgetDistribution::Normal, ContributionKind::PerMean, in("instrument_um") / 2, unit_);
    add("resolution", format_significant(in("resolution_um"), 3) + " " + unit_ + " (full width)",
        BudgetDistribution::Rectangular, ContributionKind::PerMean, in("resolution_um") / kSqrt12,
        unit_);
  }

  // The air: its index's sensitivities at the recorded mean air (20 degC, 101325 Pa, 50 %RH when
  // none is recorded), ppm per degC, Pa, %. Returns the sensitivity to temperature (ppm/K),
  // which the dead path uses.
  double air() {
    const NormalisationResult& n = n_;
    const AirConditions air{n.air_temperature_C.empty() ? 20.0 : n.air_temperature_C.mean,
                            n.air_pressure_Pa.empty() ? 101325.0 : n.air_pressure_Pa.mean,
                            n.air_humidity_pct.empty() ? 50.0 : n.air_humidity_pct.mean};
    auto slope = [&](int which, double step) {
      AirConditions lo = air, hi = air;
      double* a = which == 0 ? &lo.temperature_C : which == 1 ? &lo.pressure_Pa : &lo.humidity_pct;
      double* b = which == 0 ? &hi.temperature_C : which == 1 ? &hi.pressure_Pa : &hi.humidity_pct;
      *a -= step, *b += step;
      return std::abs(air_refractivity(hi, n.wavelength_nm) -
                      air_refractivity(lo, n.wavelength_nm)) /
             (2 * step) * 1e6;
    };
    const double dT = slope(0, 0.01), dp = slope(1, 1), dh = slope(2, 0.1);
    const bool compensated = n.air_applied || n.air == AirCompensation::Instrument;
    if (compensated) {
      add("air temperature sensor",
          format_significant(in("air_temperature_C"), 3) + " degC x " + format_significant(dT, 3) +
              " um/(m K)",
          BudgetDistribution::Rectangular, ContributionKind::Scale,
          in("air_temperature_C") * dT / kSqrt3, scale_unit());
      add("air pressure sensor",
          format_significant(in("air_pressure_Pa"), 3) + " Pa x " +
              format_significant(dp * 1e3, 3) + " um/(m kPa)",
          BudgetDistribution::Rectangular, ContributionKind::Scale,
          in("air_pressure_Pa") * dp / kSqrt3, scale_unit());
      add("air humidity sensor",
          format_significant(in("air_humidity_pct"), 3) + " %RH x " + format_significant(dh, 3) +
              " um/(m %RH)",
          BudgetDistribution::Rectangular, ContributionKind::Scale,
          in("air_humidity_pct") * dh / kSqrt3, scale_unit());
      add("Edlen equation", format_significant(in("edlen_ppm"), 3) + " um/m (k = 3)",
          BudgetDistribution::Normal, ContributionKind::Scale, in("edlen_ppm") / 3, scale_unit());
    } else {
      const double index = air_refractivity(air, n.wavelength_nm) * 1e6;
      add("air refraction not compensated",
          format_significant(index, 3) + " um/m (the index of the air)",
          BudgetDistribution::Rectangular, ContributionKind::Scale, index / kSqrt3, scale_unit());
      notes_.push_back(
          "The air's refractive index is not compensated: the budget counts the whole index as "
          "a rectangular uncertainty. Compensate the air instead (--air-compensation).");
    }
    return dT;
  }

  // The material: its temperature sensor and expansion coefficient when normalised to 20 degC,
  // the whole nominal expansion when not.
  void material() {
    const NormalisationResult& n = n_;
    const double alpha = std::isfinite(n.expansion_ppm_per_K) && n.expansion_ppm_per_K > 0
                             ? n.expansion_ppm_per_K
                             : in("nominal_expansion_ppm_per_K");
    const bool normalised = n.material_applied || n.material_compensation == "instrument";
    const bool known = !n.material_temperature_C.empty();
    const double offset = known ? std::abs(n.material_temperature_C.mean - 20) : kNaN;
    if (normalised) {
      add("material temperature sensor",
          format_significant(in("material_temperature_C"), 3) + " degC x " +
              format_significant(alpha, 3) + " um/(m K)",
          BudgetDistribution::Rectangular, ContributionKind::Scale,
          in("material_temperature_C") * alpha / kSqrt3, scale_unit());
      if (known)
        add("expansion coefficient",
            format_significant(100 * in("expansion_relative"), 3) + " % of " +
                format_significant(alpha, 3) + " um/(m K) x " + format_significant(offset, 3) +
                " K",
            BudgetDistribution::Rectangular, ContributionKind::Scale,
            in("expansion_relative") * alpha * offset / kSqrt3, scale_unit());
      else
        notes_.push_back(
            "No material temperature recorded: the expansion coefficient's uncertainty "
            "(proportional to T - 20 degC) is not in the budget.");
    } else if (known) {
      add("expansion not corrected",
          format_significant(alpha, 3) + " um/(m K) x " + format_significant(offset, 3) + " K",
          BudgetDistribution::Rectangular, ContributionKind::Scale, alpha * offset / kSqrt3,
          scale_unit());
      notes_.push_back(
          "Not normalised to 20 degC: the nominal differential expansion is counted as a "
          "rectangular uncertainty; correcting it (--expansion) removes it.");
    } else {
      notes_.push_back(
          "No material temperature recorded and no normalisation: the expansion to 20 degC is "
          "not in the budget.");
    }
  }

  // Set-up: cosine error over the travel, the dead path (`dT`: the air index' sensitivity to
  // temperature, ppm/K), the Abbe offset.
  void setup(double dT) {
    if (travel_ > 0 && in("misalignment_mm") > 0) {
      const double phi = in("misalignment_mm") / travel_;
      add("cosine error (beam misalignment)",
          format_significant(in("misalignment_mm"), 3) + " mm over " + format_number(travel_) +
              " mm",
          BudgetDistribution::OneSided, ContributionKind::Scale, phi * phi / 2 * 1e6 / kSqrt12,
          scale_unit());
    }
    if (in("dead_path_mm") > 0) {
      const double change = n_.air_refractivity.count > 1
                                ? n_.air_refractivity.max - n_.air_refractivity.min
                                : dT * 1e-6 * in("dead_path_air_change_C");
      add("dead path",
          format_significant(in("dead_path_mm"), 3) + " mm x " +
              format_significant(change * 1e6, 3) + " um/m",
          BudgetDistribution::Rectangular, ContributionKind::PerMean,
          in("dead_path_mm") * change * 1e3 / 2 / kSqrt3, unit_);
    }
    add("Abbe error",
        format_significant(in("abbe_offset_mm"), 3) + " mm x " +
            format_significant(in("abbe_angle_urad"), 3) + " urad",
        BudgetDistribution::Rectangular, ContributionKind::PerTarget,
        in("abbe_offset_mm") * in("abbe_angle_urad") * 1e-3 / 2 / kSqrt3, unit_);
  }

  // The environmental variation error and the run's own repeatability (type A, from its s).
  void environment_and_run() {
    add("environmental variation (EVE)",
        format_significant(in("eve_um"), 3) + " " + unit_ + " (range)",
        BudgetDistribution::Rectangular, ContributionKind::PerMean, in("eve_um") / 2 / kSqrt3,
        unit_);
    UncertaintyContribution a;
    a.name = "repeatability of the run (type A)";
    a.input = "s_i / sqrt(n) of the means, s_i sqrt(1 - c4^2) of the s";
    a.kind = ContributionKind::TypeA;
    C_.push_back(a);
  }

  const double kSqrt3 = std::sqrt(3.0), kSqrt12 = std::sqrt(12.0);
  const std::map<std::string, double>& in_;
  const NormalisationResult& n_;
  const std::string& unit_;
  double travel_;
  std::vector<std::string>& notes_;
  std::vector<UncertaintyContribution> C_;
};

// dF/dmean (`dm`) and dF/ds (`ds`) of each figure F, per direction and target.
struct FigureSensitivities {
  std::map<std::string, std::array<std::vector<double>, 2>> dm, ds;
};

// Central differences of the figures in the means and s (the figures are piecewise linear in
// the means; a step of 1e-6 um stays on one piece unless two extremes tie).
FigureSensitivities figure_sensitivities(const Point& p0, double k_up, double k_down) {
  const std::size_t m = p0.mean[kUp].size();
  const std::vector<std::string>& names = uncertainty_figure_names();
  const double h = 1e-6;
  FigureSensitivities S;
  for (const std::string& f : names)
    for (int d : {kUp, kDown}) S.dm[f][d].assign(m, 0), S.ds[f][d].assign(m, 0);
  for (int d : {kUp, kDown})
    for (std::size_t i = 0; i < m; ++i)
      for (bool of_s : {false, true}) {
        Point a = p0, b = p0;
        (of_s ? a.s : a.mean)[d][i] += h;
        (of_s ? b.s : b.mean)[d][i] -= h;
        if (of_s && b.s[d][i] < 0) b.s[d][i] = 0;
        const double step = of_s ? (a.s[d][i] - b.s[d][i]) : 2 * h;
        const auto fa = uncertainty_figure_values(figures_at(a, k_up, k_down));
        const auto fb = uncertainty_figure_values(figures_at(b, k_up, k_down));
        for (const std::string& f : names) {
          // A difference of rounding errors only (the figure does not depend on this input) is 0.
          const double v = (fa.at(f) - fb.at(f)) / step;
          (of_s ? S.ds : S.dm)[f][d][i] = std::abs(v) < 1e-6 ? 0.0 : v;
        }
      }
  return S;
}

// Each contribution's sensitivity and standard uncertainty per figure (GUM, linearised):
// a scale error moves every target by its travel, a per-target error both directions' means
// together, a per-mean error each mean on its own; type A from the run's s and cycles.
void propagate_contributions(std::vector<UncertaintyContribution>& C, const FigureSensitivities& S,
                             const Point& p0, const std::vector<double>& per_scale,
                             const std::array<std::size_t, 2>& cycles) {
  const std::size_t m = per_scale.size();
  for (UncertaintyContribution& c : C)
    for (const std::string& f : uncertainty_figure_names()) {
      const auto& dm = S.dm.at(f);
      const auto& ds = S.ds.at(f);
      double sens = 0, contribution = 0;
      switch (c.kind) {
        case ContributionKind::Scale:
          for (int d : {kUp, kDown})
            for (std::size_t i = 0; i < m; ++i) sens += dm[d][i] * per_scale[i];
          if (std::abs(sens) < 1e-9) sens = 0;
          contribution = std::abs(sens) * c.u;
          break;
        case ContributionKind::PerTarget:
          for (std::size_t i = 0; i < m; ++i) sens += std::pow(dm[kUp][i] + dm[kDown][i], 2);
          sens = std::sqrt(sens);
          contribution = sens * c.u;
          break;
        case ContributionKind::PerMean:
          for (int d : {kUp, kDown})
            for (std::size_t i = 0; i < m; ++i) sens += dm[d][i] * dm[d][i];
          sens = std::sqrt(sens);
          contribution = sens * c.u;
          break;
        case ContributionKind::TypeA:
          sens = kNaN;
          for (int d : {kUp, kDown}) {
            const double nd = static_cast<double>(cycles[static_cast<std::size_t>(d)]);
            const double spread =
                std::sqrt(1 - std::pow(c4(cycles[static_cast<std::size_t>(d)]), 2));
            for (std::size_t i = 0; i < m; ++i) {
              const double s = p0.s[d][i];
              contribution +=
                  std::pow(dm[d][i] * s / std::sqrt(nd), 2) + std::pow(ds[d][i] * s * spread, 2);
            }
          }
          contribution = std::sqrt(contribution);
          break;
      }
      c.sensitivity[f] = sens;
      c.contribution_um[f] = contribution;
    }
}

// Monte Carlo (GUM Supplement 1): the same inputs drawn from their distributions, the figures
// recomputed; each figure's Monte Carlo u and 95 % interval, and whether it confirms the
// linearised u.
void monte_carlo_check(UncertaintyResult& r, const Point& p0, double k_up, double k_down,
                       const std::vector<double>& per_scale,
                       const std::array<std::size_t, 2>& cycles) {
  const std::size_t m = per_scale.size();
  const std::vector<std::string>& names = uncertainty_figure_names();
  Normal g(r.seed);
  std::map<std::string, std::vector<double>> samples;
  for (const std::string& f : names) samples[f].reserve(r.trials);
  Point p = p0;
  for (std::size_t t = 0; t < r.trials; ++t) {
    for (int d : {kUp, kDown}) {
      const std::size_t nd = cycles[static_cast<std::size_t>(d)];
      for (std::size_t i = 0; i < m; ++i) {
        const double s = p0.s[d][i];
        p.mean[d][i] = p0.mean[d][i] + g() * s / std::sqrt(static_cast<double>(nd));
        double chi2 = 0;
        for (std::size_t k = 0; k + 1 < nd; ++k) {
          const double z = g();
          chi2 += z * z;
        }
        p.s[d][i] = nd > 1 ? s * std::sqrt(chi2 / static_cast<double>(nd - 1)) : s;
      }
    }
    for (const auto& c : r.contributions) {
      switch (c.kind) {
        case ContributionKind::Scale: {
          const double e = draw(g, c.distribution, c.u);
          for (int d : {kUp, kDown})
            for (std::size_t i = 0; i < m; ++i) p.mean[d][i] += e * per_scale[i];
          break;
        }
        case ContributionKind::PerTarget:
          for (std::size_t i = 0; i < m; ++i) {
            const double e = draw(g, c.distribution, c.u);
            p.mean[kUp][i] += e;
            p.mean[kDown][i] += e;
          }
          break;
        case ContributionKind::PerMean:
          for (int d : {kUp, kDown})
            for (std::size_t i = 0; i < m; ++i) p.mean[d][i] += draw(g, c.distribution, c.u);
          break;
        case ContributionKind::TypeA:
          break;
      }
    }
    const auto v = uncertainty_figure_values(figures_at(p, k_up, k_down));
    for (const std::string& f : names) samples[f].push_back(v.at(f));
  }
  for (FigureUncertainty& fu : r.figures) {
    std::vector<double>& x = samples[fu.name];
    double mean = 0;
    for (double v : x) mean += v / static_cast<double>(x.size());
    double ss = 0;
    for (double v : x) ss += (v - mean) * (v - mean);
    fu.mc_u = std::sqrt(ss / static_cast<double>(x.size() - 1));
    std::sort(x.begin(), x.end());
    const auto at = [&](double q) {
      return x[std::min(x.size() - 1, static_cast<std::size_t>(q * static_cast<double>(x.size())))];
    };
    fu.mc_low = at(0.025);
    fu.mc_high = at(0.975);
    // GUM Supplement 1, 8: the linearised u holds when the Monte Carlo's agrees; here within
    // 5 % (a figure whose extreme switches between targets under the perturbations does not).
    fu.validated = fu.u > 0 ? std::abs(fu.mc_u / fu.u - 1) <= 0.05 : fu.mc_u < 1e-9;
  }
}

}  // namespace

const std::vector<std::string>& uncertainty_classes() {
  static const std::vector<std::string> c = {"laser-compensated", "laser-edlen", "laser-manual",
                                             "scale"};
  return c;
}

std::map<std::string, double> uncertainty_defaults(const std::string& instrument_class) {
  const std::size_t c = class_index(instrument_class);
  std::map<std::string, double> out;
  for (const Key& k : keys()) out[k.name] = k.defaults[c];
  return out;
}

void UncertaintyBudget::validate() const {
  if (instrument_class != "auto") class_index(instrument_class);
  for (const auto& [name, v] : values) {
    // clang < 16 cannot capture a structured binding; the lambda takes a plain reference.
    const std::string& key = name;
    if (std::none_of(keys().begin(), keys().end(), [&](const Key& k) { return key == k.name; }))
      throw std::invalid_argument("uncertainty budget: unknown key '" + name +
                                  "' (keys: " + key_list() + ")");
    if (!(std::isfinite(v) && v >= 0))
      throw std::invalid_argument("uncertainty budget: " + name + " must be a number >= 0");
  }
  const auto k = values.find("coverage_factor");
  if (k != values.end() && !(k->second >= 1 && k->second <= 4))
    throw std::invalid_argument("uncertainty budget: coverage_factor must be in [1, 4]");
  const auto t = values.find("monte_carlo_trials");
  if (t != values.end() && (t->second != std::floor(t->second) || t->second > 1e7))
    throw std::invalid_argument(
        "uncertainty budget: monte_carlo_trials must be a whole number <= 1e7");
}

UncertaintyBudget parse_uncertainty_budget(const std::string& text, const std::string& file) {
  const YAML::Node root = parse_yaml(text, file);
  UncertaintyBudget b;
  b.source = file;
  auto loc = [&](const YAML::Node& n) {
    const YAML::Mark m = n.Mark();
    return SourceLoc{file, m.line + 1, m.column + 1};
  };
  if (root.IsNull()) return b;
  if (!root.IsMap())
    throw InputError(loc(root),
                     "an uncertainty budget is a YAML mapping (keys: " + key_list() + ")");
  for (const auto& item : root) {
    const std::string key = item.first.Scalar();
    if (key == "class") {
      b.instrument_class = item.second.IsScalar() ? item.second.Scalar() : "";
      if (b.instrument_class != "auto") try {
          class_index(b.instrument_class);
        } catch (const std::invalid_argument& e) {
          throw InputError(loc(item.second), e.what());
        }
      continue;
    }
    if (std::none_of(keys().begin(), keys().end(), [&](const Key& k) { return key == k.name; }))
      throw InputError(loc(item.first), "unknown key '" + key + "' (keys: " + key_list() + ")");
    if (b.values.count(key)) throw InputError(loc(item.first), "'" + key + "' given twice");
    double v = kNaN;
    if (item.second.IsScalar()) {
      const std::string t = trim(item.second.Scalar());
      char* end = nullptr;
      v = std::strtod(t.c_str(), &end);
      if (t.empty() || *end != '\0') v = kNaN;
    }
    if (!(std::isfinite(v) && v >= 0))
      throw InputError(loc(item.second), key + ": '" +
                                             (item.second.IsScalar() ? item.second.Scalar() : "") +
                                             "' is not a number >= 0");
    b.values[key] = v;
  }
  try {
    b.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError(loc(root), e.what());
  }
  return b;
}

UncertaintyBudget uncertainty_budget_from_flag(const std::string& flag) {
  const std::string t = trim(flag);
  UncertaintyBudget b;
  if (t == "auto") return b;
  const auto& names = uncertainty_classes();
  if (std::find(names.begin(), names.end(), t) != names.end()) {
    b.instrument_class = t;
    b.source = "defaults";
    return b;
  }
  if (t.empty() || t.find_first_of("/.") == std::string::npos)
    throw std::invalid_argument("--uncertainty " + flag + ": expected auto, a class (" +
                                join(names) + ") or a budget file (.yaml)");
  return parse_uncertainty_budget(read_data_file(t), t);
}

const char* to_string(ContributionKind k) {
  switch (k) {
    case ContributionKind::PerTarget:
      return "per target";
    case ContributionKind::PerMean:
      return "per mean";
    case ContributionKind::TypeA:
      return "type A";
    case ContributionKind::Scale:
      break;
  }
  return "scale";
}

const char* to_string(BudgetDistribution d) {
  switch (d) {
    case BudgetDistribution::Rectangular:
      return "rectangular";
    case BudgetDistribution::OneSided:
      return "one-sided rectangular";
    case BudgetDistribution::Normal:
      break;
  }
  return "normal";
}

const FigureUncertainty* UncertaintyResult::figure(const std::string& name) const {
  for (const auto& f : figures)
    if (f.name == name) return &f;
  return nullptr;
}

const std::vector<std::string>& uncertainty_figure_names() {
  static const std::vector<std::string> n = {"E",      "M",      "A",    "B",      "R",
                                             "E_up",   "E_down", "A_up", "A_down", "R_up",
                                             "R_down", "B_mean", "band"};
  return n;
}

std::map<std::string, double> uncertainty_figure_values(const IsoFigures& F) {
  double band = 0;
  for (std::size_t i = 0; i < F.mean_up.size(); ++i)
    for (double v :
         {F.mean_up[i] + F.k_up * F.s_up[i], F.mean_up[i] - F.k_up * F.s_up[i],
          F.mean_down[i] + F.k_down * F.s_down[i], F.mean_down[i] - F.k_down * F.s_down[i]})
      band = std::max(band, std::abs(v));
  return {{"E", F.E},           {"M", F.M},           {"A", F.A},
          {"B", F.B},           {"R", F.R},           {"E_up", F.E_up},
          {"E_down", F.E_down}, {"A_up", F.A_up},     {"A_down", F.A_down},
          {"R_up", F.R_up},     {"R_down", F.R_down}, {"B_mean", std::abs(F.B_mean)},
          {"band", band}};
}

Iso230_2Uncertainty::Iso230_2Uncertainty(UncertaintyBudget budget) : budget_(std::move(budget)) {
  budget_.validate();
}

UncertaintyResult Iso230_2Uncertainty::run(const IsoRuns& runs, const IsoFigures& classical,
                                           const NormalisationResult& n,
                                           const std::string& unit) const {
  UncertaintyResult r;
  r.source = budget_.source;
  r.instrument_class = budget_.instrument_class;
  if (r.instrument_class == "auto")
    r.instrument_class = n.air_applied ? "laser-edlen" : "laser-compensated";
  std::map<std::string, double> in = uncertainty_defaults(r.instrument_class);
  for (const auto& [k, v] : budget_.values) in[k] = v;
  r.coverage_factor = in["coverage_factor"];
  r.trials = static_cast<std::size_t>(in["monte_carlo_trials"]);
  r.seed = static_cast<std::uint64_t>(in["seed"]);
  const bool linear = unit == "um";
  const std::size_t m = runs.targets();
  const std::vector<double>& P = runs.positions_mm;
  const double travel = m ? P.back() - P.front() : 0;
  // Per unit of a scale error (µm/m): the travel from the datum in m.
  std::vector<double> per_scale(m);
  // A rotary axis' targets are in deg and its scale error in µrad/rad: the rotation in rad.
  for (std::size_t i = 0; i < m; ++i)
    per_scale[i] = (P[i] - n.datum_mm) * (linear ? 1e-3 : kPi / 180);

  r.contributions = BudgetContributions(in, n, unit, travel, r.notes)
                        .build(linear, r.instrument_class != "scale");
  Point p0;
  p0.mean = {classical.mean_up, classical.mean_down};
  p0.s = {classical.s_up, classical.s_down};
  const std::array<std::size_t, 2> cycles = {runs.cycles[kUp].size(), runs.cycles[kDown].size()};
  propagate_contributions(r.contributions,
                          figure_sensitivities(p0, classical.k_up, classical.k_down), p0, per_scale,
                          cycles);
  const auto values = uncertainty_figure_values(classical);
  for (const std::string& f : uncertainty_figure_names()) {
    FigureUncertainty fu;
    fu.name = f;
    fu.value = values.at(f);
    double u2 = 0;
    for (const auto& c : r.contributions) u2 += c.contribution_um.at(f) * c.contribution_um.at(f);
    fu.u = std::sqrt(u2);
    fu.U = r.coverage_factor * fu.u;
    r.figures.push_back(fu);
  }
  if (r.trials > 0) monte_carlo_check(r, p0, classical.k_up, classical.k_down, per_scale, cycles);
  return r;
}

}  // namespace weilgen
