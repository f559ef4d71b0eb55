// Wang & Yuan 2021's step procedure (Tables 5-7): rank the inputs of every failing group by
// mean |dR/dsigma_i| * sigma_i, choose the top ones once, lower each chosen stddev by its step
// per iteration and re-evaluate until every group meets its targets.
#include <algorithm>
#include <cmath>

#include "allocation_detail.hpp"
#include "weilgen/uq/allocation.hpp"

namespace weilgen {

using namespace allocation_detail;

namespace {

AllocationStep make_step(std::size_t k, const std::vector<double>& stddev,
                         std::vector<std::size_t> tightened, const GroupStats& st) {
  AllocationStep s;
  s.step = k;
  s.stddev = stddev;
  s.tightened = std::move(tightened);
  s.group_min = st.min;
  s.group_mean = st.mean;
  s.group_argmin = st.argmin;
  return s;
}

}  // namespace

AllocationResult StepAllocation::run(const AllocationProblem& problem) const {
  const AllocationOptions& options = options_;
  validate(problem, options);
  const std::size_t n = problem.inputs.size(), G = problem.groups.size();
  const std::vector<double> sigma0 = stddevs(problem.inputs);
  AllocationResult res;
  std::vector<AllocationCase> cases = evaluate_checked(problem, problem.inputs);
  GroupStats st = group_stats(problem, cases, options);
  res.steps.push_back(make_step(0, sigma0, {}, st));

  // Ranking scores at the start.
  res.group_scores.assign(G, std::vector<double>(n, 0.0));
  std::vector<std::size_t> count(G, 0);
  for (const auto& c : cases) {
    ++count[c.group];
    for (std::size_t i = 0; i < n; ++i)
      res.group_scores[c.group][i] += std::abs(c.dR_dsigma[i]) * sigma0[i];
  }
  for (std::size_t g = 0; g < G; ++g)
    for (auto& v : res.group_scores[g]) v /= static_cast<double>(count[g]);
  res.group_chosen.assign(G, {});

  if (st.met) {
    res.met = true;
    res.note = "the targets are met at the start";
    return res;
  }
  if (!options.chosen.empty()) {
    res.chosen = options.chosen;
  } else {
    for (std::size_t g = 0; g < G; ++g) {
      if (st.group_met[g]) continue;
      std::vector<std::size_t> cand;
      for (std::size_t i = 0; i < n; ++i)
        if (options.step[i] > 0 && sigma0[i] > 0 && res.group_scores[g][i] > 0) cand.push_back(i);
      std::stable_sort(cand.begin(), cand.end(), [&](std::size_t a, std::size_t b) {
        return res.group_scores[g][a] > res.group_scores[g][b];
      });
      if (cand.size() > options.choose) cand.resize(options.choose);
      res.group_chosen[g] = cand;
      res.chosen.insert(res.chosen.end(), cand.begin(), cand.end());
    }
  }
  std::sort(res.chosen.begin(), res.chosen.end());
  res.chosen.erase(std::unique(res.chosen.begin(), res.chosen.end()), res.chosen.end());

  std::vector<std::size_t> times(n, 0);  // how often each input was lowered
  for (std::size_t k = 1; k <= options.max_steps; ++k) {
    std::vector<std::size_t> tighten;
    if (options.per_group && options.chosen.empty()) {
      for (std::size_t g = 0; g < G; ++g)
        if (!st.group_met[g])
          tighten.insert(tighten.end(), res.group_chosen[g].begin(), res.group_chosen[g].end());
      std::sort(tighten.begin(), tighten.end());
      tighten.erase(std::unique(tighten.begin(), tighten.end()), tighten.end());
    } else {
      tighten = res.chosen;
    }
    if (tighten.empty()) {
      res.note =
          "cannot meet the targets by tightening the chosen errors: a failing group has "
          "no input that can be tightened";
      return res;
    }
    std::vector<double> sigma = res.steps.back().stddev;
    for (std::size_t i : tighten) {
      // From the start, so that the k-th value is sigma0 - k * step without accumulated error.
      const double s = sigma0[i] - static_cast<double>(times[i] + 1) * options.step[i];
      if (s <= 1e-12 * sigma0[i]) {
        res.note =
            "cannot meet the targets by tightening the chosen errors: " + input_name(problem, i) +
            " would reach a stddev <= 0 at step " + std::to_string(k);
        return res;
      }
      sigma[i] = s;
    }
    for (std::size_t i : tighten) ++times[i];
    cases = evaluate_checked(problem, with_stddevs(problem.inputs, sigma));
    st = group_stats(problem, cases, options);
    res.steps.push_back(make_step(k, sigma, tighten, st));
    if (st.met) {
      res.met = true;
      return res;
    }
  }
  res.note = "the targets are not met after " + std::to_string(options.max_steps) + " steps";
  return res;
}

}  // namespace weilgen
