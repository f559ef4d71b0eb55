// Tolerance allocation: tighten the spreads of the inputs that matter most until every
// reliability requirement group meets its targets (min over its cases >= min_target and mean over
// its cases >= mean_target). Generic: the caller's `evaluate` computes every case (e.g. one output
// over a grid of poses) for a set of input distributions, with dR/dsigma per input.
//   StepAllocation       Wang & Yuan 2021's procedure (Tables 5-7): choose the most sensitive
//   inputs once,
//                        lower each chosen stddev by a fixed step per iteration, re-evaluate.
//   CostAwareAllocation  minimise sum_i w_i / sigma_i subject to the same targets (NLopt SLSQP,
//                        gradients from dR/dsigma), started from the step procedure's end point.
// docs/reliability.md, section "Tolerance allocation", has the details.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "weilgen/uq/distribution.hpp"

namespace weilgen {

// One reliability requirement case (e.g. one pose of one output) of a group.
struct AllocationCase {
  std::size_t group = 0;          // index into AllocationProblem::groups
  double reliability = 0;         // R of the case
  std::vector<double> dR_dsigma;  // per input (same order as AllocationProblem::inputs)
};

struct AllocationProblem {
  std::vector<std::string> names;         // input names (for the tables); empty: "x0", "x1", ...
  std::vector<InputDistribution> inputs;  // the starting spreads
  std::vector<std::string> groups;        // group names, e.g. "dx", "dy"
  // Every case (pose x output) for the given inputs (same order as `inputs`). Must return the
  // same number of cases in the same order for every call.
  std::function<std::vector<AllocationCase>(const std::vector<InputDistribution>&)> evaluate;
};

struct AllocationOptions {
  double min_target = 0.95, mean_target = 0.97;  // per group: min and mean over its cases
  // A target counts as met when R >= target - target_tolerance (absolute, R in 0..1): an
  // optimum on the constraint misses it by rounding (2e-12), which is no verdict of its own.
  double target_tolerance = 1e-9;
  // Per input: the absolute stddev decrement per step. An input with step <= 0 is never chosen
  // by the ranking (it cannot be tightened); an explicitly chosen input must have step > 0.
  std::vector<double> step;
  // Inputs chosen per failing group, ranked by the mean over the group's cases of
  // |dR/dsigma_i| * sigma_i at the start (seed: 3-4).
  std::size_t choose = 4;
  std::vector<std::size_t> chosen;  // explicit choice (overrides `choose`)
  std::size_t max_steps = 100;
  // Tighten, at each step, only the inputs chosen by groups that still fail (an input chosen by
  // several groups while one of them fails). Default: every chosen input at every step.
  bool per_group = false;
  // Cost-aware mode: cost = sum over non-constant inputs of w_i / sigma_i (default w_i = 1: the
  // weights carry the units), sigma_i in [sigma_lower_i, sigma_upper_i] (absolute; defaults 1 %
  // and 100 % of the starting stddev, the lower default also lowered to the step procedure's end
  // point so that this point is always admissible).
  std::vector<double> cost_weights;
  std::vector<double> sigma_lower, sigma_upper;
  std::size_t cost_max_evaluations = 1000;  // NLopt evaluations of the problem

  // The checks that need no problem: targets in (0, 1], target_tolerance in [0, 1e-3], finite
  // non-negative cost weights, max_steps and cost_max_evaluations >= 1. Throws
  // std::invalid_argument naming the field.
  void validate() const;
};

struct AllocationStep {
  std::size_t step = 0;                       // 0 is the start
  std::vector<double> stddev;                 // every input's stddev at this step
  std::vector<std::size_t> tightened;         // inputs lowered at this step (empty at step 0)
  std::vector<double> group_min, group_mean;  // per group
  std::vector<std::size_t> group_argmin;      // per group: the case (index into evaluate's result)
};

struct AllocationResult {
  std::vector<std::size_t> chosen;  // ascending
  // Per group: the inputs the group chose (empty for a group meeting its targets at the start,
  // or when AllocationOptions::chosen was given), and the ranking score of every input at the
  // start (mean over the group's cases of |dR/dsigma_i| * sigma_i).
  std::vector<std::vector<std::size_t>> group_chosen;
  std::vector<std::vector<double>> group_scores;
  std::vector<AllocationStep> steps;  // steps[0] is the start
  bool met = false;
  std::string note;
  // Cost-aware mode.
  bool cost_aware_met = false;
  std::vector<double> cost_aware_stddev;  // every input
  double cost_step = 0;                   // the cost at the step procedure's last step
  double cost_aware = 0;                  // the cost at cost_aware_stddev
  std::vector<double> cost_aware_group_min, cost_aware_group_mean;
  std::size_t cost_aware_evaluations = 0;  // calls of AllocationProblem::evaluate
};

// Wang & Yuan 2021's step procedure.
class StepAllocation {
 public:
  explicit StepAllocation(AllocationOptions options);  // validates the options
  const AllocationOptions& options() const { return options_; }
  // Throws std::invalid_argument for sizes inconsistent with the problem, an explicit choice out
  // of range or without a positive step, and for `evaluate` returning cases of a wrong group or
  // gradient size or leaving a group without cases.
  AllocationResult run(const AllocationProblem& problem) const;

 private:
  AllocationOptions options_;
};

// Minimises the cost subject to the targets, starting from the step procedure's result.
class CostAwareAllocation {
 public:
  explicit CostAwareAllocation(AllocationOptions options);  // validates the options
  const AllocationOptions& options() const { return options_; }
  // Returns `steps` with the cost-aware fields filled in; the note says how the optimiser ended.
  // cost_aware <= cost_step whenever the step procedure met the targets.
  AllocationResult run(const AllocationProblem& problem, const AllocationResult& steps) const;

 private:
  AllocationOptions options_;
};

}  // namespace weilgen
