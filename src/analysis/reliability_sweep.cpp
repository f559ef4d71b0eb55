#include "weilgen/analysis/reliability_sweep.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "weilgen/base/memory.hpp"
#include "weilgen/base/parallel.hpp"

namespace weilgen {

LimitChoice parse_limit(const std::string& text) {
  if (text == "two-sided") return LimitChoice::TwoSided;
  if (text == "one-sided") return LimitChoice::OneSided;
  if (text == "radial") return LimitChoice::Radial;
  throw std::invalid_argument("--limit must be two-sided, one-sided or radial, not '" + text + "'");
}

const char* limit_name(LimitChoice limit, OutputId output) {
  if (output == OutputId::Dp) return "radial";
  return limit == LimitChoice::OneSided ? "one-sided" : "two-sided";
}

SensitivityChoice parse_sensitivities(const std::string& text) {
  if (text == "auto") return SensitivityChoice::Auto;
  if (text == "form") return SensitivityChoice::Form;
  if (text == "sampling") return SensitivityChoice::Sampling;
  throw std::invalid_argument("--sensitivities must be auto, form or sampling, not '" + text + "'");
}

ReliabilitySettings parse_reliability_settings(const std::string& method, const std::string& limit,
                                               const std::string& sensitivities,
                                               std::size_t samples, double confidence,
                                               std::uint64_t seed) {
  if (samples == 0) throw std::invalid_argument("--samples must be >= 1");
  if (!(confidence > 0 && confidence < 1))
    throw std::invalid_argument("--confidence must be in (0, 1)");
  ReliabilitySettings s{parse_limit(limit), parse_sensitivities(sensitivities), {}};
  s.options.method = parse_reliability_method(method);
  s.options.samples = samples;
  s.options.seed = seed;
  s.options.confidence = confidence;
  return s;
}

ReliabilitySettings parse_reliability_flags(const ReliabilityFlags& f, std::uint64_t seed) {
  return parse_reliability_settings(f.method, f.limit, f.sensitivities, f.samples, f.confidence,
                                    seed);
}

ReliabilitySweep::ReliabilitySweep(ReliabilitySettings settings) : settings_(std::move(settings)) {
  settings_.options.validate();
}

std::vector<SweepCase> ReliabilitySweep::run(
    const Study& st, const std::vector<InputDistribution>& inputs,
    const std::function<void(std::size_t, std::size_t)>& progress) const {
  const LimitChoice limit = settings_.limit;
  const SensitivityChoice sensitivities = settings_.sensitivities;
  ReliabilityOptions options = settings_.options;
  options.threads = st.threads;
  const Model& model = *st.model;
  const std::size_t ne = model.num_errors(), np = st.poses.poses.size();
  if (limit == LimitChoice::Radial)
    for (const auto& t : st.tolerances)
      if (t.output != OutputId::Dp)
        throw std::invalid_argument(
            "--limit radial bounds |(dx,dy,dz)|: give its tolerance as dp=..., not " +
            std::string(output_name(t.output)));
  // Results (each with dR/dmu, dR/dsigma per error) and one analysis's working memory.
  check_memory(static_cast<double>(np * st.tolerances.size()) *
                       (sizeof(SweepCase) + 48.0 * static_cast<double>(ne)) +
                   reliability_memory_bytes(options, ne),
               "--samples " + std::to_string(options.samples) + " at " + std::to_string(np) +
                   (np == 1 ? " pose" : " poses"),
               "lower --samples or the number of poses");
  std::vector<ModelData> work;
  for (unsigned t = 0; t < std::max(1u, st.threads); ++t) work.emplace_back(model);
  // Order 1: every component is exactly linear in the errors. Its linear form (deviation at zero
  // error, coefficients) depends on the pose only, so it is computed once per pose and shared
  // by every toleranced output.
  const bool linear = model.order() == 1 && model.engine() != ModelEngine::NumericChain;
  std::vector<std::vector<double>> coeff, base;
  if (linear) {
    ModelData data(model);
    const std::vector<double> zero(ne, 0.0);
    for (std::size_t p = 0; p < np; ++p) {
      base.emplace_back(6);
      model.deviation_and_coefficients(data, st.poses.poses[p].data(), zero.data(),
                                       base.back().data(), data.coeff.data());
      coeff.push_back(data.coeff);
    }
  }
  std::vector<SweepCase> cases;
  const std::size_t total = st.tolerances.size() * np;
  for (std::size_t k = 0; k < st.tolerances.size(); ++k) {
    const OutputId out = st.tolerances[k].output;
    for (std::size_t p = 0; p < np; ++p) {
      throw_if_cancelled();
      const double* pose = st.poses.poses[p].data();
      ReliabilityProblem prob;
      prob.inputs = inputs;
      prob.tolerance = st.tolerances[k].value;
      prob.limit = (out == OutputId::Dp || limit == LimitChoice::OneSided) ? LimitKind::Upper
                                                                           : LimitKind::TwoSided;
      if (out == OutputId::Dp) {
        prob.response = [&, pose](unsigned t, const double* x) {
          ModelData& w = work[t];
          model.deviation(w, pose, x, w.out.data());
          return std::sqrt(w.out[0] * w.out[0] + w.out[1] * w.out[1] + w.out[2] * w.out[2]);
        };
      } else {
        const std::size_t row = static_cast<std::size_t>(out);
        if (linear) {
          prob.linear = LinearForm{
              base[p][row],
              std::vector<double>(coeff[p].begin() + row * ne, coeff[p].begin() + (row + 1) * ne)};
        } else {
          prob.response = [&, pose, row](unsigned t, const double* x) {
            ModelData& w = work[t];
            model.deviation(w, pose, x, w.out.data());
            return w.out[row];
          };
        }
      }
      ReliabilityOptions o = options;
      o.sensitivities = sensitivities == SensitivityChoice::Sampling ||
                                (sensitivities == SensitivityChoice::Auto && out == OutputId::Dp)
                            ? SensitivityMethod::Sampling
                            : SensitivityMethod::Form;
      cases.push_back({p, k, ReliabilityAnalysis(o).run(prob)});
      if (progress) progress(cases.size(), total);
    }
  }
  return cases;
}

std::vector<SweepSummary> summarize(const Study& st, const std::vector<SweepCase>& cases) {
  std::vector<SweepSummary> s(st.tolerances.size());
  std::vector<std::size_t> n(st.tolerances.size(), 0);
  for (const auto& c : cases) {
    SweepSummary& x = s[c.tolerance];
    const double r = c.result.reliability;
    if (n[c.tolerance] == 0 || r < x.min) x.min = r, x.argmin = c.pose;
    x.mean += r;
    ++n[c.tolerance];
  }
  for (std::size_t k = 0; k < s.size(); ++k)
    if (n[k]) s[k].mean /= static_cast<double>(n[k]);
  return s;
}

}  // namespace weilgen

namespace weilgen {

std::vector<std::pair<std::size_t, double>> ranked_sensitivity(
    const std::vector<SweepCase>& cases, std::size_t tolerance,
    const std::vector<InputDistribution>& inputs) {
  std::vector<double> s(inputs.size(), 0.0);
  std::size_t n = 0;
  for (const auto& c : cases) {
    if (c.tolerance != tolerance) continue;
    ++n;
    for (std::size_t i = 0; i < inputs.size() && i < c.result.dR_dsigma.size(); ++i)
      s[i] += std::abs(c.result.dR_dsigma[i]) * inputs[i].stddev();
  }
  std::vector<std::pair<std::size_t, double>> r;
  for (std::size_t i = 0; i < s.size(); ++i)
    r.push_back({i, n ? s[i] / static_cast<double>(n) : 0.0});
  std::stable_sort(r.begin(), r.end(), [](auto& a, auto& b) { return a.second > b.second; });
  return r;
}

}  // namespace weilgen
