// Tolerance allocation of a study: Wang & Yuan 2021's step procedure (tighten the most
// reliability-sensitive errors step by step until the targets hold) and, optionally, the
// cost-aware optimum (min Σ w_i/σ_i under the same targets), over the reliability sweep of the
// study's poses and tolerances. docs/reliability.md.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "weilgen/analysis/reliability_sweep.hpp"
#include "weilgen/analysis/study.hpp"
#include "weilgen/uq/allocation.hpp"

namespace weilgen {

struct AllocationStudyOptions {
  ReliabilitySettings reliability;
  double min_target = 0.95, mean_target = 0.97;  // per output, over the poses
  // --step: "10%" (of each error's starting spread), "0.005/6mm" (every length error),
  // "0.005/6000rad" (every angular error), "E_C0X=0.005/3000rad" (one error); default 10 %.
  std::vector<std::string> steps;
  std::size_t choose = 4;       // errors chosen per output that misses its targets
  std::string rank = "scaled";  // scaled (|dR/dσ_i| σ_i) | raw (|dR/dσ_i|, Wang & Yuan 2021's)
  std::vector<std::string> errors;  // explicit choice (overrides choose)
  std::size_t max_steps = 100;
  bool per_output = false;  // tighten only the errors of outputs still missing a target
  bool cost_aware = false;
  std::vector<std::string> weights;  // NAME=w (default: the starting spread)
  double max_loosen = 4;             // cost-aware: no spread above this × its start

  // Targets in (0, 1), max_loosen >= 1, rank scaled or raw (std::invalid_argument naming the
  // flag).
  void validate() const;
};

struct AllocationStudyResult {
  std::vector<std::string> groups;  // the toleranced outputs
  AllocationOptions options;        // as resolved for the machine (steps, weights, bounds)
  AllocationResult result;
  std::vector<InputDistribution> final_inputs;  // the study's inputs at the last step's spreads
};

class AllocationStudy {
 public:
  explicit AllocationStudy(AllocationStudyOptions options);  // validates the options
  const AllocationStudyOptions& options() const { return options_; }
  AllocationStudyResult run(const Study& study) const;

 private:
  AllocationStudyOptions options_;
};

}  // namespace weilgen
