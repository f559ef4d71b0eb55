// Internals of the tolerance allocation shared by allocation.cpp, allocation_steps.cpp and
// allocation_cost.cpp (not a public header: nothing outside src/uq/ includes it).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "weilgen/uq/allocation.hpp"

namespace weilgen {

namespace allocation_detail {

struct GroupStats {
  std::vector<double> min, mean;
  std::vector<std::size_t> argmin;
  bool met = false;
  std::vector<bool> group_met;
};

// Checks the problem and options (see StepAllocation).
void validate(const AllocationProblem& problem, const AllocationOptions& options);
// evaluate() with its result checked.
std::vector<AllocationCase> evaluate_checked(const AllocationProblem& problem,
                                             const std::vector<InputDistribution>& inputs);
GroupStats group_stats(const AllocationProblem& problem, const std::vector<AllocationCase>& cases,
                       const AllocationOptions& options);
// The inputs with every stddev replaced (location-scale move, means kept).
std::vector<InputDistribution> with_stddevs(const std::vector<InputDistribution>& inputs,
                                            const std::vector<double>& stddev);
std::vector<double> stddevs(const std::vector<InputDistribution>& inputs);
std::string input_name(const AllocationProblem& problem, std::size_t i);

}  // namespace allocation_detail
}  // namespace weilgen
