// Emits the standalone C++ header of a model (generated/<machine>.hpp).
#pragma once

#include <string>

#include "weilgen/codegen/model_builder.hpp"

namespace weilgen::gen {

// `source_label` is how the banner names the machine file (a repository-relative path keeps the
// output independent of where the repository is checked out).
std::string emit_cpp_header(const SymbolicModel& model, const std::string& source_label);

}  // namespace weilgen::gen
