// Mathematical constants and the special doubles, one definition for every layer.
#pragma once

#include <limits>

namespace weilgen {

inline constexpr double kPi = 3.14159265358979323846;
// The value of a quantity that has none (not measured, not defined at this pose).
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace weilgen
