// Wide laser exports to the tidy layout. The CARTO grammar, the generic wide form and the
// mapping are documented in docs/data-format.md, "Instrument files"; what in them was assumed
// rather than taken from a published export is said there.
#include "weilgen/measure/instrument_import.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>
#include <stdexcept>
#include <tuple>

#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/base/error.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/measure/iso230_2.hpp"

namespace weilgen {

namespace {

const char* const kDegree = "\xC2\xB0";   // °
const char* const kOrdinal = "\xC2\xBA";  // º, often typed for °

struct Line {
  int no = 0;
  std::string text;
};

std::vector<Line> split_lines(const std::string& text) {
  std::vector<Line> out;
  std::size_t pos = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
  int no = 0;
  while (pos < text.size()) {
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string::npos) nl = text.size();
    std::string line = text.substr(pos, nl - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    out.push_back({++no, line});
    pos = nl + 1;
  }
  return out;
}

bool blank_or_comment(const std::string& s) {
  const std::string t = trim(s);
  return t.empty() || t[0] == '#';
}

struct Cell {
  std::string text;  // trimmed, unquoted
  int column = 0;    // 1-based character position
};

// One CSV line: fields separated by `delim`; a field may be double-quoted ("" is a quote inside).
std::vector<Cell> split_csv(const std::string& line, char delim, const std::string& file,
                            int line_no) {
  std::vector<Cell> out;
  std::size_t i = 0;
  while (true) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t') && line[i] != delim) ++i;
    Cell c;
    c.column = static_cast<int>(i + 1);
    if (i < line.size() && line[i] == '"') {
      std::size_t k = i + 1;
      bool closed = false;
      while (k < line.size()) {
        if (line[k] == '"') {
          if (k + 1 < line.size() && line[k + 1] == '"') {
            c.text += '"';
            k += 2;
            continue;
          }
          closed = true;
          ++k;
          break;
        }
        c.text += line[k++];
      }
      if (!closed) throw InputError(SourceLoc{file, line_no, c.column}, "unterminated quote");
      while (k < line.size() && line[k] != delim) {
        if (line[k] != ' ' && line[k] != '\t')
          throw InputError(SourceLoc{file, line_no, static_cast<int>(k + 1)},
                           "text after a closing quote");
        ++k;
      }
      c.text = trim(c.text);
      out.push_back(c);
      if (k >= line.size()) break;
      i = k + 1;
    } else {
      const std::size_t end = line.find(delim, i);
      c.text = trim(line.substr(i, end == std::string::npos ? std::string::npos : end - i));
      out.push_back(c);
      if (end == std::string::npos) break;
      i = end + 1;
    }
  }
  return out;
}

// Lower case, blanks collapsed, trimmed; "µ"/"μ" as "u"; "°" and "º" kept.
std::string normalise(const std::string& s) {
  std::string out;
  bool space = false;
  for (char c : ascii_unit(s)) {
    if (c == ' ' || c == '\t' || c == '_') {
      space = !out.empty();
      continue;
    }
    if (space) out += ' ';
    space = false;
    out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return out;
}

// "Air Pressure (mbar)" -> {"air pressure", "mbar"}; "[unit]" works as well.
std::pair<std::string, std::string> name_and_unit(const std::string& header) {
  const std::string h = trim(header);
  for (const auto& [open, close] : {std::pair<char, char>{'(', ')'}, {'[', ']'}}) {
    if (!h.empty() && h.back() == close) {
      const std::size_t k = h.rfind(open);
      if (k != std::string::npos)
        return {normalise(h.substr(0, k)), trim(h.substr(k + 1, h.size() - k - 2))};
    }
  }
  return {normalise(h), ""};
}

bool is_target_name(const std::string& n) {
  return n == "target position" || n == "target" || n == "target pos" || n == "target pos." ||
         n == "nominal position" || n == "nominal";
}

// A column numbering the targets ("Target No.", "Point"): it carries no measurement.
bool is_index_name(const std::string& n) {
  return n == "target no." || n == "target no" || n == "target number" || n == "target #" ||
         n == "no." || n == "no" || n == "#" || n == "index" || n == "point" || n == "point no." ||
         n == "point no" || n == "point number" || n == "position no." || n == "position no" ||
         n == "position number" || n == "step";
}

// Strict number; `decimal_comma` accepts "1,5" for 1.5 (semicolon- or tab-separated exports).
bool parse_number(std::string text, bool decimal_comma, double& v) {
  if (decimal_comma && text.find('.') == std::string::npos) {
    const std::size_t k = text.find(',');
    if (k != std::string::npos && text.find(',', k + 1) == std::string::npos) text[k] = '.';
  }
  if (text.empty() || text.find_first_not_of("0123456789+-.eE") != std::string::npos) return false;
  char* end = nullptr;
  v = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::isfinite(v);
}

// ---- The wide table, whatever its source -------------------------------------------------------

struct WideColumn {
  std::string tidy;            // the tidy column it feeds
  long cycle = 0;              // 0: every run of the row; else the run (cycle) id
  std::vector<double> values;  // one per wide row, tidy units
  int header_column = 0;       // 1-based character column of its source header cell
};

struct Wide {
  MeasurementTable meta;  // file, header keys and their lines, header line
  std::vector<int> lines;
  std::vector<WideColumn> columns;
  ReadOptions read;
};

ColumnRole role_of(const std::string& name, const ReadOptions& read) {
  return classify_column(name, read).role;
}

// One tidy row per (wide row, cycle) with a measured deviation.
MeasurementTable tidy_from_wide(const Wide& w) {
  MeasurementTable t;
  t.file = w.meta.file;
  t.header_keys = w.meta.header_keys;
  t.header_key_lines = w.meta.header_key_lines;
  // The tidy table is no longer wide: a '# format: wide' key carried into it would make the
  // readers take the tidy file for a wide one.
  t.header_keys.erase("format");
  t.header_key_lines.erase("format");
  t.header_line = w.meta.header_line;
  t.warnings = w.meta.warnings;
  std::vector<std::string> names;
  std::set<long> cycles;
  auto add_name = [&](const std::string& n) {
    if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
  };
  for (const auto& c : w.columns)
    if (c.cycle == 0) add_name(c.tidy);
  add_name("cycle");
  for (const auto& c : w.columns)
    if (c.cycle != 0) add_name(c.tidy), cycles.insert(c.cycle);
  for (const auto& n : names) {
    t.columns.push_back(n);
    t.info.push_back(classify_column(n, w.read));
    t.values[n];
    for (const auto& c : w.columns)
      if (c.tidy == n && c.header_column > 0 && !t.header_columns.count(n))
        t.header_columns[n] = c.header_column;
  }
  for (std::size_t r = 0; r < w.lines.size(); ++r) {
    for (long j : cycles) {
      bool measured = false;
      for (const auto& c : w.columns)
        if (c.cycle == j && role_of(c.tidy, w.read) == ColumnRole::Deviation &&
            std::isfinite(c.values[r]))
          measured = true;
      if (!measured) continue;
      for (const auto& n : names) {
        double v = kNaN;
        if (n == "cycle") {
          v = static_cast<double>(j);
        } else {
          for (const auto& c : w.columns)  // the run's own value, else the row's
            if (c.tidy == n && c.cycle == j && std::isfinite(c.values[r])) v = c.values[r];
          if (std::isnan(v))
            for (const auto& c : w.columns)
              if (c.tidy == n && c.cycle == 0) v = c.values[r];
        }
        t.values[n].push_back(v);
      }
      t.lines.push_back(w.lines[r]);
    }
  }
  if (t.lines.empty())
    throw InputError(SourceLoc{t.file, t.header_line, 0}, "no measured run in any data row");
  return t;
}

// ---- CARTO ------------------------------------------------------------------------------------

enum class Quantity {
  Target,
  TargetNumber,  // a running number of the target ("Target No."): checked, not carried
  Direction,
  Deviation,
  AirT,
  AirP,
  AirH,
  MaterialT,
  Time,
  Unknown
};

struct Conversion {
  double factor = 1, offset = 0;
  std::string unit;  // the tidy unit
};

// A cell in the tidy unit. A power-of-ten factor shifts the decimal point in the text
// ("1013.2" mbar -> "1013.2e2" Pa reads as exactly 101320), so converted values print as short as
// they were written; other factors multiply.
bool converted_number(const std::string& text, bool decimal_comma, const Conversion& c, double& v) {
  const double k = std::log10(c.factor);
  if (c.offset == 0 && std::abs(k - std::round(k)) < 1e-12 &&
      text.find_first_of("eE") == std::string::npos) {
    double check = 0;
    if (!parse_number(text, decimal_comma, check)) return false;
    std::string t = text;
    if (decimal_comma) std::replace(t.begin(), t.end(), ',', '.');
    return parse_number(t + "e" + std::to_string(static_cast<int>(std::round(k))), false, v);
  }
  if (!parse_number(text, decimal_comma, v)) return false;
  v = v * c.factor + c.offset;
  return true;
}

// A base-units conversion (base/units) with the file's place in its message.
template <typename Parse>
Conversion affine_unit(Parse parse, const std::string& unit, const std::string& where,
                       const char* tidy_unit) {
  try {
    const AffineUnit a = parse(unit);
    return {a.factor, a.offset, tidy_unit};
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(where + e.what());
  }
}

Conversion temperature_unit(const std::string& unit, const std::string& where) {
  if (normalise(unit).empty()) return {1, 0, "degC"};
  return affine_unit(parse_temperature_unit, unit, where, "degC");
}

Conversion pressure_unit(const std::string& unit, const std::string& where) {
  return affine_unit(parse_pressure_unit, unit, where, "Pa");
}

Conversion time_unit(const std::string& unit, const std::string& where) {
  const std::string u = normalise(unit);
  if (u == "s" || u == "sec") return {1, 0, "s"};
  if (u == "ms") return {1e-3, 0, "s"};
  if (u == "min") return {60, 0, "s"};
  if (u == "h") return {3600, 0, "s"};
  throw std::invalid_argument(where + "unit '" + unit + "' (expected s, ms, min or h)");
}

// A run's deviation in µm (linear axis) or µrad (rotary axis).
Conversion deviation_unit(const std::string& unit, bool rotary, const std::string& where) {
  std::string u = normalise(unit);
  if (u == "micron" || u == "microns") u = "um";
  if (u == "\"" || u == "sec" || u == "arc sec" || u == "arc-sec") u = "arcsec";
  if (u == kDegree || u == kOrdinal) u = "deg";
  if (u.empty())
    throw std::invalid_argument(where + "no unit (" +
                                (rotary ? "arcsec, urad, deg" : "um, mm, nm") + ")");
  UnitFactor f;
  try {
    f = parse_unit(u);
  } catch (const std::invalid_argument&) {
    throw std::invalid_argument(where + "unit '" + unit + "' (" + known_units() + ")");
  }
  if (f.angle != rotary)
    throw std::invalid_argument(where + "unit '" + unit + "' is " +
                                (f.angle ? "an angle" : "a length") + " but the axis is " +
                                (rotary ? "rotary (deviations in urad)" : "linear (in um)"));
  return {f.to_base * (rotary ? 1e6 : 1e3), 0, rotary ? "urad" : "um"};
}

Conversion target_unit(const std::string& unit, bool rotary, const std::string& where) {
  std::string u = normalise(unit);
  if (u == kDegree || u == kOrdinal) u = "deg";
  if (u.empty()) u = rotary ? "deg" : "mm";
  if (rotary ? u != "deg" : u != "mm")
    throw std::invalid_argument(
        where + "unit '" + unit + "': the axis is " +
        (rotary ? "rotary, its targets in deg" : "linear, its targets in mm"));
  return {1, 0, u};
}

struct CartoColumn {
  Quantity q = Quantity::Unknown;
  long run = 0;    // 0: the row's value for every run
  int sensor = 0;  // material temperature sensor k (0: the only one)
  std::string header, unit;
  int column = 0;
};

// The grammar of one header cell: "[Run <n> ]<quantity>[ <k>][ (<unit>)]".
CartoColumn classify_carto(const Cell& cell) {
  CartoColumn c;
  c.header = cell.text;
  c.column = cell.column;
  auto [name, unit] = name_and_unit(cell.text);
  c.unit = unit;
  if (name.rfind("run ", 0) == 0) {
    std::size_t k = 4;
    while (k < name.size() && std::isdigit(static_cast<unsigned char>(name[k]))) ++k;
    if (k == 4) return c;
    c.run = std::strtol(name.substr(4, k - 4).c_str(), nullptr, 10);
    if (c.run < 1 || k - 4 > 6) return c;
    name = trim(name.substr(k));
    if (name.empty()) {
      c.q = Quantity::Deviation;
      return c;
    }
  }
  if (c.run == 0 && is_target_name(name)) c.q = Quantity::Target;
  if (c.run == 0 && unit.empty() && is_index_name(name)) c.q = Quantity::TargetNumber;
  if (c.run == 0 && (name == "direction" || name == "dir")) c.q = Quantity::Direction;
  if (name == "air temperature" || name == "air temp") c.q = Quantity::AirT;
  if (name == "air pressure" || name == "pressure" || name == "barometric pressure")
    c.q = Quantity::AirP;
  if (name == "humidity" || name == "relative humidity" || name == "air humidity" || name == "rh")
    c.q = Quantity::AirH;
  if (name == "time" || name == "elapsed time") c.q = Quantity::Time;
  for (const char* base : {"material temperature", "material temp"}) {
    const std::string b = base;
    if (name == b) c.q = Quantity::MaterialT;
    if (name.rfind(b + " ", 0) == 0) {
      const std::string k = name.substr(b.size() + 1);
      if (!k.empty() && k.size() < 4 &&
          std::all_of(k.begin(), k.end(), [](char ch) { return std::isdigit(ch) != 0; })) {
        c.q = Quantity::MaterialT;
        c.sensor = std::atoi(k.c_str());
      }
    }
  }
  return c;
}

const char* kCartoColumns =
    "Target Position (mm|deg), Direction, Run <n> (um|mm|nm|arcsec|urad|deg), and per row or "
    "per run ('Run <n> ' before the name): Air Temperature (degC), Air Pressure "
    "(Pa|hPa|mbar|kPa|mmHg), Humidity (%), Material Temperature [<k>] (degC), Time (s|min|h)";

int direction_of(const std::string& text) {
  const std::string t = normalise(text);
  static const std::set<std::string> up = {"forward", "fwd", "f",        "+",   "+1",
                                           "1",       "up",  "positive", "pos", "increasing"};
  static const std::set<std::string> down = {"reverse",  "rev", "backward",  "back", "bwd",
                                             "b",        "r",   "-",         "-1",   "down",
                                             "negative", "neg", "decreasing"};
  if (up.count(t)) return 1;
  if (down.count(t)) return -1;
  return 0;
}

// `Key,Value` metadata: the tidy header key and the value converted to its unit. A key weilgen
// does not know is kept as its slug, or dropped ({"", ""}) when `only_known` (the "Key: Value"
// lines of a LaserXL-style header, which a title line may resemble).
std::pair<std::string, std::string> carto_key(const std::string& key, const std::string& value,
                                              const std::string& where, bool only_known = false) {
  std::string name, unit;
  std::tie(name, unit) = name_and_unit(key);
  auto one_of = [&](std::initializer_list<const char*> names) {
    for (const char* n : names)
      if (name == n) return true;
    return false;
  };
  // The value's number; a unit written after it ("1013.2 mbar") counts when the key has none.
  std::string num = trim(value);
  const std::size_t blank = num.find_first_of(" \t");
  if (blank != std::string::npos) {
    if (unit.empty()) unit = trim(num.substr(blank));
    num = num.substr(0, blank);
  }
  auto number = [&](const Conversion& c) {
    double v = 0;
    if (!converted_number(num, true, c, v))
      throw std::invalid_argument(where + "'" + value + "' is not a number");
    return format_number(v);
  };
  if (one_of({"machine", "machine name", "machine model"})) return {"machine", value};
  if (one_of({"serial", "serial number", "serial no", "serial no.", "machine serial",
              "machine serial number", "s/n"}))
    return {"serial", value};
  if (one_of({"axis", "axis name"})) return {"axis", value};
  if (one_of({"date", "test date", "date/time", "date & time", "measurement date"}))
    return {"date", value};
  if (one_of({"operator", "user", "tested by", "engineer"})) return {"operator", value};
  if (one_of({"location", "site"})) return {"location", value};
  if (one_of({"customer"})) return {"customer", value};
  if (one_of({"instrument", "laser", "laser system", "laser serial", "laser serial number"}))
    return {"instrument", value};
  if (one_of({"test name", "title", "description"})) return {"title", value};
  if (one_of({"material expansion coefficient", "expansion coefficient", "material expansion",
              "coefficient of expansion", "material coefficient"})) {
    const std::string u = normalise(unit);
    Conversion c;
    if (u == "1/k" || u == "1/degc" || u == std::string("1/") + kDegree + "c") c.factor = 1e6;
    return {"expansion_ppm_per_K", number(c)};
  }
  if (one_of({"material temperature", "material temp"}))
    return {"material_temperature_C", number(temperature_unit(unit, where))};
  if (one_of({"air temperature", "air temp"}))
    return {"air_temperature_C", number(temperature_unit(unit, where))};
  if (one_of({"air pressure", "pressure", "barometric pressure"}))
    return {"air_pressure_Pa", number(pressure_unit(unit.empty() ? "mbar" : unit, where))};
  if (one_of({"humidity", "relative humidity", "air humidity"}))
    return {"air_humidity_pct", number(Conversion{})};
  // Whether the instrument's software corrected the readings to 20 degC with its coefficient.
  if (one_of({"material compensation", "material comp", "material comp.",
              "material temperature compensation", "expansion compensation",
              "thermal expansion compensation", "material expansion compensation"})) {
    const std::string v = normalise(value);
    if (v == "on" || v == "applied" || v == "automatic" || v == "auto" || v == "yes" ||
        v == "enabled" || v == "manual" || v == "instrument")
      return {"material_compensation", "instrument"};
    if (v == "off" || v == "none" || v == "no" || v == "disabled" || v == "not applied")
      return {"material_compensation", "none"};
    throw std::invalid_argument(where + "'" + value +
                                "' (expected on/applied/automatic/manual or off/none)");
  }
  // The unit of runs whose header gives none ("Run 1").
  if (one_of({"units", "unit", "deviation units", "deviation unit", "error units", "error unit",
              "units of error", "linear units", "result units"}))
    return {"deviation_unit", value};
  if (one_of({"air compensation", "environmental compensation", "compensation"})) {
    const std::string v = normalise(value);
    if (v == "on" || v == "applied" || v == "automatic" || v == "auto" || v == "yes" ||
        v == "manual" || v == "xc-80" || v == "xc80" || v == "instrument")
      return {"air_compensation", "instrument"};
    if (v == "off" || v == "none" || v == "no" || v == "not applied")
      return {"air_compensation", "none"};
    if (v == "edlen") return {"air_compensation", "edlen"};
    throw std::invalid_argument(where + "'" + value +
                                "' (expected on/applied/automatic/manual or off/none)");
  }
  if (one_of({"wavelength", "laser wavelength"})) return {"laser_wavelength_nm", number({})};
  if (one_of({"datum", "datum position"})) return {"datum_mm", number({})};
  if (only_known) return {"", ""};
  std::string slug;
  for (char ch : name) slug += std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
  while (slug.find("__") != std::string::npos) slug.erase(slug.find("__"), 1);
  while (!slug.empty() && slug.back() == '_') slug.pop_back();
  while (!slug.empty() && slug.front() == '_') slug.erase(0, 1);
  return {slug, value};
}

// The axis letter of an `Axis` value: "X", "X axis", "Axis X", "X-Axis".
std::string axis_letter(const std::string& value) {
  std::string found;
  std::string token;
  auto flush = [&]() {
    if (token.size() == 1 && std::isalpha(static_cast<unsigned char>(token[0]))) {
      if (!found.empty())
        found = "?";
      else
        found = std::string(1, static_cast<char>(std::toupper(token[0])));
    }
    token.clear();
  };
  for (char c : value) {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      token += c;
    } else {
      flush();
    }
  }
  flush();
  return found == "?" ? "" : found;
}

// The header row of a CARTO export and its separator: the first line with a target column and,
// unless the target column comes first, a direction or run column beside it (a leading "Target
// No." column is allowed); -1 when there is none in the first 200 lines.
int find_carto_header(const std::vector<Line>& lines, char& delim) {
  int seen = 0;
  for (std::size_t k = 0; k < lines.size() && seen < 200; ++k) {
    if (blank_or_comment(lines[k].text)) continue;
    ++seen;
    std::size_t best = 0;
    for (char d : {',', ';', '\t'}) {
      std::vector<Cell> cells;
      try {
        cells = split_csv(lines[k].text, d, "", 0);
      } catch (const InputError&) {
        continue;
      }
      bool first = false, target = false, other = false;
      for (std::size_t i = 0; i < cells.size(); ++i) {
        const Quantity q = classify_carto(cells[i]).q;
        first |= i == 0 && q == Quantity::Target;
        target |= q == Quantity::Target;
        other |= q == Quantity::Direction || q == Quantity::Deviation;
      }
      if ((first || (target && other)) && cells.size() > best) best = cells.size(), delim = d;
    }
    if (best > 0) return static_cast<int>(k);
  }
  return -1;
}

// The metadata before the header row `h`: `Key,Value` rows and `# key: value` comments.
void carto_metadata(const std::vector<Line>& lines, int h, char delim, const std::string& file,
                    Wide& w) {
  for (int k = 0; k < h; ++k) {
    const Line& L = lines[k];
    std::string key, value;
    int key_col = 1;
    const std::string t = trim(L.text);
    if (t.empty()) continue;
    if (t[0] == '#') {
      const std::size_t colon = t.find(':');
      if (colon == std::string::npos) continue;
      key = trim(t.substr(1, colon - 1));
      value = trim(t.substr(colon + 1));
      if (key.empty() || key.find(' ') != std::string::npos) continue;
    } else {
      const std::vector<Cell> cells = split_csv(L.text, delim, file, L.no);
      if (cells.size() == 1 && cells[0].text.find(':') != std::string::npos) {
        // "Material Compensation: On" (LaserXL-style): only keys weilgen knows, so that a title
        // line with a colon is not read as one.
        const std::string& c = cells[0].text;
        const std::size_t colon = c.find(':');
        const std::string where = "'" + trim(c.substr(0, colon)) + "': ";
        try {
          std::tie(key, value) =
              carto_key(trim(c.substr(0, colon)), trim(c.substr(colon + 1)), where, true);
        } catch (const std::invalid_argument& e) {
          throw InputError(SourceLoc{file, L.no, cells[0].column + static_cast<int>(colon) + 1},
                           e.what());
        }
        if (key.empty() || trim(c.substr(colon + 1)).empty()) continue;
        key_col = cells[0].column;
      } else if (cells.size() < 2 || cells[0].text.empty()) {
        continue;  // a title line
      } else {
        key_col = cells[0].column;
        key = cells[0].text;
        std::vector<std::string> rest;
        for (std::size_t i = 1; i < cells.size(); ++i)
          if (!cells[i].text.empty()) rest.push_back(cells[i].text);
        if (rest.empty()) continue;
        value = rest.size() == 1 ? rest[0] : join(rest);
        const std::string where = "'" + key + "': ";
        try {
          std::tie(key, value) = carto_key(key, value, where);
        } catch (const std::invalid_argument& e) {
          throw InputError(SourceLoc{file, L.no, cells[1].column}, e.what());
        }
        if (key.empty()) continue;
      }
    }
    if (w.meta.header_keys.count(key))
      throw InputError(SourceLoc{file, L.no, key_col},
                       "header key '" + key + "' given twice (first at line " +
                           std::to_string(w.meta.header_key_lines[key]) + ")");
    w.meta.header_keys[key] = value;
    w.meta.header_key_lines[key] = L.no;
  }
  // A laser export says whether its software corrected the material's expansion; without such a
  // line the state is unstated, which the normalisation treats differently from weilgen's own
  // tidy files (weilgen/measure/normalisation.hpp).
  if (!w.meta.header_keys.count("material_compensation")) {
    w.meta.header_keys["material_compensation"] = "unstated";
    w.meta.header_key_lines["material_compensation"] = 0;
  }
}

// The axis the file names (an 'Axis' line) or --axis; both must agree.
std::string carto_axis(const ImportOptions& o, const std::string& file, Wide& w) {
  std::string axis = o.axis;
  if (w.meta.header_keys.count("axis")) {
    const std::string a = axis_letter(w.meta.header_keys["axis"]);
    if (a.empty())
      throw InputError(
          SourceLoc{file, w.meta.header_key_lines["axis"], 0},
          "axis: '" + w.meta.header_keys["axis"] + "' names no axis letter (X, Y, Z, A, B, C ...)");
    if (!axis.empty() && axis != a)
      throw std::invalid_argument("--axis " + axis + ": " + file + " measures axis " + a +
                                  " (line " + std::to_string(w.meta.header_key_lines["axis"]) +
                                  ")");
    axis = a;
  }
  if (axis.empty())
    throw InputError(SourceLoc{file, w.meta.header_line, 0},
                     "CARTO: the file does not name its axis (no 'Axis' line before the table): "
                     "give it with --axis");
  if (axis_deviation_column(axis).empty() || axis.size() != 1)
    throw std::invalid_argument("axis " + axis +
                                ": expected one of X, Y, Z, U, V, W (linear) or A, B, C (rotary)");
  w.meta.header_keys["axis"] = axis;
  if (!w.meta.header_key_lines.count("axis")) w.meta.header_key_lines["axis"] = 0;
  return axis;
}

// The header row's columns, classified, with the unit conversion of each.
struct CartoTable {
  std::vector<CartoColumn> columns;
  std::vector<Conversion> conversions;
};

// The header row `h`: each column's quantity and unit; exactly one target column, a direction
// column and at least one run.
CartoTable carto_columns(const std::vector<Line>& lines, int h, char delim, const std::string& file,
                         bool rotary, const ImportOptions& o, Wide& w) {
  const std::vector<Cell> header = split_csv(lines[h].text, delim, file, lines[h].no);
  CartoTable t;
  std::vector<CartoColumn>& cols = t.columns;
  std::vector<Conversion>& conv = t.conversions;
  std::set<std::string> seen;
  bool has_direction = false, has_run = false;
  int targets = 0;
  // The unit of runs whose header gives none, from a 'Units' line.
  const auto units_key = w.meta.header_keys.find("deviation_unit");
  const std::string default_unit =
      units_key == w.meta.header_keys.end() ? std::string() : units_key->second;
  for (const Cell& cell : header) {
    CartoColumn c = classify_carto(cell);
    auto fail = [&](const std::string& msg) {
      return InputError(SourceLoc{file, lines[h].no, cell.column}, msg);
    };
    if (cell.text.empty()) {
      c.q = Quantity::Unknown;
      cols.push_back(c);
      conv.push_back({});
      continue;  // an empty trailing header cell: its column must stay empty
    }
    const std::string key = normalise(cell.text);
    if (!seen.insert(key).second) throw fail("duplicate column '" + cell.text + "'");
    const std::string where = "column '" + cell.text + "': ";
    Conversion cv;
    try {
      switch (c.q) {
        case Quantity::Target:
          ++targets;
          cv = target_unit(c.unit, rotary, where);
          break;
        case Quantity::TargetNumber:
          break;
        case Quantity::Direction:
          has_direction = true;
          break;
        case Quantity::Deviation:
          has_run = true;
          if (c.unit.empty() && default_unit.empty())
            throw std::invalid_argument(
                where + "no unit: the deviations could be in um, mm or nm; write it in the " +
                "header ('" + cell.text + " (um)') or give a 'Units,um' line before the table");
          cv = deviation_unit(c.unit.empty() ? default_unit : c.unit, rotary, where);
          break;
        case Quantity::AirT:
        case Quantity::MaterialT:
          cv = temperature_unit(c.unit, where);
          break;
        case Quantity::AirP:
          cv = pressure_unit(c.unit, where);
          break;
        case Quantity::AirH:
          if (!(c.unit.empty() || c.unit == "%" || normalise(c.unit) == "%rh"))
            throw std::invalid_argument(where + "unit '" + c.unit + "' (expected %)");
          cv.unit = "%";
          break;
        case Quantity::Time:
          cv = time_unit(c.unit.empty() ? "s" : c.unit, where);
          break;
        case Quantity::Unknown:
          if (!o.read.allow_unknown)
            throw std::invalid_argument(
                where + "not a column of a CARTO linear export (known: " + kCartoColumns + ")");
          w.meta.warnings.push_back(file + ":" + std::to_string(lines[h].no) + ":" +
                                    std::to_string(cell.column) + ": unknown column '" + cell.text +
                                    "' (skipped)");
          break;
      }
    } catch (const std::invalid_argument& e) {
      throw fail(e.what());
    }
    cols.push_back(c);
    conv.push_back(cv);
  }
  if (targets != 1) {
    int second = 0;
    for (const auto& c : cols)
      if (c.q == Quantity::Target && second++ > 0) second = c.column;
    throw InputError(SourceLoc{file, lines[h].no, targets == 0 ? 0 : second},
                     targets == 0 ? "no target column ('Target Position (mm)')"
                                  : "two target columns: give one");
  }
  if (!has_direction)
    throw InputError(SourceLoc{file, lines[h].no, 0},
                     "no Direction column: each row needs its approach direction (Forward or "
                     "Reverse)");
  if (!has_run)
    throw InputError(SourceLoc{file, lines[h].no, 0}, "no run column ('Run 1 (um)', ...)");

  return t;
}

// The tidy column each source column feeds, and the mapping the import reports.
void carto_tidy_columns(const CartoTable& t, const std::string& axis, ImportResult& res, Wide& w) {
  const std::vector<CartoColumn>& cols = t.columns;
  const std::vector<Conversion>& conv = t.conversions;
  const std::string deviation = axis_deviation_column(axis);
  const std::string sensor_base = "T_material";
  bool several_sensors = false;
  for (const auto& c : cols) several_sensors |= c.q == Quantity::MaterialT && c.sensor > 0;
  for (std::size_t i = 0; i < cols.size(); ++i) {
    const CartoColumn& c = cols[i];
    std::string tidy;
    switch (c.q) {
      case Quantity::Target:
        tidy = axis;
        break;
      case Quantity::Direction:
        tidy = "dir";
        break;
      case Quantity::Deviation:
        tidy = deviation;
        break;
      case Quantity::AirT:
        tidy = "T_air";
        break;
      case Quantity::AirP:
        tidy = "p_air_Pa";
        break;
      case Quantity::AirH:
        tidy = "RH_air_pct";
        break;
      case Quantity::MaterialT:
        tidy = c.sensor > 0 ? sensor_base + "_" + std::to_string(c.sensor)
                            : (several_sensors ? sensor_base + "_0" : sensor_base);
        break;
      case Quantity::Time:
        tidy = "t_s";
        break;
      case Quantity::TargetNumber:
        res.mapping.push_back("'" + c.header + "' -> (the target's number: checked, not carried)");
        break;
      case Quantity::Unknown:
        break;
    }
    if (tidy.empty()) continue;
    WideColumn wc;
    wc.tidy = tidy;
    wc.cycle = c.run;
    wc.header_column = c.column;
    w.columns.push_back(wc);
    std::string m = "'" + c.header + "' -> " + tidy;
    if (c.run > 0) m += " of cycle " + std::to_string(c.run);
    if (c.q == Quantity::Direction) m += " (Forward = +1, Reverse = -1)";
    if (!conv[i].unit.empty()) {
      m += " (" + conv[i].unit;
      if (conv[i].factor != 1) m += ", x " + format_number(conv[i].factor);
      if (conv[i].offset != 0) m += ", + " + format_number(conv[i].offset);
      m += ")";
    }
    res.mapping.push_back(m);
  }
}

// The data rows after the header row `h`, converted to the tidy columns' units.
void carto_rows(const std::vector<Line>& lines, int h, char delim, const CartoTable& t,
                const std::string& file, Wide& w) {
  const std::vector<CartoColumn>& cols = t.columns;
  const std::vector<Conversion>& conv = t.conversions;
  const std::size_t header_size = cols.size();
  const bool decimal_comma = delim != ',';
  for (std::size_t k = static_cast<std::size_t>(h) + 1; k < lines.size(); ++k) {
    const Line& L = lines[k];
    if (blank_or_comment(L.text)) continue;
    const std::vector<Cell> cells = split_csv(L.text, delim, file, L.no);
    std::size_t n = cells.size();
    while (n > header_size && cells[n - 1].text.empty()) --n;  // trailing separators
    if (n != header_size) {
      // A decimal comma in a comma-separated export splits every number in two.
      const std::string hint =
          delim == ',' && n > header_size
              ? " (decimal commas in a comma-separated file split every number: export with ';' "
                "or a tab between the fields, or with a decimal point)"
              : "";
      throw InputError(SourceLoc{file, L.no, n > header_size ? cells[header_size].column : 0},
                       std::to_string(n) + " fields, the header (line " +
                           std::to_string(lines[h].no) + ") has " + std::to_string(header_size) +
                           hint);
    }
    std::size_t wc = 0;
    for (std::size_t i = 0; i < cols.size(); ++i) {
      const Cell& cell = cells[i];
      auto fail = [&](const std::string& msg) {
        return InputError(SourceLoc{file, L.no, cell.column},
                          "column '" + cols[i].header + "': " + msg);
      };
      if (cols[i].q == Quantity::Unknown) {
        if (cols[i].header.empty() && !cell.text.empty())
          throw InputError(SourceLoc{file, L.no, cell.column}, "a value under no column name");
        continue;
      }
      if (cols[i].q == Quantity::TargetNumber) {
        double number = 0;
        if (!cell.text.empty() &&
            !(parse_number(cell.text, false, number) && number == std::floor(number)))
          throw fail("'" + cell.text + "' is not a whole number");
        continue;
      }
      double v = kNaN;
      if (cols[i].q == Quantity::Direction) {
        if (!cell.text.empty()) {
          v = direction_of(cell.text);
          if (v == 0)
            throw fail("'" + cell.text + "' is not a direction (Forward/Fwd/+1/Up or " +
                       "Reverse/Backward/Bwd/-1/Down)");
        }
      } else if (!cell.text.empty()) {
        if (!converted_number(cell.text, decimal_comma, conv[i], v))
          throw fail("'" + cell.text + "' is not a number");
      }
      if (std::isnan(v) && (cols[i].q == Quantity::Target || cols[i].q == Quantity::Direction))
        throw fail("empty: every row needs its " +
                   std::string(cols[i].q == Quantity::Target ? "target" : "direction"));
      w.columns[wc++].values.push_back(v);
    }
    w.lines.push_back(L.no);
  }
}

ImportResult parse_carto(const std::vector<Line>& lines, const std::string& file,
                         const ImportOptions& o) {
  char delim = ',';
  const int h = find_carto_header(lines, delim);
  if (h < 0)
    throw InputError(SourceLoc{file, 0, 0}, "CARTO: no header row with a target column (" +
                                                std::string(kCartoColumns) + ")");
  ImportResult res;
  res.format = InstrumentFormat::Carto;
  Wide w;
  w.meta.file = file;
  w.meta.header_line = lines[h].no;
  carto_metadata(lines, h, delim, file, w);
  const std::string axis = carto_axis(o, file, w);
  const bool rotary = axis == "A" || axis == "B" || axis == "C";
  const CartoTable table = carto_columns(lines, h, delim, file, rotary, o, w);
  carto_tidy_columns(table, axis, res, w);
  carto_rows(lines, h, delim, table, file, w);
  if (w.lines.empty())
    throw InputError(SourceLoc{file, lines[h].no, 0}, "no data rows after the header");
  w.read.coordinates = {axis};
  res.source_rows = w.lines.size();
  res.table = tidy_from_wide(w);
  return res;
}

// ---- Generic wide ------------------------------------------------------------------------------

ImportResult parse_wide(const std::string& text, const std::vector<Line>& lines,
                        const std::string& file, const ImportOptions& o) {
  // The header row's per-cycle names ("dx_um@3") are accepted by the tidy reader as covariates,
  // then split here.
  std::vector<Cell> header;
  int header_no = 0;
  for (const Line& L : lines) {
    if (blank_or_comment(L.text)) continue;
    header = split_csv(L.text, ',', file, L.no);
    header_no = L.no;
    break;
  }
  ReadOptions read = o.read;
  for (const Cell& c : header)
    if (c.text.find('@') != std::string::npos) read.expected.push_back(c.text);
  MeasurementTable t = parse_measurements(text, file, read);
  ImportResult res;
  res.format = InstrumentFormat::Wide;
  res.source_rows = t.rows();
  Wide w;
  w.meta = t;
  w.lines = t.lines;
  w.read = o.read;
  w.read.expected.clear();
  bool any_deviation = false;
  for (std::size_t i = 0; i < t.columns.size(); ++i) {
    const std::string& name = t.columns[i];
    const int col = i < header.size() ? header[i].column : 0;
    WideColumn wc;
    const std::size_t at = name.find('@');
    if (at == std::string::npos) {
      if (name == "cycle")
        throw InputError(SourceLoc{file, header_no, col},
                         "a wide file gives the cycle in the column names (dx_um@1, dx_um@2 ...), "
                         "not in a column 'cycle'");
      if (t.info[i].role == ColumnRole::Deviation)
        throw InputError(
            SourceLoc{file, header_no, col},
            "deviation column '" + name + "' without its cycle ('" + name + "@1' ...)");
      wc.tidy = name;
      res.mapping.push_back("'" + name + "' -> " + name + " of every cycle of the row");
    } else {
      const std::string base = name.substr(0, at), cyc = name.substr(at + 1);
      char* end = nullptr;
      const long j = std::strtol(cyc.c_str(), &end, 10);
      if (cyc.empty() || *end != '\0' || j < 1 || cyc.size() > 9)
        throw InputError(SourceLoc{file, header_no, col},
                         "column '" + name + "': the cycle after '@' must be a whole number >= 1");
      const ColumnRole role = classify_column(base, o.read).role;
      if (role != ColumnRole::Deviation && role != ColumnRole::Time &&
          role != ColumnRole::Temperature && role != ColumnRole::Covariate)
        throw InputError(SourceLoc{file, header_no, col},
                         "column '" + name + "': '" + base +
                             "' is not a deviation, time, temperature or covariate column");
      any_deviation |= role == ColumnRole::Deviation;
      wc.tidy = base;
      wc.cycle = j;
      res.mapping.push_back("'" + name + "' -> " + base + " of cycle " + std::to_string(j));
    }
    wc.values = t.values.at(name);
    w.columns.push_back(wc);
  }
  // The tidy reader warned about nothing of ours: '@' names were expected.
  if (!any_deviation)
    throw InputError(SourceLoc{file, header_no, 0},
                     "no per-cycle deviation column (dx_um@1, dx_um@2 ...)");
  res.table = tidy_from_wide(w);
  return res;
}

}  // namespace

