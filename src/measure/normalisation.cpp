#include "weilgen/measure/normalisation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <stdexcept>

#include "weilgen/base/constants.hpp"
#include "weilgen/base/error.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"

namespace weilgen {

namespace {

struct Limits {
  double lo, hi;
  const char* unit;
};

Limits limits_of(EnvironmentQuantity q) {
  switch (q) {
    case EnvironmentQuantity::MaterialTemperature:
      return {-50, 100, "degC"};
    case EnvironmentQuantity::AirTemperature:
      return {kAirTemperatureMin_C, kAirTemperatureMax_C, "degC"};
    case EnvironmentQuantity::AirPressure:
      return {kAirPressureMin_Pa, kAirPressureMax_Pa, "Pa"};
    case EnvironmentQuantity::AirHumidity:
      break;
  }
  return {0, 100, "%"};
}

std::string range_text(const Limits& l) {
  return "[" + format_short(l.lo) + ", " + format_short(l.hi) + "] " + l.unit;
}

void check_value(double v, double lo, double hi, const std::string& unit,
                 const std::string& origin) {
  if (!(v >= lo && v <= hi))
    throw std::invalid_argument(origin + ": " + format_short(v) + " " + unit + " is outside [" +
                                format_short(lo) + ", " + format_short(hi) + "] " + unit);
}

// A whole-text number ("21.5", "-3e-1"); false for anything else.
bool read_number(const std::string& text, double& v) {
  if (text.empty() || text.find_first_not_of("0123456789+-.eE") != std::string::npos) return false;
  char* end = nullptr;
  v = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::isfinite(v);
}

// The leading number of "1013.25 hPa" and the rest (trimmed).
bool split_number_unit(const std::string& text, double& v, std::string& unit) {
  std::size_t k = 0;
  while (k < text.size() && std::string("0123456789+-.eE").find(text[k]) != std::string::npos) ++k;
  // "e" may start a unit name only after a complete number: back off a dangling exponent.
  while (k > 0 && (text[k - 1] == 'e' || text[k - 1] == 'E')) --k;
  if (!read_number(text.substr(0, k), v)) return false;
  unit = trim(text.substr(k));
  return true;
}

bool is_column_name(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

// The value of one source at a row: the constant, or the mean of its columns' finite cells
// (NaN when every cell is empty).
class SourceReader {
 public:
  SourceReader(const MeasurementTable& t, EnvironmentSource s) : table_(t), source_(std::move(s)) {
    for (const auto& c : source_.columns) {
      if (!t.has(c))
        throw InputError(SourceLoc{t.file, t.header_line, 0},
                         "column '" + c + "' (" + source_.origin +
                             ") is not in the file (columns: " + join(t.columns) + ")");
      cols_.push_back(&t.column(c));
    }
  }
  bool known() const { return source_.given(); }
  const std::vector<std::string>& columns() const { return source_.columns; }
  double at(std::size_t row) const {
    if (source_.value) return *source_.value;
    if (row >= table_.rows()) return kNaN;
    double sum = 0;
    int n = 0;
    for (const auto* c : cols_)
      if (std::isfinite((*c)[row])) sum += (*c)[row], ++n;
    return n ? sum / n : kNaN;
  }
  // The value at a row that needs it: InputError naming the line and the columns when it is
  // missing or outside its range.
  double needed(std::size_t row, const Limits& l, const std::string& what) const {
    const double v = at(row);
    const std::string cols =
        "column" + std::string(cols_.size() > 1 ? "s " : " ") + join(quoted_all(source_.columns));
    const int line = row < table_.rows() ? table_.lines[row] : 0;
    if (std::isnan(v))
      throw InputError(SourceLoc{table_.file, line, 0},
                       cols + ": empty, but the " + what + " is needed for this measured row");
    if (!(v >= l.lo && v <= l.hi))
      throw InputError(SourceLoc{table_.file, line, 0},
                       (source_.value ? source_.origin : cols) + ": " + what + " " +
                           format_short(v) + " " + l.unit + " is outside " + range_text(l));
    return v;
  }
  std::string describe() const {
    if (source_.value) return source_.origin;
    return (source_.columns.size() > 1 ? "mean of columns " : "column ") + join(source_.columns) +
           (source_.origin.empty() ? "" : " (" + source_.origin + ")");
  }

 private:
  static std::vector<std::string> quoted_all(const std::vector<std::string>& v) {
    std::vector<std::string> out;
    for (const auto& s : v) out.push_back("'" + s + "'");
    return out;
  }
  const MeasurementTable& table_;
  EnvironmentSource source_;
  std::vector<const std::vector<double>*> cols_;
};

// The source to use: the given one, else the default columns present in the table.
EnvironmentSource resolve(const EnvironmentSource& given, const MeasurementTable& t,
                          const std::function<bool(const std::string&)>& is_default) {
  if (given.given()) return given;
  EnvironmentSource s;
  for (const auto& c : t.columns)
    if (is_default(c)) s.columns.push_back(c);
  return s;
}

// "file:line" of a header key, or the file alone when the import wrote the key.
std::string key_place(const MeasurementTable& t, int line) {
  return line > 0 ? t.file + ":" + std::to_string(line) : t.file;
}

// Whether weilgen corrects the material's expansion, and why (docs/iso230-2.md, "Instrument
// compensation state").
void decide_material(const NormalisationOptions& o, const MeasurementTable& t,
                     NormalisationResult& r) {
  const std::string& state = o.material_compensation;
  const std::string place = key_place(t, o.material_compensation_line);
  if (!o.expansion_ppm_per_K) {
    r.material_decision =
        state == "instrument"
            ? place + " says material_compensation: instrument"
            : "no expansion coefficient (--expansion or the header key expansion_ppm_per_K)";
    return;
  }
  const double alpha = *o.expansion_ppm_per_K;
  const bool flag = r.expansion_origin.rfind("header", 0) != 0;
  const std::string alpha_text = format_number(alpha) + " um/(m K) (" + r.expansion_origin + ")";
  if (alpha == 0) {
    r.material_decision =
        "expansion coefficient 0 (" + r.expansion_origin + "): no expansion correction";
    return;
  }
  switch (o.mode) {
    case NormaliseMode::Never:
      if (flag)
        throw std::invalid_argument("--expansion " + format_number(alpha) +
                                    ": --normalise never applies no correction; drop one of them");
      r.material_decision = "not corrected (alpha " + alpha_text + ")";
      return;
    case NormaliseMode::Force:
      r.material_applied = true;
      r.material_decision =
          "corrected with alpha " + alpha_text +
          (state == "instrument"
               ? ", although " + place + " says the instrument already corrected the material"
               : std::string());
      return;
    case NormaliseMode::Auto:
      break;
  }
  if (state == "instrument") {
    if (flag)
      throw std::invalid_argument(
          "--expansion " + format_number(alpha) + ": " + place +
          " says the instrument already corrected the readings to 20 degC "
          "(material_compensation: instrument); a second correction doubles it (" +
          format_number(alpha) + " um/m per K); --normalise force applies it anyway");
    r.material_decision = place + " says material_compensation: instrument (alpha " + alpha_text +
                          "); not corrected again";
  } else if (state == "none") {
    r.material_applied = true;
    r.material_decision =
        place + " says material_compensation: none; corrected with alpha " + alpha_text;
  } else if (state == "unstated" && !flag) {
    r.material_decision =
        "the file gives alpha " + alpha_text +
        " but not whether the instrument applied it; a laser export's coefficient is the one its "
        "material compensation uses, so weilgen does not correct again (--normalise force "
        "corrects; a 'Material Compensation,Off' line says the instrument did not)";
  } else {
    r.material_applied = true;
    r.material_decision =
        "corrected with alpha " + alpha_text +
        (state == "unstated" ? "; the file does not say whether the instrument corrected it"
                             : std::string());
  }
}

// Whether weilgen corrects the air's refractive index, and why. `force` lifts the refusal of a
// correction the file says the instrument applied; it corrects nothing nobody asked for.
void decide_air(const NormalisationOptions& o, const MeasurementTable& t, bool values_known,
                NormalisationResult& r) {
  const bool flag = o.air != AirCompensation::Unstated && o.air_origin.rfind("header", 0) != 0;
  const std::string place = key_place(t, o.air_in_file_line);
  const std::string in_file = std::string("air_compensation: ") + to_string(o.air_in_file);
  const bool twice = o.air_in_file == AirCompensation::Instrument;
  auto apply = [&](const std::string& why) {
    r.air_applied = true;
    r.air = AirCompensation::Edlen;
    r.air_decision = why;
  };
  if (o.mode == NormaliseMode::Never) {
    if (flag && o.air == AirCompensation::Edlen)
      throw std::invalid_argument(
          "--air-compensation edlen: --normalise never applies no correction; drop one of them");
    r.air_decision = "--normalise never";
    return;
  }
  if (flag) {
    if (o.air == AirCompensation::Edlen) {
      if (twice && o.mode == NormaliseMode::Auto)
        throw std::invalid_argument(
            "--air-compensation edlen: " + place +
            " says the instrument already compensated the air (" + in_file +
            "); a second correction doubles it (about 271 um/m); --normalise force applies it "
            "anyway");
      apply("--air-compensation edlen" + (twice ? ", --normalise force: although " + place +
                                                      " says the instrument already compensated it"
                                                : std::string()));
      return;
    }
    r.air_decision = std::string("--air-compensation ") + to_string(o.air);
    return;
  }
  switch (o.air_in_file) {
    case AirCompensation::Instrument:
      r.air_decision = place + " says " + in_file;
      return;
    case AirCompensation::Edlen:
      apply("header key air_compensation: edlen (" + place + ")");
      return;
    case AirCompensation::None:
      if (values_known) {
        apply(place + " says " + in_file + "; corrected from the recorded air values");
        return;
      }
      r.air_decision = place + " says " + in_file +
                       " and the file records no air temperature, pressure and " + "humidity";
      return;
    case AirCompensation::Unstated:
      break;
  }
  r.air_decision = "the file does not say whether the instrument compensated the air";
}

// Sensors that disagree with their siblings by more than 5 K (a degF column taken as degC, a
// sensor off the machine), and temperatures far from a test's 20 degC: warnings naming the
// column's header cell.
void check_sensors(const MeasurementTable& t, const std::vector<IsoObservation>& obs,
                   const SourceReader& source, const std::string& what,
                   std::vector<std::string>& warnings) {
  const std::vector<std::string>& cols = source.columns();
  std::vector<double> means;
  for (const std::string& c : cols) {
    double sum = 0;
    int n = 0;
    for (const auto& x : obs)
      if (x.row < t.rows() && std::isfinite(t.column(c)[x.row])) sum += t.column(c)[x.row], ++n;
    means.push_back(n ? sum / n : kNaN);
  }
  auto cell = [&](std::size_t i) { return t.header_cell(cols[i]).str(); };
  if (cols.size() == 2 && std::abs(means[0] - means[1]) > 5) {
    warnings.push_back(cell(1) + ": " + what + " sensors '" + cols[0] + "' and '" + cols[1] +
                       "' differ by " + format_fixed(std::abs(means[0] - means[1]), 1) +
                       " K on average (" + format_fixed(means[0], 1) + " and " +
                       format_fixed(means[1], 1) +
                       " degC): check their units and placement; their mean is used");
    return;
  }
  std::vector<double> finite;
  for (double m : means)
    if (std::isfinite(m)) finite.push_back(m);
  std::sort(finite.begin(), finite.end());
  const std::size_t h = finite.size() / 2;
  const double median = finite.empty()      ? kNaN
                        : finite.size() % 2 ? finite[h]
                                            : 0.5 * (finite[h - 1] + finite[h]);
  for (std::size_t i = 0; cols.size() > 2 && i < cols.size(); ++i)
    if (std::abs(means[i] - median) > 5)
      warnings.push_back(cell(i) + ": " + what + " sensor '" + cols[i] + "' reads " +
                         format_fixed(means[i], 1) + " degC on average beside " +
                         format_fixed(median, 1) + " degC, the median of the " + what +
                         " sensors: check its unit (degF read as degC?); it pulls the mean used "
                         "for the correction");
  if (cols.empty()) return;
  double sum = 0;
  int n = 0;
  for (double m : means)
    if (std::isfinite(m)) sum += m, ++n;
  if (n && (sum / n < 10 || sum / n > 35))
    warnings.push_back(t.header_cell(cols[0]).str() + ": the " + what + " temperature reads " +
                       format_fixed(sum / n, 1) +
                       " degC on average, far from a test's 20 degC: check the unit");
}

}  // namespace

const char* to_string(AirCompensation mode) {
  switch (mode) {
    case AirCompensation::Instrument:
      return "instrument";
    case AirCompensation::Edlen:
      return "edlen";
    case AirCompensation::None:
      return "none";
    case AirCompensation::Unstated:
      break;
  }
  return "unstated";
}

const char* to_string(NormaliseMode mode) {
  switch (mode) {
    case NormaliseMode::Force:
      return "force";
    case NormaliseMode::Never:
      return "never";
    case NormaliseMode::Auto:
      break;
  }
  return "auto";
}

NormaliseMode parse_normalise_mode(const std::string& text) {
  const std::string t = lower(trim(text));
  if (t == "auto") return NormaliseMode::Auto;
  if (t == "force") return NormaliseMode::Force;
  if (t == "never") return NormaliseMode::Never;
  throw std::invalid_argument("--normalise " + text +
                              ": expected auto (never a correction the file says the instrument "
                              "applied), force (every correction the data allow) or never");
}

AirCompensation parse_air_compensation(const std::string& text, const std::string& what) {
  const std::string t = lower(trim(text));
  if (t == "instrument") return AirCompensation::Instrument;
  if (t == "edlen") return AirCompensation::Edlen;
  if (t == "none") return AirCompensation::None;
  throw std::invalid_argument(what + ": '" + text +
                              "' (expected instrument: the instrument compensated the readings; "
                              "edlen: weilgen does, from the air columns; none: nobody does)");
}

EnvironmentSource parse_environment_source(const std::string& text, EnvironmentQuantity q,
                                           const std::string& origin) {
  EnvironmentSource s;
  s.origin = origin;
  const std::string t = trim(text);
  if (t.empty()) throw std::invalid_argument(origin + ": empty value");
  double v = 0;
  std::string unit;
  if (split_number_unit(t, v, unit)) {
    const Limits l = limits_of(q);
    AffineUnit to_base;  // the unit to Pa or degC; no unit: already Pa, %, degC
    try {
      if (q == EnvironmentQuantity::AirPressure && !unit.empty())
        to_base = parse_pressure_unit(unit);
      else if (q == EnvironmentQuantity::AirHumidity && !(unit.empty() || unit == "%"))
        throw std::invalid_argument("unit '" + unit + "' (expected % or none)");
      else if (q != EnvironmentQuantity::AirPressure && q != EnvironmentQuantity::AirHumidity &&
               !unit.empty())
        to_base = parse_temperature_unit(unit);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(origin + ": " + e.what());
    }
    s.value = to_base.to_base(v);
    check_value(*s.value, l.lo, l.hi, l.unit, origin);
    return s;
  }
  for (const auto& item : split(t, ',')) {
    const std::string name = trim(item);
    if (!is_column_name(name))
      throw std::invalid_argument(origin + ": '" + text +
                                  "' is neither a number nor a list of column names");
    s.columns.push_back(name);
  }
  return s;
}

void NormalisationOptions::validate() const {
  if (expansion_ppm_per_K) check_value(*expansion_ppm_per_K, -10, 100, "ppm/K", "--expansion");
  if (wavelength_nm)
    check_value(*wavelength_nm, kWavelengthMin_nm, kWavelengthMax_nm, "nm", "--wavelength");
  if (assumed_index) check_value(*assumed_index, 1, 1.001, "", "--air-index-assumed");
  if (datum_mm && !std::isfinite(*datum_mm)) throw std::invalid_argument("--datum: not finite");
  if (!(reference_temperature_C > -50 && reference_temperature_C < 100))
    throw std::invalid_argument("reference temperature out of range");
  const std::pair<const EnvironmentSource*, EnvironmentQuantity> sources[] = {
      {&material_temperature, EnvironmentQuantity::MaterialTemperature},
      {&air_temperature, EnvironmentQuantity::AirTemperature},
      {&air_pressure, EnvironmentQuantity::AirPressure},
      {&air_humidity, EnvironmentQuantity::AirHumidity}};
  for (const auto& [s, q] : sources) {
    if (!s->value) continue;
    const Limits l = limits_of(q);
    check_value(*s->value, l.lo, l.hi, l.unit, s->origin);
  }
}

NormalisationOptions normalisation_with_header_keys(NormalisationOptions o,
                                                    const MeasurementTable& t) {
  auto key_of = [&](const char* key, const std::function<void(const std::string&)>& set) {
    const auto it = t.header_keys.find(key);
    if (it == t.header_keys.end()) return;
    const SourceLoc loc{t.file, t.header_key_lines.at(key), 0};
    try {
      set(it->second);
    } catch (const std::invalid_argument& e) {
      throw InputError(loc, e.what());
    }
  };
  auto number = [](const std::string& key, const std::string& v, double lo, double hi,
                   const char* unit) {
    double x = 0;
    if (!read_number(trim(v), x))
      throw std::invalid_argument("header key " + key + ": '" + v + "' is not a number");
    check_value(x, lo, hi, unit, "header key " + key);
    return x;
  };
  if (o.expansion_ppm_per_K && o.expansion_origin.empty()) o.expansion_origin = "--expansion";
  if (!o.expansion_ppm_per_K)
    key_of("expansion_ppm_per_K", [&](const std::string& v) {
      o.expansion_ppm_per_K = number("expansion_ppm_per_K", v, -10, 100, "ppm/K");
      o.expansion_origin = "header key expansion_ppm_per_K";
    });
  key_of("material_compensation", [&](const std::string& v) {
    const std::string state = lower(trim(v));
    if (state != "instrument" && state != "none" && state != "unstated")
      throw std::invalid_argument("header key material_compensation: '" + v +
                                  "' (expected instrument: the instrument corrected the "
                                  "readings to 20 degC; none: it did not; unstated)");
    o.material_compensation = state;
    o.material_compensation_line = t.header_key_lines.at("material_compensation");
  });
  if (o.air != AirCompensation::Unstated && o.air_origin.empty())
    o.air_origin = "--air-compensation";
  key_of("air_compensation", [&](const std::string& v) {
    o.air_in_file = parse_air_compensation(v, "header key air_compensation");
    o.air_in_file_line = t.header_key_lines.at("air_compensation");
  });
  if (o.air == AirCompensation::Unstated && o.air_in_file != AirCompensation::Unstated) {
    o.air = o.air_in_file;
    o.air_origin = "header key air_compensation";
  }
  if (!o.wavelength_nm)
    key_of("laser_wavelength_nm", [&](const std::string& v) {
      o.wavelength_nm =
          number("laser_wavelength_nm", v, kWavelengthMin_nm, kWavelengthMax_nm, "nm");
    });
  if (!o.assumed_index)
    key_of("air_index_assumed", [&](const std::string& v) {
      o.assumed_index = number("air_index_assumed", v, 1, 1.001, "");
    });
  if (!o.datum_mm)
    key_of("datum_mm",
           [&](const std::string& v) { o.datum_mm = number("datum_mm", v, -1e9, 1e9, "mm"); });
  const std::tuple<EnvironmentSource*, EnvironmentQuantity, const char*> sources[] = {
      {&o.material_temperature, EnvironmentQuantity::MaterialTemperature, "material_temperature_C"},
      {&o.air_temperature, EnvironmentQuantity::AirTemperature, "air_temperature_C"},
      {&o.air_pressure, EnvironmentQuantity::AirPressure, "air_pressure_Pa"},
      {&o.air_humidity, EnvironmentQuantity::AirHumidity, "air_humidity_pct"}};
  for (const auto& [s, q, key] : sources)
    if (!s->given())
      key_of(key, [&, s = s, q = q, key = key](const std::string& v) {
        *s = parse_environment_source(v, q, std::string("header key ") + key);
      });
  return o;
}

void ValueRange::add(double v) {
  if (std::isnan(v)) return;
  if (count == 0) {
    min = max = mean = v;
  } else {
    min = std::min(min, v);
    max = std::max(max, v);
    mean += (v - mean) / static_cast<double>(count + 1);
  }
  ++count;
}

NormalisationResult normalise_observations(const MeasurementTable& table,
                                           std::vector<IsoObservation>& obs,
                                           const NormalisationOptions& o, const std::string& unit) {
  NormalisationResult r;
  r.mode = o.mode;
  r.reference_temperature_C = o.reference_temperature_C;
  r.material_compensation = o.material_compensation;
  r.air = o.air;
  r.air_in_file = o.air_in_file;
  r.wavelength_nm = o.wavelength_nm.value_or(kHeNeWavelength_nm);
  r.assumed_index = o.assumed_index.value_or(1.0);
  r.expansion_ppm_per_K = o.expansion_ppm_per_K.value_or(kNaN);
  if (o.expansion_ppm_per_K)
    r.expansion_origin = o.expansion_origin.empty() ? "--expansion" : o.expansion_origin;
  r.correction_um.assign(obs.size(), 0.0);

  const SourceReader material(table,
                              resolve(o.material_temperature, table, [](const std::string& c) {
                                return c == "T_material" || c.rfind("T_material_", 0) == 0;
                              }));
  const SourceReader air_t(
      table, resolve(o.air_temperature, table, [](const std::string& c) { return c == "T_air"; }));
  const SourceReader air_p(
      table, resolve(o.air_pressure, table, [](const std::string& c) { return c == "p_air_Pa"; }));
  const SourceReader air_h(table, resolve(o.air_humidity, table,
                                          [](const std::string& c) { return c == "RH_air_pct"; }));
  decide_material(o, table, r);
  decide_air(o, table, air_t.known() && air_p.known() && air_h.known(), r);
  if (obs.empty()) return r;
  double lowest = obs[0].position_mm;
  for (const auto& x : obs) lowest = std::min(lowest, x.position_mm);
  r.datum_mm = o.datum_mm.value_or(lowest);
  if (r.material_applied && !material.known())
    throw InputError(SourceLoc{table.file, table.header_line, 0},
                     "an expansion coefficient is given but no material temperature: add a "
                     "column T_material (T_material_<k>), --material-temperature or the header "
                     "key material_temperature_C");
  if (r.air_applied) {
    const std::pair<const SourceReader*, const char*> need[] = {
        {&air_t, "temperature: a column T_air, --air-temperature or header key air_temperature_C"},
        {&air_p, "pressure: a column p_air_Pa, --air-pressure or header key air_pressure_Pa"},
        {&air_h, "humidity: a column RH_air_pct, --air-humidity or header key air_humidity_pct"}};
    for (const auto& [src, what] : need)
      if (!src->known())
        throw InputError(SourceLoc{table.file, table.header_line, 0},
                         std::string("air compensation 'edlen' needs the air ") + what);
  }
  if ((r.material_applied || r.air_applied) && unit != "um")
    throw std::invalid_argument(
        "normalisation to 20 degC and air compensation apply to a linear axis (deviations in "
        "um); this deviation column is in " +
        unit);
  if (material.known()) r.material_source = material.describe();
  if (air_t.known()) r.air_temperature_source = air_t.describe();
  if (air_p.known()) r.air_pressure_source = air_p.describe();
  if (air_h.known()) r.air_humidity_source = air_h.describe();
  check_sensors(table, obs, material, "material", r.warnings);
  check_sensors(table, obs, air_t, "air", r.warnings);

  const Limits lm = limits_of(EnvironmentQuantity::MaterialTemperature);
  const Limits lt = limits_of(EnvironmentQuantity::AirTemperature);
  const Limits lp = limits_of(EnvironmentQuantity::AirPressure);
  const Limits lh = limits_of(EnvironmentQuantity::AirHumidity);
  for (std::size_t k = 0; k < obs.size(); ++k) {
    IsoObservation& x = obs[k];
    const std::size_t row = x.row;
    const bool has_row = row < table.rows();
    // The displacement the laser read from its zero, mm.
    const double reading_mm = (x.position_mm - r.datum_mm) + x.deviation * 1e-3;
    double air_um = 0, material_um = 0;
    if (r.air_applied) {
      const AirConditions air{air_t.needed(row, lt, "air temperature"),
                              air_p.needed(row, lp, "air pressure"),
                              air_h.needed(row, lh, "air humidity")};
      const double n_minus_1 = air_refractivity(air, r.wavelength_nm);
      r.air_refractivity.add(n_minus_1);
      // n0/n − 1 = ((n0 − 1) − (n − 1)) / n, without forming 1 + 2.7e-4 first.
      air_um = reading_mm * ((r.assumed_index - 1) - n_minus_1) / (1 + n_minus_1) * 1e3;
    }
    if (r.material_applied) {
      const double tm = material.needed(row, lm, "material temperature");
      material_um = -*o.expansion_ppm_per_K * (tm - r.reference_temperature_C) *
                    (reading_mm + air_um * 1e-3) * 1e-3;
    }
    if (has_row && !r.air_applied && air_t.known() && air_p.known() && air_h.known()) {
      // The index of the recorded air, for the statements and the uncertainty budget.
      const AirConditions air{air_t.at(row), air_p.at(row), air_h.at(row)};
      if (air.temperature_C >= lt.lo && air.temperature_C <= lt.hi && air.pressure_Pa >= lp.lo &&
          air.pressure_Pa <= lp.hi && air.humidity_pct >= lh.lo && air.humidity_pct <= lh.hi)
        r.air_refractivity.add(air_refractivity(air, r.wavelength_nm));
    }
    if (has_row) {
      if (material.known()) r.material_temperature_C.add(material.at(row));
      if (air_t.known()) r.air_temperature_C.add(air_t.at(row));
      if (air_p.known()) r.air_pressure_Pa.add(air_p.at(row));
      if (air_h.known()) r.air_humidity_pct.add(air_h.at(row));
    }
    if (r.air_applied) r.air_correction_um.add(air_um);
    if (r.material_applied) r.material_correction_um.add(material_um);
    r.correction_um[k] = air_um + material_um;
    x.deviation += r.correction_um[k];
  }
  return r;
}

}  // namespace weilgen
