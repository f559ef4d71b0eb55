// The names a machine file gives (the machine, coordinates, errors, parameters, points, derived
// quantities, bodies, groups) become C++ identifiers in the generated header: a namespace, local
// variables, constants. This says which names cannot be used there, so that the loader refuses
// them (exit 3, file:line:column) instead of emitting a header that does not compile.
#pragma once

#include <string>

namespace weilgen {

// "" when `name` (already [A-Za-z_][A-Za-z0-9_]*) is usable in generated code, else why not:
//   "is a C++ keyword"                          int, delete, and, co_await, ...
//   "is reserved for the C++ implementation"    a leading '_' and a capital, '__' anywhere
//   "starts with '_', which the generated code uses for its temporaries (_tmp0, _coef1)"
//   "is a macro of the standard headers the generated code includes"   errno, NULL, M_PI, ...
//   "is a name of the generated code"           Scalar, axes, errors, params, std, cos, ...,
//                                               Deviation, ... and k<Capital>... constants
std::string cxx_name_problem(const std::string& name);

}  // namespace weilgen
