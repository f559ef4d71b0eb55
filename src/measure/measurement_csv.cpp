#include "weilgen/measure/measurement_csv.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen {

namespace {

bool is_ident_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
}

bool is_identifier(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), is_ident_char);
}

bool is_space(char c) { return c == ' ' || c == '\t'; }

// [first, last) of s without surrounding blanks.
std::pair<std::size_t, std::size_t> trimmed_range(const std::string& s, std::size_t first,
                                                  std::size_t last) {
  while (first < last && is_space(s[first])) ++first;
  while (last > first && is_space(s[last - 1])) --last;
  return {first, last};
}

// One comma-separated field: its text (trimmed) and its 1-based character column.
struct Field {
  std::string text;
  int column = 0;
};

std::vector<Field> split_fields(const std::string& line) {
  std::vector<Field> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    const std::size_t end = comma == std::string::npos ? line.size() : comma;
    const auto [a, b] = trimmed_range(line, start, end);
    out.push_back({line.substr(a, b - a), static_cast<int>((a < b ? a : start) + 1)});
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

bool is_coordinate_name(const std::string& name, const ReadOptions& o) {
  if (!o.coordinates.empty())
    return std::find(o.coordinates.begin(), o.coordinates.end(), name) != o.coordinates.end();
  return name.size() == 1 && name[0] >= 'A' && name[0] <= 'Z';
}

std::string coordinate_unit(const std::string& name) {
  return name == "A" || name == "B" || name == "C" ? "deg" : "mm";
}

// Strict number: digits, sign, '.', exponent; rejects nan, inf, hex and overflow.
bool parse_number(const std::string& text, double& value, std::string& why) {
  if (text.find_first_not_of("0123456789+-.eE") != std::string::npos) {
    why = "is not a number";
    return false;
  }
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || text.empty()) {
    why = "is not a number";
    return false;
  }
  if (!std::isfinite(value)) {
    why = "is out of range";
    return false;
  }
  return true;
}

const char* kKnownRoles =
    "coordinates (single upper-case letters such as X, Y, Z, A, C, or the machine's), t_s, dir, "
    "dir_<axis>, cycle, T_<name>, covariates (rpm, feed_mm_min, p_air_Pa, RH_air_pct, "
    "cov_<name>), deviations "
    "(dx_um, dy_um, dz_um, da_urad, db_urad, dc_urad), ballbar angle_deg and dr_um";

}  // namespace

const char* to_string(ColumnRole role) {
  switch (role) {
    case ColumnRole::Coordinate:
      return "coordinate";
    case ColumnRole::Time:
      return "time";
    case ColumnRole::Direction:
      return "direction";
    case ColumnRole::Cycle:
      return "cycle";
    case ColumnRole::Temperature:
      return "temperature";
    case ColumnRole::Covariate:
      return "covariate";
    case ColumnRole::Deviation:
      return "deviation";
    case ColumnRole::Angle:
      return "angle";
    case ColumnRole::Radial:
      return "radial";
    case ColumnRole::Unknown:
      break;
  }
  return "unknown";
}

ColumnInfo classify_column(const std::string& name, const ReadOptions& o) {
  ColumnInfo c;
  c.name = name;
  auto set = [&](ColumnRole role, std::string unit, std::string axis = "") {
    c.role = role;
    c.unit = std::move(unit);
    c.axis = std::move(axis);
    return c;
  };
  if (is_coordinate_name(name, o)) return set(ColumnRole::Coordinate, coordinate_unit(name));
  if (name == "t_s") return set(ColumnRole::Time, "s");
  if (name == "dir") return set(ColumnRole::Direction, "");
  if (name.rfind("dir_", 0) == 0 && is_coordinate_name(name.substr(4), o))
    return set(ColumnRole::Direction, "", name.substr(4));
  if (name == "cycle") return set(ColumnRole::Cycle, "");
  if (name.size() > 2 && name.rfind("T_", 0) == 0 && is_identifier(name.substr(2)))
    return set(ColumnRole::Temperature, "degC");
  if (name == "dx_um" || name == "dy_um" || name == "dz_um")
    return set(ColumnRole::Deviation, "um");
  if (name == "da_urad" || name == "db_urad" || name == "dc_urad")
    return set(ColumnRole::Deviation, "urad");
  if (name == "angle_deg") return set(ColumnRole::Angle, "deg");
  if (name == "dr_um") return set(ColumnRole::Radial, "um");
  if (std::find(o.expected.begin(), o.expected.end(), name) != o.expected.end())
    return set(ColumnRole::Covariate, "");
  if (name == "rpm") return set(ColumnRole::Covariate, "1/min");
  if (name == "feed_mm_min") return set(ColumnRole::Covariate, "mm/min");
  // The air of a laser measurement (air refraction, docs/iso230-2.md); T_air is a temperature.
  if (name == "p_air_Pa") return set(ColumnRole::Covariate, "Pa");
  if (name == "RH_air_pct") return set(ColumnRole::Covariate, "%");
  if (name.size() > 4 && name.rfind("cov_", 0) == 0 && is_identifier(name.substr(4)))
    return set(ColumnRole::Covariate, "");
  return set(ColumnRole::Unknown, "");
}

