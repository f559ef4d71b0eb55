// Numeric evaluation of a symbolic model through GiNaC (for verification; generated code is the
// fast path).
#pragma once

#include <array>
#include <map>
#include <vector>

#include "weilgen/codegen/model_builder.hpp"

namespace weilgen::gen {

// axes in the joints' units, errors in base units (mm, rad), params in mm/deg (defaults when
// empty). Returns dx, dy, dz (mm), da, db, dc (rad).
std::array<double, 6> evaluate_model(const SymbolicModel& m, const std::vector<double>& axes,
                                     const std::vector<double>& errors,
                                     const std::vector<double>& params = {});

// Coefficients of a model (polynomials over coordinates, their cos/sin symbols, parameters and
// reciprocals _invK) as numbers at one pose, by a direct walk of the expression (far cheaper than
// GiNaC's subs + evalf; the report evaluates tens of thousands of coefficients). Memoised per
// coefficient.
class CoefficientEvaluator {
 public:
  // axes in the joints' units; params in mm/deg (defaults when empty).
  CoefficientEvaluator(const SymbolicModel& m, const std::vector<double>& axes,
                       const std::vector<double>& params = {});
  double operator()(const GiNaC::ex& c);

 private:
  double walk(const GiNaC::ex& e);
  std::map<GiNaC::ex, double, GiNaC::ex_is_less> symbols_, memo_;
  GiNaC::exmap exact_;  // the same values for what the walk does not know (functions)
};

}  // namespace weilgen::gen