const char* to_string(InstrumentFormat f) {
  switch (f) {
    case InstrumentFormat::Carto:
      return "carto";
    case InstrumentFormat::Wide:
      return "wide";
    case InstrumentFormat::Tidy:
      break;
  }
  return "tidy";
}

InstrumentFormat parse_instrument_format(const std::string& text) {
  const std::string t = lower(trim(text));
  if (t == "tidy") return InstrumentFormat::Tidy;
  if (t == "carto") return InstrumentFormat::Carto;
  if (t == "wide") return InstrumentFormat::Wide;
  throw std::invalid_argument("--format " + text + ": expected auto, tidy, carto or wide");
}

InstrumentFormat detect_instrument_format(const std::string& text) {
  const std::vector<Line> lines = split_lines(text);
  for (const Line& L : lines) {
    const std::string t = trim(L.text);
    if (t.empty()) continue;
    if (t[0] != '#') break;
    const std::size_t colon = t.find(':');
    if (colon != std::string::npos && trim(t.substr(1, colon - 1)) == "format" &&
        lower(trim(t.substr(colon + 1))) == "wide")
      return InstrumentFormat::Wide;
  }
  char delim = ',';
  return find_carto_header(lines, delim) >= 0 ? InstrumentFormat::Carto : InstrumentFormat::Tidy;
}

