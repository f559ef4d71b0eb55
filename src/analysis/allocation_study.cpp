#include "weilgen/analysis/allocation_study.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"

namespace weilgen {

namespace {

// Later flags win over earlier ones of the same scope; per-error flags over kind-wide ones.
std::vector<double> parse_steps(const Description& d, const std::vector<std::string>& flags,
                                const std::vector<InputDistribution>& inputs) {
  const std::size_t ne = d.errors.size();
  std::vector<double> step(ne, 0.0), per_error(ne, 0.0);
  std::vector<bool> set_error(ne, false);
  bool any_kind = false;
  for (const auto& flag : flags) {
    const auto eq = flag.find('=');
    if (eq != std::string::npos) {
      const std::string name = trim(flag.substr(0, eq));
      const int i = d.error_index(name);
      if (i < 0) throw std::invalid_argument("--step: unknown error \"" + name + "\"");
      const auto& e = d.errors[i];
      const std::string def = e.base_unit();
      per_error[i] = parse_quantity(flag.substr(eq + 1), def, "--step " + name);
      set_error[i] = true;
      continue;
    }
    const std::string t = trim(flag);
    if (!t.empty() && t.back() == '%') {
      const double pct = parse_quantity_unit(t.substr(0, t.size() - 1), "mm", "--step").number;
      if (!(pct > 0 && pct < 100))
        throw std::invalid_argument("--step: percentage must be in (0, 100)");
      for (std::size_t i = 0; i < ne; ++i) step[i] = pct / 100 * inputs[i].stddev();
      any_kind = true;
      continue;
    }
    const Quantity q = parse_quantity_unit(t, "", "--step");
    for (std::size_t i = 0; i < ne; ++i)
      if ((d.errors[i].effect == ErrorEffect::Rotation) == q.unit.angle) step[i] = q.value();
    any_kind = true;
  }
  if (!any_kind && flags.empty())
    for (std::size_t i = 0; i < ne; ++i) step[i] = 0.1 * inputs[i].stddev();
  for (std::size_t i = 0; i < ne; ++i) {
    if (set_error[i]) step[i] = per_error[i];
    if (step[i] < 0 || !std::isfinite(step[i]))
      throw std::invalid_argument("--step: steps must be positive");
  }
  return step;
}

// Wang & Yuan 2021's choice: per output that misses a target, the `choose` errors with the largest
// mean |dR/dsigma| in base units.
void choose_raw(const AllocationProblem& prob, const Study& st, std::size_t choose,
                AllocationOptions& ao) {
  const std::size_t ne = st.inputs.size();
  const auto cases = prob.evaluate(st.inputs);
  for (std::size_t g = 0; g < prob.groups.size(); ++g) {
    std::vector<double> score(ne, 0.0);
    double mean = 0, min = 1;
    std::size_t n = 0;
    for (const auto& c : cases)
      if (c.group == g) {
        for (std::size_t i = 0; i < ne; ++i) score[i] += std::abs(c.dR_dsigma[i]);
        mean += c.reliability, min = std::min(min, c.reliability), ++n;
      }
    if (n == 0 || (min >= ao.min_target && mean / static_cast<double>(n) >= ao.mean_target))
      continue;
    std::vector<std::size_t> idx(ne);
    for (std::size_t i = 0; i < ne; ++i) idx[i] = i;
    std::stable_sort(idx.begin(), idx.end(), [&](auto a, auto b) { return score[a] > score[b]; });
    for (std::size_t k = 0; k < std::min(choose, ne); ++k)
      if (score[idx[k]] > 0 && ao.step[idx[k]] > 0 &&
          std::find(ao.chosen.begin(), ao.chosen.end(), idx[k]) == ao.chosen.end())
        ao.chosen.push_back(idx[k]);
  }
}

}  // namespace

void AllocationStudyOptions::validate() const {
  if (!(min_target > 0 && min_target < 1) || !(mean_target > 0 && mean_target < 1))
    throw std::invalid_argument("--min and --mean must be in (0, 1)");
  if (!(max_loosen >= 1)) throw std::invalid_argument("--max-loosen must be >= 1");
  if (rank != "scaled" && rank != "raw")
    throw std::invalid_argument("--rank must be scaled or raw, not '" + rank + "'");
  reliability.options.validate();
}

AllocationStudy::AllocationStudy(AllocationStudyOptions options) : options_(std::move(options)) {
  options_.validate();
}

AllocationStudyResult AllocationStudy::run(const Study& st) const {
  const AllocationStudyOptions& o = options_;
  const Description& d = st.model->description();
  const std::size_t ne = d.errors.size();
  AllocationStudyResult out;
  for (const auto& t : st.tolerances) out.groups.push_back(output_name(t.output));

  AllocationProblem prob;
  for (const auto& e : d.errors) prob.names.push_back(e.name);
  prob.inputs = st.inputs;
  prob.groups = out.groups;
  const ReliabilitySweep sweep(o.reliability);
  prob.evaluate = [&](const std::vector<InputDistribution>& inputs) {
    std::vector<AllocationCase> cases;
    for (auto& c : sweep.run(st, inputs))
      cases.push_back({c.tolerance, c.result.reliability, c.result.dR_dsigma});
    return cases;
  };
  AllocationOptions& ao = out.options;
  ao.min_target = o.min_target;
  ao.mean_target = o.mean_target;
  ao.step = parse_steps(d, o.steps, st.inputs);
  ao.choose = o.choose;
  ao.max_steps = o.max_steps;
  ao.per_group = o.per_output;
  for (const auto& item : o.errors) {
    const int i = d.error_index(trim(item));
    if (i < 0) throw std::invalid_argument("--errors: unknown error \"" + trim(item) + "\"");
    ao.chosen.push_back(static_cast<std::size_t>(i));
  }
  if (o.rank == "raw" && ao.chosen.empty()) choose_raw(prob, st, o.choose, ao);
  // Default weights: the starting spreads, so that the cost sum sigma0_i / sigma_i is free of
  // units and every error costs 1 at the start (a raw sum of 1/sigma would let the rad-valued
  // errors, ~1e-5, outweigh the mm-valued ones, ~1e-2, by three orders of magnitude).
  for (std::size_t i = 0; i < ne; ++i) ao.cost_weights.push_back(st.inputs[i].stddev());
  for (const auto& w : o.weights) {
    const auto eq = w.find('=');
    const int i = eq == std::string::npos ? -1 : d.error_index(trim(w.substr(0, eq)));
    if (i < 0)
      throw std::invalid_argument("--weight: expected NAME=w with a known error, not \"" + w +
                                  "\"");
    const auto& e = d.errors[i];
    ao.cost_weights[i] = parse_quantity(w.substr(eq + 1), e.base_unit(), "--weight");
    if (!(ao.cost_weights[i] >= 0)) throw std::invalid_argument("--weight: must be >= 0");
  }
  for (std::size_t i = 0; i < ne; ++i) {
    ao.sigma_lower.push_back(0.01 * st.inputs[i].stddev());
    ao.sigma_upper.push_back(o.max_loosen * st.inputs[i].stddev());
  }

  out.result = StepAllocation(ao).run(prob);
  if (o.cost_aware) out.result = CostAwareAllocation(ao).run(prob, out.result);
  out.final_inputs = st.inputs;
  if (!out.result.steps.empty())
    for (std::size_t i = 0; i < ne; ++i)
      out.final_inputs[i] =
          st.inputs[i].with_mean_stddev(st.inputs[i].mean(), out.result.steps.back().stddev[i]);
  return out;
}

}  // namespace weilgen
