// ReliabilityAnalysis: validation, the choice of method, names.
#include "weilgen/uq/reliability.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <stdexcept>

#include "reliability_detail.hpp"
#include "weilgen/base/parallel.hpp"

namespace weilgen {

using namespace reliability_detail;

const char* to_string(ReliabilityMethod method) {
  switch (method) {
    case ReliabilityMethod::Auto:
      return "auto";
    case ReliabilityMethod::Exact:
      return "exact";
    case ReliabilityMethod::Form:
      return "form";
    case ReliabilityMethod::ImportanceSampling:
      return "is";
    case ReliabilityMethod::MonteCarlo:
      return "mc";
  }
  return "?";
}

const char* to_string(LimitKind kind) {
  return kind == LimitKind::TwoSided ? "two-sided" : "upper";
}

ReliabilityMethod parse_reliability_method(const std::string& name) {
  std::string s(name);
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (s == "auto") return ReliabilityMethod::Auto;
  if (s == "exact") return ReliabilityMethod::Exact;
  if (s == "form") return ReliabilityMethod::Form;
  if (s == "is" || s == "importance-sampling") return ReliabilityMethod::ImportanceSampling;
  if (s == "mc" || s == "monte-carlo") return ReliabilityMethod::MonteCarlo;
  throw std::invalid_argument("unknown reliability method \"" + name +
                              "\": expected auto, exact, form, is (importance-sampling) or mc "
                              "(monte-carlo)");
}

namespace {

// Why Exact does not apply, or "" when it does.
std::string exact_obstacle(const ReliabilityProblem& p) {
  if (!p.linear) return "the response is not given as a linear form";
  for (std::size_t i = 0; i < p.inputs.size(); ++i) {
    const InputDistribution& d = p.inputs[i];
    if (d.kind() != InputDistribution::Kind::Normal && !d.is_constant())
      return "input " + std::to_string(i) + " is " + d.str() + ", not normal";
  }
  return "";
}

void validate(const ReliabilityProblem& p, const ReliabilityOptions& o) {
  if (p.inputs.empty()) throw std::invalid_argument("reliability: the problem has no inputs");
  if (!(p.tolerance > 0) || !std::isfinite(p.tolerance))
    throw std::invalid_argument("reliability: the tolerance must be finite and > 0");
  if (!p.response && !p.linear)
    throw std::invalid_argument(
        "reliability: the problem has neither a response nor a linear form");
  if (p.linear && p.linear->coefficients.size() != p.inputs.size())
    throw std::invalid_argument("reliability: the linear form has " +
                                std::to_string(p.linear->coefficients.size()) +
                                " coefficients for " + std::to_string(p.inputs.size()) + " inputs");
  o.validate();
}

// Every input constant: r is a number and R is 0 or 1.
ReliabilityResult deterministic(const StandardSpace& space, ReliabilityMethod method) {
  const ReliabilityProblem& p = space.problem();
  std::vector<double> x(space.num_inputs());
  space.to_x(nullptr, x.data());
  ReliabilityResult res;
  res.method = method;
  const double r = space.response(0, x.data(), res.evaluations);
  const bool safe = p.limit == LimitKind::TwoSided ? std::abs(r) <= p.tolerance : r <= p.tolerance;
  res.reliability = res.ci_lo = res.ci_hi = safe ? 1.0 : 0.0;
  res.failure = 1.0 - res.reliability;
  res.dR_dmu.assign(p.inputs.size(), 0.0);
  res.dR_dsigma.assign(p.inputs.size(), 0.0);
  res.note = "every input is constant: the response is deterministic";
  return res;
}

}  // namespace

bool exact_applicable(const ReliabilityProblem& problem) { return exact_obstacle(problem).empty(); }

void ReliabilityOptions::validate() const {
  if (!(confidence > 0 && confidence < 1))
    throw std::invalid_argument("reliability: the confidence must be in (0, 1)");
  if (form_max_iterations < 1 || !(form_tolerance > 0))
    throw std::invalid_argument("reliability: FORM needs max iterations >= 1 and a tolerance > 0");
}

double reliability_memory_bytes(const ReliabilityOptions& o, std::size_t inputs) {
  // Importance sampling keeps, per block of 64 lines, two derivative vectors and its moments.
  const double blocks = static_cast<double>(o.samples) / 64 + 1;
  return blocks * (16 * static_cast<double>(inputs) + 128);
}

ReliabilityAnalysis::ReliabilityAnalysis(ReliabilityOptions options)
    : options_(std::move(options)) {
  options_.validate();
}

ReliabilityResult ReliabilityAnalysis::run(const ReliabilityProblem& problem) const {
  const ReliabilityOptions& options = options_;
  validate(problem, options);
  ReliabilityMethod method = options.method;
  const std::string obstacle = exact_obstacle(problem);
  if (method == ReliabilityMethod::Auto)
    method = obstacle.empty() ? ReliabilityMethod::Exact : ReliabilityMethod::ImportanceSampling;
  if (method == ReliabilityMethod::Exact) {
    if (!obstacle.empty())
      throw std::invalid_argument(
          "reliability: the exact method needs a linear response and "
          "normal inputs, but " +
          obstacle);
    return exact_reliability(problem);
  }
  if ((method == ReliabilityMethod::ImportanceSampling ||
       method == ReliabilityMethod::MonteCarlo) &&
      options.samples == 0)
    throw std::invalid_argument("reliability: sampling needs samples >= 1");
  const StandardSpace space(problem);
  ReliabilityResult res;
  if (space.dim() == 0) {
    res = deterministic(space, method);
  } else if (method == ReliabilityMethod::Form) {
    res = form_reliability(space, options);
  } else if (method == ReliabilityMethod::ImportanceSampling) {
    res = importance_sampling(space, options);
  } else {
    res = monte_carlo(space, options);
  }
  if (options.qmc &&
      (method == ReliabilityMethod::ImportanceSampling || method == ReliabilityMethod::MonteCarlo))
    append_note(res.note, "qmc is not implemented: plain pseudo-random sampling was used");
  return res;
}

}  // namespace weilgen
