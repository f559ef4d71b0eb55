// Human-readable closed forms: the Markdown report (generated/<machine>.md) and `weilgen show`.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "weilgen/codegen/model_builder.hpp"

namespace weilgen::gen {

enum class Notation { Iso, Alias };  // error names as in ISO 230-1 or as the file's first alias
// Text: "dx = -E_XX - z·E_BX ..."; Latex; Sympy: the same terms in Python syntax (`*`, `**`),
// "dx = -E_XX - z*E_BX ...", whose right-hand side sympy.sympify reads.
enum class FormStyle { Text, Latex, Sympy };

// "dx = -E_XX - z·E_BX + y·E_CX + ..." grouped by error in declaration order, then higher terms;
// with max_degree > 0 only the terms up to that degree.
std::string closed_form(const SymbolicModel& m, int output, FormStyle style, Notation notation,
                        int max_degree = 0);
nlohmann::json closed_forms_json(const SymbolicModel& m, Notation notation);
// The report prints the closed forms in full up to this degree; higher terms (order 3 and up)
// are counted and the largest listed (`weilgen show` prints every term).
inline constexpr int kReportMaxDegree = 2;
std::string emit_report_markdown(const SymbolicModel& m, const std::string& source_label);

}  // namespace weilgen::gen