const std::vector<double>& MeasurementTable::column(const std::string& name) const {
  const auto it = values.find(name);
  if (it == values.end())
    throw InputError(SourceLoc{file, 0, 0},
                     "missing column '" + name + "' (columns: " + join(columns) + ")");
  return it->second;
}

SourceLoc MeasurementTable::cell(std::size_t row, const std::string& name) const {
  SourceLoc at{file, row < lines.size() ? lines[row] : 0, 0};
  for (std::size_t c = 0; c < columns.size(); ++c)
    if (columns[c] == name && row < cell_columns.size() && c < cell_columns[row].size())
      at.column = cell_columns[row][c];
  return at;
}

SourceLoc MeasurementTable::header_cell(const std::string& name) const {
  const auto it = header_columns.find(name);
  return SourceLoc{file, header_line, it == header_columns.end() ? 0 : it->second};
}

const ColumnInfo& MeasurementTable::info_of(const std::string& name) const {
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (columns[i] == name) return info[i];
  column(name);  // throws
  throw InputError(SourceLoc{file, 0, 0}, "missing column '" + name + "'");
}

std::vector<std::string> MeasurementTable::columns_with(ColumnRole role) const {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (info[i].role == role) out.push_back(columns[i]);
  return out;
}

std::string MeasurementTable::header_key(const std::string& key,
                                         const std::string& fallback) const {
  const auto it = header_keys.find(key);
  return it == header_keys.end() ? fallback : it->second;
}

