// The tolerance-allocation engine on a synthetic problem whose step procedure can be followed by
// hand: two groups of exact linear Gaussian cases.
#include <doctest/doctest.h>

#include <cmath>
#include <stdexcept>

#include "weilgen/uq/allocation.hpp"
#include "weilgen/uq/reliability.hpp"

using namespace weilgen;

namespace {

double Phi(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

constexpr double kT = 0.025;  // two-sided tolerance of every case

// Inputs x0..x3, normal(0, sigma). Group "dx": r = x0 + p x2 for p = 1, 2, 3 (three poses);
// group "dy": r = x1 + 0.5 x2 + p x3 for p = 1, 2, 3.
std::vector<LinearForm> case_forms() {
  std::vector<LinearForm> f;
  for (double p : {1.0, 2.0, 3.0}) f.push_back(LinearForm{0.0, {1.0, 0.0, p, 0.0}});
  for (double p : {1.0, 2.0, 3.0}) f.push_back(LinearForm{0.0, {0.0, 1.0, 0.5, p}});
  return f;
}

AllocationProblem synthetic_problem(std::size_t* calls = nullptr) {
  AllocationProblem p;
  p.names = {"x0", "x1", "x2", "x3"};
  for (double s : {0.010, 0.012, 0.004, 0.002}) p.inputs.push_back(InputDistribution::normal(0, s));
  p.groups = {"dx", "dy"};
  p.evaluate = [calls](const std::vector<InputDistribution>& inputs) {
    if (calls) ++*calls;
    std::vector<AllocationCase> cases;
    const auto forms = case_forms();
    for (std::size_t c = 0; c < forms.size(); ++c) {
      ReliabilityProblem rp;
      rp.inputs = inputs;
      rp.linear = forms[c];
      rp.tolerance = kT;
      const auto r = ReliabilityAnalysis(ReliabilityOptions{}).run(rp);
      cases.push_back(AllocationCase{c < 3 ? 0u : 1u, r.reliability, r.dR_dsigma});
    }
    return cases;
  };
  return p;
}

// Independent check: min and mean reliability of each group for the given sigmas.
void group_values(const std::vector<double>& s, double min[2], double mean[2]) {
  for (int g = 0; g < 2; ++g) {
    min[g] = 1;
    mean[g] = 0;
  }
  for (double p : {1.0, 2.0, 3.0}) {
    const double sx = std::sqrt(s[0] * s[0] + p * p * s[2] * s[2]);
    const double sy = std::sqrt(s[1] * s[1] + 0.25 * s[2] * s[2] + p * p * s[3] * s[3]);
    const double rx = 2 * Phi(kT / sx) - 1, ry = 2 * Phi(kT / sy) - 1;
    min[0] = std::min(min[0], rx);
    min[1] = std::min(min[1], ry);
    mean[0] += rx / 3;
    mean[1] += ry / 3;
  }
}

AllocationOptions synthetic_options() {
  AllocationOptions o;
  o.step = {0.001, 0.001, 0.0005, 0.0005};
  o.choose = 1;
  return o;
}

}  // namespace

TEST_CASE("allocation: the step procedure on a problem followed by hand") {
  // Start: dx min 0.8905 (p = 3), mean 0.9398; dy min 0.9347, mean 0.9471: both fail.
  // Ranking (mean |dR/dsigma_i| sigma_i): dx x0 0.1315 > x2 0.1057; dy x1 0.2034 > x3 0.0269
  // > x2 0.0056. With choose = 1: x0 for dx, x1 for dy.
  // dx's worst case p = 3 needs 0.025 / sqrt(s0^2 + 9 * 0.004^2) >= 1.95996, i.e.
  // s0 <= 0.004324: from 0.010 in steps of 0.001 that is 0.004, step 6 (its mean is then 0.982).
  // dy needs s1 <= 0.01108 for the minimum and s1 <= 0.0100 (step 2) for the mean >= 0.97.
  const AllocationProblem problem = synthetic_problem();
  AllocationOptions o = synthetic_options();
  const AllocationResult res = StepAllocation(o).run(problem);
  CHECK(res.met);
  CHECK(res.note.empty());
  CHECK(res.chosen == std::vector<std::size_t>{0, 1});
  CHECK(res.group_chosen[0] == std::vector<std::size_t>{0});
  CHECK(res.group_chosen[1] == std::vector<std::size_t>{1});
  CHECK(res.group_scores[0][0] == doctest::Approx(0.131544).epsilon(1e-5));
  CHECK(res.group_scores[0][2] == doctest::Approx(0.105691).epsilon(1e-5));
  CHECK(res.group_scores[1][1] == doctest::Approx(0.203393).epsilon(1e-5));
  CHECK(res.group_scores[0][1] == 0);
  REQUIRE(res.steps.size() == 7);  // start + 6 steps
  CHECK(res.steps[0].group_min[0] == doctest::Approx(0.890504).epsilon(1e-6));
  CHECK(res.steps[0].group_mean[1] == doctest::Approx(0.947058).epsilon(1e-6));
  CHECK(res.steps[0].group_argmin[0] == 2);  // p = 3 of dx
  CHECK(res.steps[0].group_argmin[1] == 5);  // p = 3 of dy
  CHECK(res.steps[0].tightened.empty());
  CHECK(res.steps[1].tightened == std::vector<std::size_t>{0, 1});
  const auto& last = res.steps.back().stddev;
  CHECK(last[0] == doctest::Approx(0.004).epsilon(1e-12));
  CHECK(last[1] == doctest::Approx(0.006).epsilon(1e-12));
  CHECK(last[2] == 0.004);
  CHECK(last[3] == 0.002);
  for (const auto& s : res.steps) {
    double mn[2], me[2];
    group_values(s.stddev, mn, me);
    CAPTURE(s.step);
    for (int g = 0; g < 2; ++g) {
      CHECK(s.group_min[g] == doctest::Approx(mn[g]).epsilon(1e-12));
      CHECK(s.group_mean[g] == doctest::Approx(me[g]).epsilon(1e-12));
    }
    const bool met = mn[0] >= 0.95 && me[0] >= 0.97 && mn[1] >= 0.95 && me[1] >= 0.97;
    CHECK(met == (s.step == 6));
  }

  // Tightening only the failing groups' choices: dy stops after step 2 at s1 = 0.010.
  o.per_group = true;
  const AllocationResult pg = StepAllocation(o).run(problem);
  CHECK(pg.met);
  REQUIRE(pg.steps.size() == 7);
  CHECK(pg.steps[2].tightened == std::vector<std::size_t>{0, 1});
  CHECK(pg.steps[3].tightened == std::vector<std::size_t>{0});
  CHECK(pg.steps.back().stddev[0] == doctest::Approx(0.004).epsilon(1e-12));
  CHECK(pg.steps.back().stddev[1] == doctest::Approx(0.010).epsilon(1e-12));
}

TEST_CASE("allocation: targets met at the start, and targets out of reach") {
  const AllocationProblem problem = synthetic_problem();
  AllocationOptions o = synthetic_options();
  o.min_target = 0.85;
  o.mean_target = 0.9;
  const AllocationResult easy = StepAllocation(o).run(problem);
  CHECK(easy.met);
  CHECK(easy.steps.size() == 1);
  CHECK(easy.chosen.empty());
  CHECK(easy.note == "the targets are met at the start");

  // Only x2 and x3 may be tightened: dy keeps s1 = 0.012, so its mean stays below 0.97 however
  // small they get; x3 (0.002, step 0.0005) would reach 0 at step 4.
  o = synthetic_options();
  o.chosen = {2, 3};
  const AllocationResult stuck = StepAllocation(o).run(problem);
  CHECK_FALSE(stuck.met);
  CHECK(stuck.steps.size() == 4);
  CHECK(stuck.note ==
        "cannot meet the targets by tightening the chosen errors: x3 would reach a stddev <= 0 "
        "at step 4");
  CHECK(stuck.steps.back().stddev[3] == doctest::Approx(0.0005).epsilon(1e-12));

  o = synthetic_options();
  o.max_steps = 3;
  const AllocationResult short_run = StepAllocation(o).run(problem);
  CHECK_FALSE(short_run.met);
  CHECK(short_run.steps.size() == 4);
  CHECK(short_run.note == "the targets are not met after 3 steps");
}

TEST_CASE("allocation: cost-aware mode meets the targets at a lower cost") {
  std::size_t calls = 0;
  const AllocationProblem problem = synthetic_problem(&calls);
  AllocationOptions o = synthetic_options();
  const AllocationResult steps = StepAllocation(o).run(problem);
  REQUIRE(steps.met);
  o.per_group = true;
  const AllocationResult pg = StepAllocation(o).run(problem);
  o.per_group = false;
  calls = 0;
  const AllocationResult res = CostAwareAllocation(o).run(problem, steps);
  CHECK(res.steps.size() == steps.steps.size());
  CHECK(res.cost_aware_met);
  CHECK(res.cost_aware_evaluations == calls);
  const auto cost = [](const std::vector<double>& s) {
    double c = 0;
    for (double v : s) c += 1 / v;
    return c;
  };
  CHECK(res.cost_step == doctest::Approx(cost(steps.steps.back().stddev)).epsilon(1e-12));
  CHECK(res.cost_aware == doctest::Approx(cost(res.cost_aware_stddev)).epsilon(1e-12));
  CHECK(res.cost_aware <= res.cost_step);
  CHECK(res.cost_aware <= cost(pg.steps.back().stddev));  // also beats the per-group end point
  // Re-evaluated independently: the targets hold.
  double mn[2], me[2];
  group_values(res.cost_aware_stddev, mn, me);
  for (int g = 0; g < 2; ++g) {
    CAPTURE(g);
    CHECK(mn[g] >= 0.95 - AllocationOptions{}.target_tolerance);
    CHECK(me[g] >= 0.97 - AllocationOptions{}.target_tolerance);
    CHECK(res.cost_aware_group_min[g] == doctest::Approx(mn[g]).epsilon(1e-12));
    CHECK(res.cost_aware_group_mean[g] == doctest::Approx(me[g]).epsilon(1e-12));
  }
  // Within the default bounds [1 %, 100 %] of the start.
  for (std::size_t i = 0; i < 4; ++i) {
    CHECK(res.cost_aware_stddev[i] <= problem.inputs[i].stddev() * (1 + 1e-12));
    CHECK(res.cost_aware_stddev[i] >= 0.01 * problem.inputs[i].stddev() * (1 - 1e-12));
  }
  MESSAGE("cost-aware: cost " << res.cost_aware << " vs steps " << res.cost_step
                              << " (per-group steps " << cost(pg.steps.back().stddev) << "), sigma "
                              << res.cost_aware_stddev[0] << " " << res.cost_aware_stddev[1] << " "
                              << res.cost_aware_stddev[2] << " " << res.cost_aware_stddev[3]
                              << ", dx min " << mn[0] << " mean " << me[0] << ", dy min " << mn[1]
                              << " mean " << me[1] << ", " << res.cost_aware_evaluations
                              << " evaluations; " << res.note);

  // Weights: making x0 very expensive to tighten moves the burden to x2.
  AllocationOptions w = o;
  w.cost_weights = {100.0, 1.0, 1.0, 1.0};
  const AllocationResult rw = CostAwareAllocation(w).run(problem, steps);
  CHECK(rw.cost_aware_met);
  CHECK(rw.cost_aware_stddev[0] > res.cost_aware_stddev[0]);
  CHECK(rw.cost_aware_stddev[2] < res.cost_aware_stddev[2]);
}

TEST_CASE("allocation: bad problems throw std::invalid_argument") {
  const AllocationProblem problem = synthetic_problem();
  AllocationOptions o = synthetic_options();
  o.step.pop_back();
  CHECK_THROWS_AS(StepAllocation(o).run(problem), std::invalid_argument);
  o = synthetic_options();
  o.chosen = {7};
  CHECK_THROWS_AS(StepAllocation(o).run(problem), std::invalid_argument);
  o.chosen = {1, 1};
  CHECK_THROWS_AS(StepAllocation(o).run(problem), std::invalid_argument);
  o = synthetic_options();
  o.step[1] = 0;
  o.chosen = {1};
  CHECK_THROWS_WITH_AS(StepAllocation(o).run(problem), doctest::Contains("x1 has no positive step"),
                       std::invalid_argument);
  o = synthetic_options();
  o.min_target = 1.5;
  CHECK_THROWS_AS(StepAllocation(o).run(problem), std::invalid_argument);
  AllocationProblem bad = problem;
  bad.evaluate = [](const std::vector<InputDistribution>&) {
    return std::vector<AllocationCase>{AllocationCase{0, 0.9, {0, 0, 0, 0}}};
  };
  CHECK_THROWS_WITH_AS(StepAllocation(synthetic_options()).run(bad),
                       doctest::Contains("group dy has no cases"), std::invalid_argument);
  bad.evaluate = [](const std::vector<InputDistribution>&) {
    return std::vector<AllocationCase>{AllocationCase{0, 0.9, {0, 0}},
                                       AllocationCase{1, 0.9, {0, 0, 0, 0}}};
  };
  CHECK_THROWS_AS(StepAllocation(synthetic_options()).run(bad), std::invalid_argument);
  o = synthetic_options();
  o.sigma_lower = {0.0, 0.0, 0.0, 0.0};
  CHECK_THROWS_AS(
      CostAwareAllocation(o).run(problem, StepAllocation(synthetic_options()).run(problem)),
      std::invalid_argument);
}
