// Emits the standalone C++ header of a model (generated/<machine>.hpp).
#pragma once

#include <cstddef>
#include <string>

#include "weilgen/codegen/model_builder.hpp"

namespace weilgen::gen {

// `source_label` is how the banner names the machine file (a repository-relative path keeps the
// output independent of where the repository is checked out).
// Above `max_nested_higher_terms` non-zero coefficients of degree >= 2, Deviation sums the
// higher terms by a loop over the header's table instead of writing them in nested form (a
// smaller header, a slower call; docs/generator.md).
inline constexpr std::size_t kMaxNestedHigherTerms = 20000;
// A MonomialCoefficients of more than `split_statements` statements (temporaries and
// coefficients after common-subexpression elimination) is written as functions of at most
// `part_statements` statements each, called in order: a compiler's time and memory grow faster
// than the length of one function (docs/performance.md, "Compiling the order-3 header").
struct SplitLimits {
  std::size_t split_statements = 4000;
  std::size_t part_statements = 1000;
};
std::string emit_cpp_header(const SymbolicModel& model, const std::string& source_label,
                            std::size_t max_nested_higher_terms = kMaxNestedHigherTerms,
                            const SplitLimits& split = {});

}  // namespace weilgen::gen
