#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <set>
#include <stdexcept>

#include "internal.hpp"
#include "weilgen/analysis/ballbar_model.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"

namespace weilgen {

using namespace gap_detail;

GapData gap_data(const MeasurementTable& table, const Description& desc,
                 const std::map<std::string, double>& fixed, const BallbarFlags& ballbar,
                 const std::vector<double>& parameters) {
  MeasurementTable t = table;
  GapData g;
  const bool trace = t.has("dr_um");
  for (int b : desc.axes()) {
    const std::string& c = desc.bodies[static_cast<std::size_t>(b)].joint.coordinate;
    g.axes.push_back(c);
    g.axis_units.push_back(desc.bodies[static_cast<std::size_t>(b)].joint.unit);
    if (trace || t.has(c)) continue;
    const auto it = fixed.find(c);
    if (it == fixed.end())
      throw InputError(SourceLoc{t.file, t.header_line, 0},
                       "missing column '" + c + "' (give the coordinate of a pose the data do " +
                           "not vary with --at " + c + "=VALUE; columns: " + join(t.columns) + ")");
    t.values[c] = std::vector<double>(t.rows(), it->second);
    t.columns.push_back(c);
    ColumnInfo info;
    info.name = c;
    info.role = ColumnRole::Coordinate;
    info.unit = desc.bodies[static_cast<std::size_t>(b)].joint.unit;
    t.info.push_back(info);
    g.fixed_axes.push_back(c);
  }
  // A rotary coordinate in radians where the machine says degrees is the reader's check
  // (measurement_csv.cpp, check_radians): identify reads the same columns.
  g.points =
      trace ? ballbar_point_data(t, desc, ballbar, parameters, g.circle) : point_data(t, desc);
  const std::size_t rows = t.rows();
  g.time_s = t.has("t_s") ? t.column("t_s") : std::vector<double>(rows, kNaN);
  g.cycle = t.has("cycle") ? t.column("cycle") : std::vector<double>(rows, kNaN);
  // Observed rows only decide what varies.
  std::vector<bool> observed(rows, false);
  for (const PointObservation& o : g.points.observations) observed[o.row] = true;
  // Every measured row needs the column's value (a gap is named with its rows); a covariate must
  // also vary, a direction or a cycle need not (one direction, one cycle).
  auto check_varies = [&](const std::string& name, const std::vector<double>& v, const char* unit,
                          bool must_vary = true) {
    double lo = INFINITY, hi = -INFINITY;
    std::vector<std::size_t> gaps;  // measured rows without a value
    for (std::size_t r = 0; r < rows; ++r) {
      if (!observed[r]) continue;
      if (!std::isfinite(v[r])) {
        gaps.push_back(r);
        continue;
      }
      lo = std::min(lo, v[r]), hi = std::max(hi, v[r]);
    }
    if (!gaps.empty()) {
      std::string list;
      for (std::size_t k = 0; k < gaps.size() && k < 10; ++k)
        list += (k ? ", " : "") + std::to_string(t.lines[gaps[k]]);
      if (gaps.size() > 10) list += " and " + std::to_string(gaps.size() - 10) + " more";
      throw InputError(t.cell(gaps.front(), name),
                       "column '" + name + "' is empty in " + std::to_string(gaps.size()) + " row" +
                           (gaps.size() > 1 ? "s" : "") + " where a deviation is measured (line" +
                           (gaps.size() > 1 ? "s " : " ") + list +
                           "): the diagnosis needs it in every row; fill or drop those rows");
    }
    if (must_vary && !(hi > lo))
      throw InputError(SourceLoc{t.file, t.header_line, 0},
                       "column '" + name + "' is constant (" + format_short(lo) + " " + unit +
                           "): it cannot explain anything; drop the column");
  };
  for (const std::string& c : t.columns_with(ColumnRole::Temperature)) {
    check_varies(c, t.column(c), "degC");
    g.temperature[c] = t.column(c);
  }
  for (const std::string& c : t.columns_with(ColumnRole::Covariate)) {
    check_varies(c, t.column(c), t.info_of(c).unit.c_str());
    g.covariate[c] = t.column(c);
    g.covariate_unit[c] = t.info_of(c).unit;
  }
  if (t.has("t_s")) check_varies("t_s", g.time_s, "s");
  if (t.has("cycle")) check_varies("cycle", g.cycle, "", false);
  // Directions: dir_<axis>, or `dir` for the axis that varies most.
  if (trace) {
    check_varies("angle_deg", t.column("angle_deg"), "deg");
    g.covariate["angle_deg"] = t.column("angle_deg");
    g.covariate_unit["angle_deg"] = t.info_of("angle_deg").unit;
  }
  for (const std::string& c : t.columns_with(ColumnRole::Direction)) {
    std::string axis = t.info_of(c).axis;
    if (axis.empty() && trace) {  // a trace's `dir` is its feed (ccw +1, cw -1)
      check_varies("dir", t.column(c), "");
      g.covariate["feed"] = t.column(c);
      g.covariate_unit["feed"] = "";  // ccw +1, cw -1
      continue;
    }
    if (axis.empty()) {
      std::size_t best = 0;
      for (const std::string& a : g.axes) {
        const std::size_t n = t.has(a) ? distinct(t.column(a)) : 0;
        if (n > best) best = n, axis = a;
      }
    }
    check_varies(c, t.column(c), "", false);
    if (!axis.empty()) g.dir[axis] = t.column(c);
  }
  // A trace's axes reverse where the circle says: their directions of travel come from the
  // angle and the feed (a `dir` column, else the circle's), so `reversal` sees a trace without
  // dir_<axis> columns too.
  if (trace && g.circle) {
    const std::vector<double>& angle = t.column("angle_deg");
    const std::vector<double>* feed = nullptr;
    for (const std::string& c : t.columns_with(ColumnRole::Direction))
      if (t.info_of(c).axis.empty()) feed = &t.column(c);
    for (int which : {0, 1}) {
      const std::string& axis = which == 0 ? g.circle->first : g.circle->second;
      if (g.dir.count(axis)) continue;  // the file's own dir_<axis> wins
      std::vector<double> dir(rows, kNaN);
      for (std::size_t r = 0; r < rows; ++r) {
        if (!std::isfinite(angle[r])) continue;
        const int f =
            feed && std::isfinite((*feed)[r]) ? static_cast<int>((*feed)[r]) : g.circle->feed;
        dir[r] = ballbar_travel_direction({angle[r]}, f, which).front();
      }
      g.dir[axis] = dir;
      g.derived_dir.push_back(axis);
    }
  }
  if (g.points.observations.size() < 10)
    throw InputError(SourceLoc{t.file, 0, 0}, "only " +
                                                  std::to_string(g.points.observations.size()) +
                                                  " observations: the diagnosis needs at least 10");
  return g;
}

std::map<std::string, double> parse_fixed_coordinates(const Description& desc,
                                                      const std::vector<std::string>& at) {
  std::map<std::string, double> fixed;
  for (const std::string& a : at)
    for (const std::string& item : split(a, ',')) {
      const auto eq = item.find('=');
      if (eq == std::string::npos)
        throw std::invalid_argument("--at \"" + item + "\": expected NAME=VALUE");
      const std::string name = trim(item.substr(0, eq));
      if (desc.coordinate_body(name) < 0)
        throw std::invalid_argument("--at: '" + name + "' is not a coordinate of " + desc.name);
      const std::string unit =
          desc.bodies[static_cast<std::size_t>(desc.coordinate_body(name))].joint.unit;
      fixed[name] =
          parse_quantity_unit(item.substr(eq + 1), unit, "--at " + name).in(parse_unit(unit));
    }
  return fixed;
}

}  // namespace weilgen