ImportResult parse_instrument_text(const std::string& text, const std::string& filename,
                                   const ImportOptions& o) {
  const InstrumentFormat f = o.format ? *o.format : detect_instrument_format(text);
  if (f == InstrumentFormat::Tidy) {
    ImportResult r;
    try {
      r.table = parse_measurements(text, filename, o.read);
    } catch (const InputError& e) {
      // A header row without a comma is a title line: the file is likely an export whose table
      // was not recognised, and the tidy reader's complaint about it would mislead.
      const std::vector<Line> lines = split_lines(text);
      const auto first = std::find_if(lines.begin(), lines.end(),
                                      [](const Line& L) { return !blank_or_comment(L.text); });
      if (o.format || first == lines.end() || first->no != e.loc().line ||
          first->text.find_first_of(",;\t") != std::string::npos)
        throw;
      throw InputError(e.loc(), e.message() +
                                    " (the first line is text without a separator: an instrument "
                                    "export whose table was not found? Its header row needs a "
                                    "target column such as 'Target Position (mm)'; --format "
                                    "carto or wide; docs/data-format.md, 'Instrument files')");
    }
    r.source_rows = r.table.rows();
    return r;
  }
  const std::vector<Line> lines = split_lines(text);
  if (lines.empty()) throw InputError(SourceLoc{filename, 0, 0}, "empty file");
  return f == InstrumentFormat::Carto ? parse_carto(lines, filename, o)
                                      : parse_wide(text, lines, filename, o);
}

ImportResult read_instrument_file(const std::string& path, const ImportOptions& o) {
  return parse_instrument_text(read_data_file(path), path, o);
}

}  // namespace weilgen
