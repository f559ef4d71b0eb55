// Numbers as text, in one place. Every printed number goes through one of these.
#pragma once

#include <string>

namespace weilgen {

// The shortest of 15, 16 or 17 significant digits that reads back as the same double ("%g"
// style: 0.03, 1e-05, 1500): file values, labels, JSON-equivalent text.
std::string format_number(double v);
// "%g" with `digits` significant digits (6 by default): numbers inside messages and summaries.
std::string format_short(double v, int digits = 6);
// Fixed-point with `decimals` digits after the point; "-" for NaN and infinities: table cells.
// A value that rounds to zero has no sign ("0.000", never "-0.000").
std::string format_fixed(double v, int decimals);
// `digits` significant digits (std::setprecision); "-" for NaN and infinities: table cells.
std::string format_significant(double v, int digits);
// A C++ double literal: the shortest decimal (1 to 17 digits) that reads back as v, with ".0"
// appended when it would otherwise read as an integer (generated code).
std::string format_literal(double v);
// A C++ double literal with all 17 significant digits ("-400.0", "0.0028541741934906256"): the
// identified parameter header, whose readers compare it with a stated tolerance.
std::string format_literal17(double v);

}  // namespace weilgen