namespace {

// An angle column in degrees that holds radians (docs/data-format.md, "Angles in radians"). The
// radian reading must be possible: the column turns (3 or more distinct values), every value
// lies within ±2π and, read as radians, inside the travel [min, max] deg of an axis that turns
// 90° or more. Then, when the values read as radians land on whole degrees (0.523599 = 30°, each
// of 2 or more nonzero values within 0.03°, half the rounding of 3 decimals) and are not whole
// numbers as written, it is an error; when only the range says so (the data would turn the axis
// by 0.5 to 2π degrees of its travel) it is a warning: a short sweep in degrees is possible.
void check_radians(const MeasurementTable& t, std::size_t c, double min, double max,
                   std::vector<std::string>& warnings) {
  const std::string& name = t.columns[c];
  const std::vector<double>& v = t.values.at(name);
  constexpr double kDeg = 180 / kPi;
  if (max - min < 90) return;
  std::vector<double> seen;
  std::size_t at = 0;  // the row of the largest magnitude
  for (std::size_t row = 0; row < v.size(); ++row) {
    const double x = v[row];
    if (std::isnan(x)) continue;
    if (std::fabs(x) > 2 * kPi + 1e-6 || x * kDeg < min - 1 || x * kDeg > max + 1) return;
    if (std::find(seen.begin(), seen.end(), x) == seen.end()) seen.push_back(x);
    if (std::fabs(x) > std::fabs(v[at]) || std::isnan(v[at])) at = row;
  }
  if (seen.size() < 3) return;
  const auto [lo, hi] = std::minmax_element(seen.begin(), seen.end());
  std::size_t nonzero = 0;
  bool whole_as_radians = true, whole_as_written = true;
  for (double x : seen) {
    if (x == 0) continue;
    ++nonzero;
    whole_as_radians = whole_as_radians && std::fabs(x * kDeg - std::round(x * kDeg)) <= 0.03;
    whole_as_written = whole_as_written && x == std::round(x);
  }
  const SourceLoc cell{t.file, t.lines[at], t.cell_columns[at][c]};
  const std::string range = " (" + format_short(*lo) + " .. " + format_short(*hi) + ") while " +
                            name + " is in deg over [" + format_short(min) + ", " +
                            format_short(max) + "] deg";
  if (nonzero >= 2 && whole_as_radians && !whole_as_written)
    throw InputError(cell, "column '" + name + "' looks like radians: every value lies within ±2π" +
                               range + ", and read as radians they are whole degrees (" +
                               format_short(v[at]) +
                               " rad = " + format_short(std::round(v[at] * kDeg)) +
                               " deg); write it in degrees (times 180/π)");
  if (*hi - *lo >= 0.5)
    warnings.push_back(cell.str() + ": warning: column '" + name +
                       "' looks like radians: every value lies within ±2π" + range +
                       ", so as degrees the data turn " + name + " by only " +
                       format_short(*hi - *lo) +
                       " deg; if they are radians, write them in degrees");
}

// The checks that need every row: the machine named in the header, values that cannot be real,
// coordinates outside the travel, angles in radians (docs/data-format.md, "Checks on values").
void check_values(MeasurementTable& t, const ReadOptions& o) {
  const auto where = [&](std::size_t row, std::size_t c) {
    return SourceLoc{t.file, t.lines[row], t.cell_columns[row][c]};
  };
  if (!o.machine.empty() && t.header_keys.count("machine") &&
      t.header_keys.at("machine") != o.machine)
    throw InputError(SourceLoc{t.file, t.header_key_lines.at("machine"), 0},
                     "'# machine: " + t.header_keys.at("machine") + "', but the machine given is " +
                         o.machine + ": these data were recorded on another machine");
  std::size_t warned = 0, more = 0;
  const auto warn = [&](const SourceLoc& at, const std::string& message) {
    if (warned++ < 5)
      t.warnings.push_back(at.str() + ": warning: " + message);
    else
      ++more;
  };
  for (std::size_t c = 0; c < t.columns.size(); ++c) {
    const ColumnInfo& info = t.info[c];
    const std::vector<double>& v = t.values.at(t.columns[c]);
    const ReadOptions::Travel* travel = nullptr;
    for (const auto& r : o.travel)
      if (r.coordinate == t.columns[c] && r.min < r.max) travel = &r;
    for (std::size_t row = 0; row < v.size(); ++row) {
      const double x = v[row];
      if (std::isnan(x)) continue;
      const std::string cell = "column '" + t.columns[c] + "': " + format_short(x);
      if ((info.role == ColumnRole::Deviation || info.role == ColumnRole::Radial) &&
          std::fabs(x) > kImplausibleDeviation) {
        if (std::fabs(x) > kImpossibleDeviation)
          throw InputError(where(row, c), cell + " " + info.unit +
                                              " is impossible for a machine-tool deviation "
                                              "(more than 1 m or 1 rad): check the unit");
        warn(where(row, c), cell + " " + info.unit +
                                " is implausibly large for a deviation (more than 10 mm or "
                                "10 mrad): check the unit");
      }
      if (info.role == ColumnRole::Coordinate && std::fabs(x) > kImpossibleCoordinate)
        throw InputError(where(row, c), cell + " is impossible for a coordinate (more than " +
                                            format_short(kImpossibleCoordinate) + " " + info.unit +
                                            ")");
      if (info.role == ColumnRole::Temperature && x < -273.15)
        throw InputError(where(row, c), cell + " °C is below absolute zero");
      if (travel && (x < travel->min || x > travel->max))
        warn(where(row, c), cell + " " + travel->unit + " is outside the travel range [" +
                                format_short(travel->min) + ", " + format_short(travel->max) +
                                "] " + travel->unit + " of machine " + o.machine);
    }
  }
  if (more > 0)
    t.warnings.push_back(t.file + ": warning: " + std::to_string(more) +
                         " more value(s) like those above");
  for (std::size_t c = 0; c < t.columns.size(); ++c) {
    if (t.info[c].role == ColumnRole::Angle) check_radians(t, c, -360, 720, t.warnings);
    for (const auto& r : o.travel)
      if (r.coordinate == t.columns[c] && r.unit == "deg" &&
          t.info[c].role == ColumnRole::Coordinate)
        check_radians(t, c, r.min, r.max, t.warnings);
  }
}

}  // namespace

