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
std::string emit_cpp_header(const SymbolicModel& model, const std::string& source_label,
                            std::size_t max_nested_higher_terms = kMaxNestedHigherTerms);

}  // namespace weilgen::gen
