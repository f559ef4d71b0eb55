// Numeric evaluation of a symbolic model through GiNaC (for verification; generated code is the
// fast path).
#pragma once

#include <array>
#include <vector>

#include "weilgen/codegen/model_builder.hpp"

namespace weilgen::gen {

// axes in the joints' units, errors in base units (mm, rad), params in mm/deg (defaults when
// empty). Returns dx, dy, dz (mm), da, db, dc (rad).
std::array<double, 6> evaluate_model(const SymbolicModel& m, const std::vector<double>& axes,
                                     const std::vector<double>& errors,
                                     const std::vector<double>& params = {});

}  // namespace weilgen::gen
