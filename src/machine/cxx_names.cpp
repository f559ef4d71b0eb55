#include "weilgen/machine/cxx_names.hpp"

#include <algorithm>
#include <cctype>
#include <set>

namespace weilgen {

namespace {

// C++20 keywords and alternative tokens ([lex.key], [lex.digraph]).
const std::set<std::string>& keywords() {
  static const std::set<std::string> k = {"alignas",       "alignof",     "and",
                                          "and_eq",        "asm",         "auto",
                                          "bitand",        "bitor",       "bool",
                                          "break",         "case",        "catch",
                                          "char",          "char8_t",     "char16_t",
                                          "char32_t",      "class",       "compl",
                                          "concept",       "const",       "consteval",
                                          "constexpr",     "constinit",   "const_cast",
                                          "continue",      "co_await",    "co_return",
                                          "co_yield",      "decltype",    "default",
                                          "delete",        "do",          "double",
                                          "dynamic_cast",  "else",        "enum",
                                          "explicit",      "export",      "extern",
                                          "false",         "float",       "for",
                                          "friend",        "goto",        "if",
                                          "inline",        "int",         "long",
                                          "mutable",       "namespace",   "new",
                                          "noexcept",      "not",         "not_eq",
                                          "nullptr",       "operator",    "or",
                                          "or_eq",         "private",     "protected",
                                          "public",        "register",    "reinterpret_cast",
                                          "requires",      "return",      "short",
                                          "signed",        "sizeof",      "static",
                                          "static_assert", "static_cast", "struct",
                                          "switch",        "template",    "this",
                                          "thread_local",  "throw",       "true",
                                          "try",           "typedef",     "typeid",
                                          "typename",      "union",       "unsigned",
                                          "using",         "virtual",     "void",
                                          "volatile",      "wchar_t",     "while",
                                          "xor",           "xor_eq",      "final",
                                          "override",      "import",      "module"};
  return k;
}

// Object-like macros of <array>, <cmath>, <cstddef> (glibc, GNU mode) and the compilers'
// predefined ones: a local variable of that name would be rewritten by the preprocessor.
const std::set<std::string>& macros() {
  static const std::set<std::string> m = [] {
    std::set<std::string> s = {"errno",
                               "NULL",
                               "EDOM",
                               "ERANGE",
                               "EILSEQ",
                               "INFINITY",
                               "NAN",
                               "HUGE_VAL",
                               "HUGE_VALF",
                               "HUGE_VALL",
                               "FP_NAN",
                               "FP_INFINITE",
                               "FP_ZERO",
                               "FP_SUBNORMAL",
                               "FP_NORMAL",
                               "FP_ILOGB0",
                               "FP_ILOGBNAN",
                               "FP_FAST_FMA",
                               "FP_FAST_FMAF",
                               "FP_FAST_FMAL",
                               "MATH_ERRNO",
                               "MATH_ERREXCEPT",
                               "math_errhandling",
                               "linux",
                               "unix",
                               "i386",
                               "offsetof"};
    for (const char* c : {"M_E", "M_LOG2E", "M_LOG10E", "M_LN2", "M_LN10", "M_PI", "M_PI_2",
                          "M_PI_4", "M_1_PI", "M_2_PI", "M_2_SQRTPI", "M_SQRT2", "M_SQRT1_2"})
      for (const char* suffix : {"", "l", "f"}) s.insert(std::string(c) + suffix);
    return s;
  }();
  return m;
}

// The generated code's own names: function parameters and locals of every generated function,
// functions, types, namespaces, the std functions it calls unqualified.
const std::set<std::string>& generated_names() {
  static const std::set<std::string> g = {"Scalar",
                                          "T",
                                          "N",
                                          "axes",
                                          "errors",
                                          "params",
                                          "position",
                                          "orientation",
                                          "position_coeff",
                                          "orientation_coeff",
                                          "jacobian",
                                          "command",
                                          "errors_at",
                                          "std",
                                          "cos",
                                          "sin",
                                          "tan",
                                          "sqrt",
                                          "pow",
                                          "exp",
                                          "log",
                                          "weilgen_models",
                                          "compensation_detail",
                                          "Deviation",
                                          "Coefficients",
                                          "HigherOrder",
                                          "MonomialCoefficients",
                                          "coefficients",
                                          "terms",
                                          "NominalPose",
                                          "NominalJacobian",
                                          "Compensate",
                                          "Errors",
                                          "ErrorsAt",
                                          "AxisInfo",
                                          "ErrorInfo",
                                          "ParamInfo",
                                          "DistributionKind",
                                          "PolySum",
                                          "LegendreSum",
                                          "ChebyshevSum",
                                          "FourierSum",
                                          "EnableIf",
                                          "IfCallable",
                                          "IsArray",
                                          "Bare",
                                          "Condition"};
  return g;
}

bool upper(char c) { return std::isupper(static_cast<unsigned char>(c)) != 0; }

}  // namespace

std::string cxx_name_problem(const std::string& name) {
  if (keywords().count(name)) return "is a C++ keyword";
  if ((name.size() > 1 && name[0] == '_' && upper(name[1])) || name.find("__") != std::string::npos)
    return "is reserved for the C++ implementation (a leading '_' and a capital letter, or '__')";
  if (!name.empty() && name[0] == '_')
    return "starts with '_', which the generated code uses for its own names (_tmp0, _coef1)";
  if (macros().count(name)) return "is a macro of the standard headers the generated code includes";
  if (generated_names().count(name) || (name.size() > 1 && name[0] == 'k' && upper(name[1])))
    return "is a name of the generated code (Scalar, axes, errors, params, std, cos, sin, sqrt, "
           "Deviation, kNumAxes, ...)";
  return "";
}

}  // namespace weilgen
