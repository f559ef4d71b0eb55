// The C API of a model (`weilgen generate --c-api`): <name>_c.h, a C99 header (extern "C" under
// C++) with the counts and named indices as enums, and <name>_c.cpp, its implementation over the
// C++ header <name>.hpp. Both come from the real files templates/c_api.h and templates/c_api.cpp
// (compiled and run on their own by CTest c_api_template). docs/controllers.md.
#pragma once

#include <string>
#include <vector>

#include "weilgen/codegen/model_builder.hpp"

namespace weilgen::gen {

// The model's names in C: the prefix of functions and types (the model name, vmc_3axis), of
// macros and enumerators (VMC_3AXIS), and each axis, error and parameter as an enumerator suffix
// (upper case: X, E_C0Y, TOOL_LENGTH), in kAxes, kErrors, kParams order.
struct CNames {
  std::string lower, upper;
  std::vector<std::string> axes, errors, params;
};

// Throws InputError naming the machine file, the line and both names when two names of one kind
// become the same enumerator in upper case (axes X and x), and when the model name is reserved
// in C and C++ (a leading underscore, or a double one).
CNames c_names(const SymbolicModel& model);

// `source_label` is how the banner names the machine file (generate.hpp, source_label()).
std::string emit_c_api_header(const SymbolicModel& model, const std::string& source_label);
std::string emit_c_api_source(const SymbolicModel& model, const std::string& source_label);

// The C++ header's named indices (namespaces axis, error, param of the model's namespace):
// axes[axis::X], errors[error::E_C0Y], params[param::tool_length].
std::string emit_index_constants(const SymbolicModel& model);

// A template's text with the stand-in names replaced: the identifier `standin` (alone or as the
// prefix of an identifier, standin_deviation) by `lower`, `STANDIN` by `upper`; then the block
// from the line holding "---- weilgen template: <block> begin ----" to the line holding "... end
// ----" by `block_text` for each (block, text) pair, in order. Throws std::logic_error for a
// missing block or a stand-in name inside an identifier. The one place templates are filled
// (the C API, the HAL component and the model header, templates/).
std::string instantiate_template(const std::string& text, const std::string& lower,
                                 const std::string& upper,
                                 const std::vector<std::pair<std::string, std::string>>& blocks);

// The lines strictly between a block's begin and end lines: a template's section that an
// emitter places itself (the model header's functions, whose order depends on the model).
std::string template_block(const std::string& text, const std::string& block);

}  // namespace weilgen::gen
