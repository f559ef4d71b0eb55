// Shared pieces of the allocation procedures: validation, checked evaluation, group statistics.
#include "weilgen/uq/allocation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "allocation_detail.hpp"

namespace weilgen::allocation_detail {

namespace {
[[noreturn]] void fail(const std::string& what) {
  throw std::invalid_argument("allocation: " + what);
}
}  // namespace

std::string input_name(const AllocationProblem& problem, std::size_t i) {
  return i < problem.names.size() ? problem.names[i] : "x" + std::to_string(i);
}

void validate(const AllocationProblem& problem, const AllocationOptions& options) {
  const std::size_t n = problem.inputs.size();
  if (n == 0) fail("the problem has no inputs");
  if (!problem.names.empty() && problem.names.size() != n)
    fail(std::to_string(problem.names.size()) + " names for " + std::to_string(n) + " inputs");
  if (problem.groups.empty()) fail("the problem has no groups");
  if (!problem.evaluate) fail("the problem has no evaluate function");
  options.validate();
  if (options.step.size() != n)
    fail("step: " + std::to_string(options.step.size()) + " decrements for " + std::to_string(n) +
         " inputs");
  for (std::size_t k = 0; k < options.chosen.size(); ++k) {
    const std::size_t i = options.chosen[k];
    if (i >= n) fail("chosen input " + std::to_string(i) + " is out of range");
    if (!(options.step[i] > 0))
      fail("chosen input " + input_name(problem, i) + " has no positive step");
    if (problem.inputs[i].is_constant())
      fail("chosen input " + input_name(problem, i) + " is constant");
    if (std::count(options.chosen.begin(), options.chosen.end(), i) > 1)
      fail("input " + input_name(problem, i) + " is chosen twice");
  }
  for (const auto* v : {&options.cost_weights, &options.sigma_lower, &options.sigma_upper})
    if (!v->empty() && v->size() != n)
      fail("cost weights and sigma bounds need one value per input");
}

std::vector<AllocationCase> evaluate_checked(const AllocationProblem& problem,
                                             const std::vector<InputDistribution>& inputs) {
  std::vector<AllocationCase> cases = problem.evaluate(inputs);
  std::vector<bool> seen(problem.groups.size(), false);
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const AllocationCase& k = cases[c];
    if (k.group >= problem.groups.size())
      fail("case " + std::to_string(c) + " has group " + std::to_string(k.group) + " of " +
           std::to_string(problem.groups.size()));
    if (k.dR_dsigma.size() != inputs.size())
      fail("case " + std::to_string(c) + " has " + std::to_string(k.dR_dsigma.size()) +
           " sensitivities for " + std::to_string(inputs.size()) + " inputs");
    if (!std::isfinite(k.reliability))
      fail("case " + std::to_string(c) + " has a non-finite reliability");
    seen[k.group] = true;
  }
  for (std::size_t g = 0; g < seen.size(); ++g)
    if (!seen[g]) fail("group " + problem.groups[g] + " has no cases");
  return cases;
}

GroupStats group_stats(const AllocationProblem& problem, const std::vector<AllocationCase>& cases,
                       const AllocationOptions& options) {
  const std::size_t G = problem.groups.size();
  GroupStats st;
  st.min.assign(G, 2.0);
  st.mean.assign(G, 0.0);
  st.argmin.assign(G, 0);
  std::vector<std::size_t> count(G, 0);
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const std::size_t g = cases[c].group;
    if (cases[c].reliability < st.min[g]) {
      st.min[g] = cases[c].reliability;
      st.argmin[g] = c;
    }
    st.mean[g] += cases[c].reliability;
    ++count[g];
  }
  st.met = true;
  st.group_met.assign(G, false);
  for (std::size_t g = 0; g < G; ++g) {
    st.mean[g] /= static_cast<double>(count[g]);
    const double tol = options.target_tolerance;
    st.group_met[g] =
        st.min[g] >= options.min_target - tol && st.mean[g] >= options.mean_target - tol;
    st.met = st.met && st.group_met[g];
  }
  return st;
}

std::vector<InputDistribution> with_stddevs(const std::vector<InputDistribution>& inputs,
                                            const std::vector<double>& stddev) {
  std::vector<InputDistribution> out(inputs);
  for (std::size_t i = 0; i < inputs.size(); ++i)
    if (stddev[i] != inputs[i].stddev())
      out[i] = inputs[i].with_mean_stddev(inputs[i].mean(), stddev[i]);
  return out;
}

std::vector<double> stddevs(const std::vector<InputDistribution>& inputs) {
  std::vector<double> s;
  for (const auto& d : inputs) s.push_back(d.stddev());
  return s;
}

}  // namespace weilgen::allocation_detail

namespace weilgen {

void AllocationOptions::validate() const {
  for (double target : {min_target, mean_target})
    if (!(target > 0 && target <= 1))
      throw std::invalid_argument("allocation: the targets must be in (0, 1]");
  if (!(target_tolerance >= 0 && target_tolerance <= 1e-3))
    throw std::invalid_argument("allocation: target_tolerance must be in [0, 1e-3]");
  for (double w : cost_weights)
    if (!(w >= 0) || !std::isfinite(w))
      throw std::invalid_argument("allocation: cost weights must be finite and >= 0");
  if (cost_max_evaluations < 1)
    throw std::invalid_argument("allocation: cost_max_evaluations must be >= 1");
}

StepAllocation::StepAllocation(AllocationOptions options) : options_(std::move(options)) {
  options_.validate();
}

CostAwareAllocation::CostAwareAllocation(AllocationOptions options) : options_(std::move(options)) {
  options_.validate();
}

}  // namespace weilgen
