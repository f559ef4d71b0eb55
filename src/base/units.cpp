#include "weilgen/base/units.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <vector>

#include "weilgen/base/constants.hpp"
#include "weilgen/base/expr.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen {
namespace {

struct NamedUnit {
  const char* name;
  UnitFactor factor;
};

// "µ" as the micro sign (U+00B5) and as the Greek small mu (U+03BC), in UTF-8.
const char* const kMicroSign = "\xC2\xB5";
const char* const kGreekMu = "\xCE\xBC";

const std::vector<NamedUnit>& units() {
  static const std::vector<NamedUnit> u = {
      {"mm", {1, false}},         {"um", {1e-3, false}},
      {"nm", {1e-6, false}},      {"m", {1e3, false}},
      {"inch", {25.4, false}},    {"rad", {1, true}},
      {"mrad", {1e-3, true}},     {"urad", {1e-6, true}},
      {"deg", {kPi / 180, true}}, {"arcsec", {kPi / 648000, true}},
      {"mm/m", {1e-3, true}},     {"um/m", {1e-6, true}},
  };
  return u;
}

// µm, μm -> um; µrad -> urad; µm/m -> um/m.
std::string ascii_micro(const std::string& unit) {
  for (const char* mu : {kMicroSign, kGreekMu}) {
    const std::string m(mu);
    if (unit.compare(0, m.size(), m) == 0) return "u" + unit.substr(m.size());
  }
  return unit;
}

bool unit_char(char c) {
  const auto u = static_cast<unsigned char>(c);
  return std::isalpha(u) || c == '/' || u >= 0x80;
}

[[noreturn]] void fail(const std::string& what, const std::string& why) {
  throw std::invalid_argument(what.empty() ? why : what + ": " + why);
}

}  // namespace

std::string ascii_unit(const std::string& unit) { return ascii_micro(unit); }

std::string known_units() {
  return "lengths: mm, um, µm, nm, m, inch; angles: rad, mrad, urad, µrad, deg, arcsec; slopes: "
         "mm/m, "
         "um/m";
}

UnitFactor parse_unit(const std::string& unit) {
  const std::string ascii = ascii_micro(unit);
  for (const NamedUnit& u : units()) {
    if (ascii == u.name) return u.factor;
  }
  throw std::invalid_argument("unknown unit \"" + abbreviated(unit) + "\" (" + known_units() + ")");
}

Quantity parse_quantity_unit(const std::string& text, const std::string& default_unit,
                             const std::string& what) {
  const std::string t = trim(text);
  if (t.empty()) fail(what, "empty value (expected a number with an optional unit, e.g. 0.03mm)");
  std::string bare = lower(t);
  bare.erase(0, bare.find_first_not_of("+- \t"));
  if (bare.compare(0, 3, "nan") == 0)
    fail(what, "\"" + abbreviated(t) + "\" is not a number (NaN)");
  if (bare.compare(0, 3, "inf") == 0)
    fail(what, "\"" + abbreviated(t) + "\" is not a finite number");

  // The unit is the trailing run of letters, '/' and µ; an expression ending in a name
  // ("2*pi") has none.
  size_t cut = t.size();
  while (cut > 0 && unit_char(t[cut - 1])) --cut;
  std::string number_text = trim(t.substr(0, cut));
  std::string unit_text = t.substr(cut);
  Quantity q;
  if (!unit_text.empty()) {
    try {
      q.unit = parse_unit(unit_text);
      q.unit_name = unit_text;
      q.unit_given = true;
    } catch (const std::invalid_argument& ex) {
      // Not a unit: either the whole text is an expression ("2*pi") or the unit is wrong.
      bool expression = false;
      try {
        expression = parse_expr(t).params().empty();
      } catch (const std::invalid_argument&) {
      }
      if (!expression) fail(what, std::string(ex.what()) + " in \"" + abbreviated(t) + "\"");
      number_text = t;
      unit_text.clear();
    }
  }
  if (!q.unit_given) {
    if (default_unit.empty()) {
      fail(what, "\"" + abbreviated(t) + "\" needs a unit (" + known_units() + ")");
    }
    q.unit = parse_unit(default_unit);
    q.unit_name = default_unit;
  }
  if (number_text.empty()) fail(what, "\"" + abbreviated(t) + "\" has no number before the unit");
  Expr e;
  try {
    e = parse_expr(number_text);
  } catch (const std::invalid_argument& ex) {
    fail(what, "\"" + abbreviated(t) + "\" is not a number or expression: " + ex.what());
  }
  if (!e.params().empty()) {
    fail(what, "\"" + abbreviated(t) + "\" is not a number: unknown name \"" + e.params().front() +
                   "\" (expected a number or an expression such as 0.05/6, then a unit)");
  }
  q.number = e.eval({});
  if (!std::isfinite(q.number)) fail(what, "\"" + abbreviated(t) + "\" is not a finite number");
  return q;
}

