// Allowed ranges of numeric settings and the strict reading of numbers typed as text: one home
// for "must be in [lo, hi]", so that every flag and every Options::validate() says it the same
// way, naming the flag or field and giving the allowed range.
#pragma once

#include <limits>
#include <string>

namespace weilgen {

// An interval of numbers, each end closed or open (an infinite end is open); `whole` admits
// whole numbers only.
struct NumberRange {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;
  bool whole = false;

  static NumberRange whole_numbers(double lo, double hi);  // whole numbers in [lo, hi]
  static NumberRange closed(double lo, double hi);         // [lo, hi]
  static NumberRange open(double lo, double hi);           // (lo, hi)
  static NumberRange left_open(double lo, double hi);      // (lo, hi]
  static NumberRange positive(double hi = std::numeric_limits<double>::infinity());  // (0, hi]

  bool contains(double v) const;
  // "a whole number from 0 to 100000", "a number in (0, 1)", "a number > 0".
  std::string text() const;
};

// Checks a value already read (NaN and infinities are never in a range). Throws
// std::invalid_argument "<what>: <value> is out of range (allowed: <range>)".
void check_number_in(double value, const NumberRange& range, const std::string& what);

// Reads `text` as one number of `range`: decimal digits, sign, point and exponent only (no
// blanks around it, no hex, NaN, infinity or trailing characters), a whole number when the range
// asks for one. Throws std::invalid_argument "<what>: '<text>' is not a number (allowed: ...)" or
// "<what>: '<text>' is out of range (allowed: ...)".
double parse_number_in(const std::string& text, const NumberRange& range, const std::string& what);

}  // namespace weilgen
