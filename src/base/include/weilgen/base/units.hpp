// Units and quantities of the study inputs (command-line flags and tolerance files,
// docs/study-inputs.md): "0.03mm", "30 um", "5 µrad", "0.05/6" (an expression, no unit).
// Base units are mm for lengths and rad for angles, as everywhere in the runtime.
#pragma once

#include <string>
#include <vector>

namespace weilgen {

// A unit's factor to base units (mm or rad) and whether it measures an angle.
struct UnitFactor {
  double to_base = 1.0;
  bool angle = false;
};

// Lengths: mm, um, µm, nm, m, inch (25.4 mm); angles: rad, mrad, urad, µrad, deg, arcsec; slopes
// (angles): mm/m, um/m, µm/m (= 1e-3 rad, 1e-6 rad). µ may be written as the micro sign (U+00B5) or
// the Greek mu (U+03BC). Throws std::invalid_argument naming the unit and the known ones.
UnitFactor parse_unit(const std::string& unit);

// The unit's name in ASCII as the table spells it: "µm" and "μm" -> "um", "µrad" -> "urad"
// (other text unchanged). Files and reports store this spelling.
std::string ascii_unit(const std::string& unit);

// Every unit parse_unit knows, for messages: "lengths: mm, ...; angles: ...; slopes: ...".
std::string known_units();

// A number as written with its unit: value in base units = number * unit.to_base.
struct Quantity {
  double number = 0;      // the number or expression as written, evaluated
  UnitFactor unit;        // the written unit, else the default
  std::string unit_name;  // as written, else the default unit's name
  bool unit_given = false;
  double value() const { return number * unit.to_base; }
  // The number in another unit; exact when `target` is the written unit.
  double in(const UnitFactor& target) const { return number * (unit.to_base / target.to_base); }
};

// "0.03mm", "30 um", "0.05/6 mm", "-2*pi rad", "0.05/6" (no unit: `default_unit`). The number may
// be an expression (+ - * / ^, parentheses, pi). An empty `default_unit` makes the unit required.
// Throws std::invalid_argument "<what>: <why>" (empty text, unknown unit, NaN, inf, not a number).
Quantity parse_quantity_unit(const std::string& text, const std::string& default_unit,
                             const std::string& what);

// The value of parse_quantity_unit in base units (mm or rad).
double parse_quantity(const std::string& text, const std::string& default_unit,
                      const std::string& what);

// A duration in seconds: "4h", "30 min", "90 s", "1.5h" (an expression allowed); units s, min, h,
// `default_unit` when none is written. Throws std::invalid_argument "<what>: <why>".
double parse_duration_s(const std::string& text, const std::string& default_unit,
                        const std::string& what);

// A feedrate in mm/min: "1000 mm/min", "16.7 mm/s", "1.2 m/min", "40 in/min", or a number
// (mm/min); > 0. Throws std::invalid_argument "<what>: <why>".
double parse_feedrate_mm_min(const std::string& text, const std::string& what);

// An affine conversion to a base unit: value in the base unit = number * factor + offset.
struct AffineUnit {
  double factor = 1;
  double offset = 0;
  double to_base(double number) const { return number * factor + offset; }
};

// A temperature unit to °C: degC (C, °C, ºC), degF (F, °F), K. Case, blanks and '_' do not
// matter; the empty unit is the caller's default. Throws std::invalid_argument
// "unit '<unit>' (expected degC, degF or K)".
AffineUnit parse_temperature_unit(const std::string& unit);

// A pressure unit to Pa: Pa, hPa, mbar, kPa, mmHg, inHg (case, blanks and '_' do not matter).
// Throws std::invalid_argument "unit '<unit>' (expected Pa, hPa, mbar, kPa, mmHg or inHg)".
AffineUnit parse_pressure_unit(const std::string& unit);

}  // namespace weilgen
