#include "weilgen/base/range.hpp"

#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen {

NumberRange NumberRange::whole_numbers(double lo, double hi) {
  NumberRange r = closed(lo, hi);
  r.whole = true;
  return r;
}

NumberRange NumberRange::closed(double lo, double hi) {
  NumberRange r;
  r.lo = lo;
  r.hi = hi;
  return r;
}

NumberRange NumberRange::open(double lo, double hi) {
  NumberRange r = closed(lo, hi);
  r.lo_open = r.hi_open = true;
  return r;
}

NumberRange NumberRange::left_open(double lo, double hi) {
  NumberRange r = closed(lo, hi);
  r.lo_open = true;
  return r;
}

NumberRange NumberRange::positive(double hi) { return left_open(0.0, hi); }

bool NumberRange::contains(double v) const {
  if (!std::isfinite(v)) return false;
  if (whole && v != std::floor(v)) return false;
  if (lo_open ? !(v > lo) : !(v >= lo)) return false;
  return hi_open ? v < hi : v <= hi;
}

std::string NumberRange::text() const {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  const std::string kind = whole ? "a whole number" : "a number";
  // Whole numbers print in full (100000, not 1e+05).
  const auto num = [&](double v) {
    if (whole && v >= 18446744073709551615.0) return std::string("2^64 - 1");  // a 64-bit seed
    return whole && std::fabs(v) < 1e15 ? std::to_string(static_cast<long long>(v))
                                        : format_number(v);
  };
  if (has_lo && has_hi) {
    if (whole) return kind + " from " + num(lo) + " to " + num(hi);
    return kind + " in " + (lo_open ? "(" : "[") + num(lo) + ", " + num(hi) + (hi_open ? ")" : "]");
  }
  if (has_lo) return kind + (lo_open ? " > " : " >= ") + num(lo);
  if (has_hi) return kind + (hi_open ? " < " : " <= ") + num(hi);
  return kind;
}

void check_number_in(double value, const NumberRange& range, const std::string& what) {
  if (range.contains(value)) return;
  throw std::invalid_argument(what + ": " + format_number(value) +
                              " is out of range (allowed: " + range.text() + ")");
}

double parse_number_in(const std::string& text, const NumberRange& range, const std::string& what) {
  const auto fail = [&](const std::string& why) {
    return std::invalid_argument(what + ": '" + abbreviated(text) + "' " + why +
                                 " (allowed: " + range.text() + ")");
  };
  if (text.empty() || text.find_first_not_of("0123456789+-.eE") != std::string::npos)
    throw fail("is not a number");
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) throw fail("is not a number");
  if (!std::isfinite(v)) throw fail("is out of range");  // overflow: 1e400
  if (range.whole && v != std::floor(v)) throw fail("is not a whole number");
  if (!range.contains(v)) throw fail("is out of range");
  return v;
}

}  // namespace weilgen