MeasurementTable parse_measurements(const std::string& text, const std::string& filename,
                                    const ReadOptions& options) {
  MeasurementTable t;
  t.file = filename;
  auto fail = [&](int line, int col, const std::string& msg) -> InputError {
    return InputError(SourceLoc{filename, line, col}, msg);
  };

  std::size_t pos = 0;
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) pos = 3;  // UTF-8 byte-order mark
  int line_no = 0;
  bool header_seen = false;
  while (pos < text.size()) {
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string::npos) nl = text.size();
    std::string line = text.substr(pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto [a, b] = trimmed_range(line, 0, line.size());
    if (a == b) continue;  // blank line
    if (line[a] == '#') {
      if (header_seen) continue;
      // "# key: value" before the header.
      const std::string body = line.substr(a + 1, b - a - 1);
      const std::size_t colon = body.find(':');
      if (colon == std::string::npos) continue;
      const auto [ka, kb] = trimmed_range(body, 0, colon);
      const std::string key = body.substr(ka, kb - ka);
      bool ok = !key.empty();
      for (char ch : key) ok = ok && (is_ident_char(ch) || ch == '-' || ch == '.');
      if (!ok) continue;  // a plain comment
      const auto [va, vb] = trimmed_range(body, colon + 1, body.size());
      if (t.header_keys.count(key))
        throw fail(line_no, static_cast<int>(a + 2 + ka),
                   "header key '" + key + "' given twice (first at line " +
                       std::to_string(t.header_key_lines[key]) + ")");
      t.header_keys[key] = body.substr(va, vb - va);
      t.header_key_lines[key] = line_no;
      continue;
    }
    const std::vector<Field> fields = split_fields(line);
    if (!header_seen) {
      header_seen = true;
      t.header_line = line_no;
      std::vector<std::string> unknown;
      for (std::size_t i = 0; i < fields.size(); ++i) {
        std::string name = fields[i].text;
        if (name.size() >= 2 && name.front() == '"' && name.back() == '"')
          name = name.substr(1, name.size() - 2);
        if (name.empty())
          throw fail(line_no, fields[i].column,
                     "empty column name (header field " + std::to_string(i + 1) + ")");
        if (name.find('"') != std::string::npos)
          throw fail(line_no, fields[i].column,
                     "column name " + fields[i].text +
                         ": quotes only around a whole name, without quotes inside");
        const auto dup = std::find(t.columns.begin(), t.columns.end(), name);
        if (dup != t.columns.end())
          throw fail(line_no, fields[i].column,
                     "duplicate column '" + name + "' (also header field " +
                         std::to_string(dup - t.columns.begin() + 1) + ")");
        ColumnInfo info = classify_column(name, options);
        if (info.role == ColumnRole::Unknown) {
          unknown.push_back("'" + name + "'");
          if (options.allow_unknown)
            t.warnings.push_back(filename + ":" + std::to_string(line_no) + ":" +
                                 std::to_string(fields[i].column) + ": unknown column '" + name +
                                 "' (kept, not interpreted)");
        }
        t.columns.push_back(name);
        t.info.push_back(std::move(info));
        t.values[name];
        t.header_columns[name] = fields[i].column;
      }
      if (!unknown.empty() && !options.allow_unknown)
        throw fail(line_no, 0,
                   std::string(unknown.size() > 1 ? "unknown columns " : "unknown column ") +
                       join(unknown) + " (known: " + kKnownRoles + ")");
      continue;
    }
    // A data row.
    if (fields.size() != t.columns.size())
      throw fail(line_no, 0,
                 std::to_string(fields.size()) + " field" + (fields.size() == 1 ? "" : "s") +
                     ", the header (line " + std::to_string(t.header_line) + ") has " +
                     std::to_string(t.columns.size()));
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const Field& f = fields[i];
      const std::string& name = t.columns[i];
      double v = kNaN;
      if (!f.text.empty()) {
        std::string why;
        if (!parse_number(f.text, v, why))
          throw fail(line_no, f.column,
                     "column '" + name + "': '" + abbreviated(f.text) + "' " + why);
        const ColumnRole role = t.info[i].role;
        if (role == ColumnRole::Direction && v != 1.0 && v != -1.0)
          throw fail(line_no, f.column, "column '" + name + "': '" + f.text + "' must be +1 or -1");
        if (role == ColumnRole::Cycle && v != std::floor(v))
          throw fail(line_no, f.column,
                     "column '" + name + "': '" + f.text + "' is not an integer");
      }
      t.values[name].push_back(v);
    }
    t.lines.push_back(line_no);
    t.cell_columns.emplace_back();
    for (const Field& f : fields) t.cell_columns.back().push_back(f.column);
  }
  if (!header_seen)
    throw fail(0, 0, line_no == 0 ? "empty file" : "no header row (only comments and blank lines)");
  if (t.lines.empty()) throw fail(t.header_line, 0, "no data rows after the header");
  check_values(t, options);
  return t;
}

std::string read_data_file(const std::string& path) {
  std::string text;
  if (const std::string why = unreadable_reason(path); !why.empty() || !read_file(path, text))
    throw InputError(SourceLoc{path, 0, 0},
                     "cannot read the data file: " + (why.empty() ? "read error" : why));
  return text;
}

MeasurementTable read_measurements(const std::string& path, const ReadOptions& options) {
  return parse_measurements(read_data_file(path), path, options);
}

ReadOptions machine_read_options(const Description& desc, bool allow_unknown) {
  ReadOptions ro;
  for (int b : desc.axes())
    ro.coordinates.push_back(desc.bodies[static_cast<std::size_t>(b)].joint.coordinate);
  ro.allow_unknown = allow_unknown;
  ro.machine = desc.name;
  for (int b : desc.axes()) {
    const Joint& j = desc.bodies[static_cast<std::size_t>(b)].joint;
    ro.travel.push_back({j.coordinate, j.unit, j.min, j.max});
  }
  return ro;
}

}  // namespace weilgen