double parse_quantity(const std::string& text, const std::string& default_unit,
                      const std::string& what) {
  return parse_quantity_unit(text, default_unit, what).value();
}

double parse_duration_s(const std::string& text, const std::string& default_unit,
                        const std::string& what) {
  const std::string t = trim(text);
  std::size_t cut = t.size();
  while (cut > 0 && std::isalpha(static_cast<unsigned char>(t[cut - 1]))) --cut;
  const std::string unit = t.substr(cut).empty() ? default_unit : t.substr(cut);
  double factor = 0;
  if (unit == "s")
    factor = 1;
  else if (unit == "min")
    factor = 60;
  else if (unit == "h")
    factor = 3600;
  else
    fail(what, "unit \"" + unit + "\" in \"" + abbreviated(t) + "\" is not a time (s, min, h)");
  // The number as a quantity without unit (an expression allowed).
  const std::string number = trim(t.substr(0, cut));
  if (number.empty()) fail(what, "\"" + abbreviated(t) + "\" has no number before the unit");
  Expr e;
  try {
    e = parse_expr(number);
  } catch (const std::invalid_argument& ex) {
    fail(what, "\"" + abbreviated(t) + "\" is not a number or expression: " + ex.what());
  }
  if (!e.params().empty())
    fail(what,
         "\"" + abbreviated(t) + "\" is not a number: unknown name \"" + e.params().front() + "\"");
  const double v = e.eval({}) * factor;
  if (!std::isfinite(v)) fail(what, "\"" + abbreviated(t) + "\" is not a finite number");
  return v;
}

double parse_feedrate_mm_min(const std::string& text, const std::string& what) {
  static const std::pair<const char*, double> units[] = {
      {"mm/min", 1}, {"mm/s", 60}, {"m/min", 1000}, {"in/min", 25.4}, {"mm/sec", 60}};
  const std::string t = trim(text);
  std::string number = t;
  double factor = 1;
  for (const auto& [unit, f] : units) {
    const std::string u = unit;
    if (t.size() > u.size() && lower(t.substr(t.size() - u.size())) == u) {
      number = trim(t.substr(0, t.size() - u.size()));
      factor = f;
      break;
    }
  }
  const Quantity q = parse_quantity_unit(number, "mm", what);
  if (q.unit_given)
    fail(what, "\"" + abbreviated(t) + "\": a feedrate's unit is mm/min, mm/s, m/min or in/min");
  const double v = q.number * factor;
  if (!(v > 0)) fail(what, "\"" + abbreviated(t) + "\": the feedrate must be > 0");
  return v;
}

namespace {

// Lower-case ASCII, µ/μ as u, blanks and '_' dropped: "Deg_C" -> "degc", "° F" -> "°f".
std::string unit_key(const std::string& unit) {
  std::string key;
  for (char c : ascii_unit(unit))
    if (c != ' ' && c != '\t' && c != '_')
      key += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return key;
}

}  // namespace

AffineUnit parse_temperature_unit(const std::string& unit) {
  static const std::string degree = "\xC2\xB0", ordinal = "\xC2\xBA";  // °, º (typed for °)
  const std::string u = unit_key(unit);
  if (u == "c" || u == "degc" || u == degree + "c" || u == ordinal + "c") return {1, 0};
  if (u == "f" || u == "degf" || u == degree + "f") return {5.0 / 9, -160.0 / 9};
  if (u == "k") return {1, -273.15};
  throw std::invalid_argument("unit '" + unit + "' (expected degC, degF or K)");
}

AffineUnit parse_pressure_unit(const std::string& unit) {
  const std::string u = unit_key(unit);
  if (u == "pa") return {1, 0};
  if (u == "hpa" || u == "mbar") return {100, 0};
  if (u == "kpa") return {1000, 0};
  if (u == "mmhg") return {133.322387415, 0};
  if (u == "inhg") return {3386.38864, 0};
  throw std::invalid_argument("unit '" + unit + "' (expected Pa, hPa, mbar, kPa, mmHg or inHg)");
}

}  // namespace weilgen
