// ISO 230-2 data grouping, column selection and the standard's figures. Stejskal et al. 2017's
// evaluation is in iso230_2_drift.cpp. Formulas: docs/iso230-2.md.
#include "weilgen/measure/iso230_2.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>

#include "weilgen/base/constants.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/uq/distribution.hpp"
#include "weilgen/uq/test_statistics.hpp"

namespace weilgen {

namespace {

std::string mm(double v) { return format_number(v) + " mm"; }

std::string dir_name(int d) { return d == kUp ? "+1" : "-1"; }

std::string list_cycles(const std::vector<long>& c, std::size_t max_items = 8) {
  std::vector<std::string> s;
  for (std::size_t i = 0; i < c.size() && i < max_items; ++i) s.push_back(std::to_string(c[i]));
  if (c.size() > max_items) s.push_back("...");
  return join(s);
}

}  // namespace

double sample_mean(const std::vector<double>& v) {
  if (v.empty()) return kNaN;
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

double sample_sd(const std::vector<double>& v) {
  if (v.size() < 2) return kNaN;
  const double m = sample_mean(v);
  double ss = 0;
  for (double x : v) ss += (x - m) * (x - m);
  return std::sqrt(ss / static_cast<double>(v.size() - 1));
}

double difference_sd_ratio(const std::vector<double>& a) {
  if (a.size() < 3) return kNaN;
  std::vector<double> b(a.size() - 1);
  for (std::size_t i = 0; i + 1 < a.size(); ++i) b[i] = a[i] - a[i + 1];
  return sample_sd(b) / sample_sd(a);
}

double student_coverage_factor(std::size_t dof, double k_normal) {
  if (dof < 1) throw std::invalid_argument("student_coverage_factor: dof must be >= 1");
  return students_t_quantile(static_cast<double>(dof), normal_cdf(k_normal));
}

std::string axis_deviation_column(const std::string& axis) {
  static const std::map<std::string, std::string> kDefault = {
      {"X", "dx_um"}, {"U", "dx_um"},   {"Y", "dy_um"},   {"V", "dy_um"},  {"Z", "dz_um"},
      {"W", "dz_um"}, {"A", "da_urad"}, {"B", "db_urad"}, {"C", "dc_urad"}};
  const auto it = kDefault.find(axis);
  return it == kDefault.end() ? std::string() : it->second;
}

// ---- Grouping --------------------------------------------------------------------------------

IsoRuns group_iso_runs(const std::vector<IsoObservation>& observations, const std::string& file,
                       double tolerance_mm) {
  auto fail = [&](int line, const std::string& msg) {
    return InputError(SourceLoc{file, line, 0}, msg);
  };
  // Blanks (an empty deviation cell) only locate a missing observation.
  std::vector<IsoObservation> obs, blanks;
  for (const IsoObservation& o : observations)
    (std::isnan(o.deviation) ? blanks : obs).push_back(o);
  if (obs.empty()) throw fail(0, "no observations (no row has a measured deviation)");
  IsoRuns runs;
  runs.file = file;

  // Targets: clusters of sorted positions, each spanning at most tolerance_mm.
  std::vector<std::size_t> order(obs.size());
  for (std::size_t i = 0; i < obs.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return obs[a].position_mm < obs[b].position_mm;
  });
  std::vector<std::size_t> target_of(obs.size());
  // Offsets from the cluster's first position, so a target read as the same number every time
  // is that number exactly (a plain mean of 10 x 103.2 is 103.20000000000002).
  std::vector<double> start, sum;
  std::vector<std::size_t> count;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const double p = obs[order[k]].position_mm;
    if (k == 0 || p - start.back() > tolerance_mm) {
      start.push_back(p);
      sum.push_back(0);
      count.push_back(0);
    }
    sum.back() += p - start.back();
    ++count.back();
    target_of[order[k]] = sum.size() - 1;
  }
  const std::size_t m = sum.size();
  for (std::size_t i = 0; i < m; ++i)
    runs.positions_mm.push_back(start[i] + sum[i] / static_cast<double>(count[i]));

  // (direction, target, cycle) -> observation.
  std::array<std::map<std::pair<std::size_t, long>, std::size_t>, 2> cell;
  std::array<std::vector<int>, 2> first_line;  // per direction and target, 0 = none
  for (int d = 0; d < 2; ++d) first_line[d].assign(m, 0);
  for (std::size_t k = 0; k < obs.size(); ++k) {
    const IsoObservation& o = obs[k];
    if (o.direction != 1 && o.direction != -1)
      throw fail(o.line, "direction " + std::to_string(o.direction) + " must be +1 or -1");
    const int d = o.direction > 0 ? kUp : kDown;
    const std::size_t i = target_of[k];
    const auto [it, inserted] = cell[d].emplace(std::make_pair(i, o.cycle), k);
    if (!inserted)
      throw fail(o.line,
                 "target " + mm(runs.positions_mm[i]) + ", direction " + dir_name(d) + ", cycle " +
                     std::to_string(o.cycle) + " is measured twice (also " +
                     (obs[it->second].line > 0 ? "line " + std::to_string(obs[it->second].line)
                                               : std::string("earlier")) +
                     ")");
    if (first_line[d][i] == 0) first_line[d][i] = o.line > 0 ? o.line : -1;
  }
  for (int d = 0; d < 2; ++d) {
    if (cell[d].empty())
      throw fail(0, std::string("no observation in direction ") + dir_name(d) +
                        ": ISO 230-2 needs both approach directions (column dir or dir_<axis>)");
  }
  // The same targets in both directions.
  for (std::size_t i = 0; i < m; ++i) {
    for (int d = 0; d < 2; ++d) {
      if (first_line[d][i] == 0) {
        const int o = 1 - d;
        throw fail(std::max(first_line[o][i], 0), "target " + mm(runs.positions_mm[i]) +
                                                      " is measured in direction " + dir_name(o) +
                                                      " but not in direction " + dir_name(d) +
                                                      " (both directions need the same targets)");
      }
    }
  }
  runs.has_time = true;
  for (int d = 0; d < 2; ++d) {
    std::vector<long>& cycles = runs.cycles[d];
    for (const auto& [key, k] : cell[d]) cycles.push_back(key.second);
    std::sort(cycles.begin(), cycles.end());
    cycles.erase(std::unique(cycles.begin(), cycles.end()), cycles.end());
    const std::size_t n = cycles.size();
    if (n < 2)
      throw fail(0, "direction " + dir_name(d) + " has " + std::to_string(n) + " cycle (" +
                        list_cycles(cycles) +
                        "): ISO 230-2 needs at least 2 cycles per target and direction (the "
                        "standard asks for 5)");
    runs.x[d].assign(m, std::vector<double>(n, kNaN));
    runs.t[d].assign(m, std::vector<double>(n, kNaN));
    for (std::size_t i = 0; i < m; ++i) {
      std::vector<long> missing;
      for (std::size_t j = 0; j < n; ++j) {
        const auto it = cell[d].find({i, cycles[j]});
        if (it == cell[d].end()) {
          missing.push_back(cycles[j]);
          continue;
        }
        runs.x[d][i][j] = obs[it->second].deviation;
        runs.t[d][i][j] = obs[it->second].time_s;
        if (!std::isfinite(obs[it->second].time_s)) runs.has_time = false;
      }
      for (const IsoObservation& b : blanks)
        if ((b.direction > 0) == (d == kUp) &&
            std::abs(b.position_mm - runs.positions_mm[i]) <= tolerance_mm &&
            std::find(missing.begin(), missing.end(), b.cycle) != missing.end())
          throw InputError(SourceLoc{file, b.line, b.column},
                           "the deviation is empty, but it is the observation of target " +
                               mm(runs.positions_mm[i]) + ", direction " + dir_name(d) +
                               ", cycle " + std::to_string(b.cycle) +
                               " (every target of a direction needs every cycle)");
      if (!missing.empty())
        throw fail(std::max(first_line[d][i], 0),
                   "target " + mm(runs.positions_mm[i]) + ", direction " + dir_name(d) +
                       ": no observation in cycle" + (missing.size() > 1 ? "s " : " ") +
                       list_cycles(missing) + " (every target of a direction needs the " +
                       std::to_string(n) + " cycles " + list_cycles(cycles) + ")");
    }
  }
  return runs;
}

// ---- Columns ---------------------------------------------------------------------------------

IsoColumns iso_columns(const MeasurementTable& table, const std::string& axis,
                       const std::string& deviation_column) {
  IsoColumns c;
  const std::vector<std::string> coords = table.columns_with(ColumnRole::Coordinate);
  auto is_coord = [&](const std::string& name) {
    return std::find(coords.begin(), coords.end(), name) != coords.end();
  };
  if (!axis.empty()) {
    if (!is_coord(axis))
      throw std::invalid_argument(
          "--axis " + axis + ": " + table.file + " has no coordinate column '" + axis +
          "' (coordinate columns: " + (coords.empty() ? std::string("none") : join(coords)) + ")");
    c.axis = axis;
  } else if (table.header_keys.count("axis")) {
    const std::string a = trim(table.header_keys.at("axis"));
    if (!is_coord(a))
      throw InputError(SourceLoc{table.file, table.header_key_lines.at("axis"), 0},
                       "axis: '" + a + "' is not a coordinate column (coordinate columns: " +
                           (coords.empty() ? std::string("none") : join(coords)) + ")");
    c.axis = a;
  } else if (coords.size() == 1) {
    c.axis = coords[0];
  } else if (coords.empty()) {
    throw InputError(SourceLoc{table.file, table.header_line, 0},
                     "no coordinate column (the axis positions, e.g. X in mm)");
  } else {
    std::vector<std::string> varying;
    for (const auto& name : coords) {
      double lo = INFINITY, hi = -INFINITY;
      for (double v : table.column(name))
        if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
      if (hi - lo > 1e-6) varying.push_back(name);
    }
    if (varying.size() != 1)
      throw InputError(SourceLoc{table.file, table.header_line, 0},
                       "several coordinate columns (" + join(coords) + ")" +
                           (varying.empty() ? "" : ", " + join(varying) + " varying") +
                           ": say which axis with --axis or a '# axis: X' header line");
    c.axis = varying[0];
  }

  if (table.has("dir_" + c.axis))
    c.direction = "dir_" + c.axis;
  else if (table.has("dir"))
    c.direction = "dir";
  else
    throw InputError(SourceLoc{table.file, table.header_line, 0},
                     "missing column 'dir' or 'dir_" + c.axis +
                         "' (the approach direction, +1 or -1; columns: " + join(table.columns) +
                         ")");
  table.column("cycle");  // throws when missing
  c.cycle = "cycle";
  if (table.has("t_s")) c.time = "t_s";

  if (!deviation_column.empty()) {
    if (!table.has(deviation_column))
      throw std::invalid_argument("--column " + deviation_column + ": " + table.file +
                                  " has no such column (columns: " + join(table.columns) + ")");
    if (deviation_column == c.axis || deviation_column == c.direction ||
        deviation_column == c.cycle || deviation_column == c.time)
      throw std::invalid_argument("--column " + deviation_column +
                                  ": that column holds the axis position, direction, cycle or "
                                  "time, not a deviation");
    c.deviation = deviation_column;
  } else {
    c.deviation = axis_deviation_column(c.axis);
    if (c.deviation.empty())
      throw std::invalid_argument("axis " + c.axis +
                                  " has no default deviation column: give one with --column");
    table.column(c.deviation);  // throws "missing column" when absent
  }
  c.unit = table.info_of(c.deviation).unit;
  if (c.unit.empty()) c.unit = "um";
  return c;
}

std::vector<IsoObservation> iso_observations(const MeasurementTable& table, const IsoColumns& c) {
  const auto& pos = table.column(c.axis);
  const auto& dir = table.column(c.direction);
  const auto& cyc = table.column(c.cycle);
  const auto& dev = table.column(c.deviation);
  const std::vector<double>* time = c.time.empty() ? nullptr : &table.column(c.time);
  std::vector<IsoObservation> out;
  for (std::size_t r = 0; r < table.rows(); ++r) {
    const int line = table.lines[r];
    if (std::isnan(dev[r])) {
      // Not measured. Kept as a blank when the row names its target, direction and cycle, so
      // that a run missing that observation points at this empty cell.
      if (!std::isnan(pos[r]) && !std::isnan(dir[r]) && !std::isnan(cyc[r]) &&
          std::abs(cyc[r]) <= 1e15) {
        IsoObservation blank;
        blank.position_mm = pos[r];
        blank.direction = dir[r] > 0 ? 1 : -1;
        blank.cycle = static_cast<long>(cyc[r]);
        blank.deviation = kNaN;
        blank.line = line;
        blank.column = table.cell(r, c.deviation).column;
        out.push_back(blank);
      }
      continue;
    }
    auto need = [&](double v, const std::string& name) {
      if (std::isnan(v))
        throw InputError(table.cell(r, name),
                         "column '" + name + "' is empty but '" + c.deviation +
                             "' is measured (every observation needs its position, direction "
                             "and cycle)");
    };
    need(pos[r], c.axis);
    need(dir[r], c.direction);
    need(cyc[r], c.cycle);
    if (std::abs(cyc[r]) > 1e15)
      throw InputError(table.cell(r, c.cycle), "column 'cycle': value out of range");
    IsoObservation o;
    o.position_mm = pos[r];
    o.direction = dir[r] > 0 ? 1 : -1;
    o.cycle = static_cast<long>(cyc[r]);
    o.deviation = dev[r];
    o.time_s = time ? (*time)[r] : kNaN;
    o.line = line;
    o.row = r;
    out.push_back(o);
  }
  return out;
}

// ---- Figures ---------------------------------------------------------------------------------

IsoFigures iso_figures(const std::vector<double>& mean_up, const std::vector<double>& mean_down,
                       const std::vector<double>& s_up, const std::vector<double>& s_down,
                       double k_up, double k_down) {
  const std::size_t m = mean_up.size();
  if (m == 0 || mean_down.size() != m || s_up.size() != m || s_down.size() != m)
    throw std::invalid_argument("iso_figures: need equal-sized, non-empty per-target vectors");
  IsoFigures f;
  f.k_up = k_up;
  f.k_down = k_down;
  f.mean_up = mean_up;
  f.mean_down = mean_down;
  f.s_up = s_up;
  f.s_down = s_down;
  double max_up = -INFINITY, min_up = INFINITY, max_dn = -INFINITY, min_dn = INFINITY;
  double max_bi = -INFINITY, min_bi = INFINITY;
  double a_up_hi = -INFINITY, a_up_lo = INFINITY, a_dn_hi = -INFINITY, a_dn_lo = INFINITY;
  double sum_b = 0;
  for (std::size_t i = 0; i < m; ++i) {
    const double u = mean_up[i], d = mean_down[i];
    f.mean_bi.push_back((u + d) / 2);
    f.B_i.push_back(u - d);
    f.R_i_up.push_back(2 * k_up * s_up[i]);
    f.R_i_down.push_back(2 * k_down * s_down[i]);
    f.R_i.push_back(std::max(
        {k_up * s_up[i] + k_down * s_down[i] + std::abs(u - d), f.R_i_up[i], f.R_i_down[i]}));
    f.B = std::max(f.B, std::abs(u - d));
    sum_b += u - d;
    f.R_up = std::max(f.R_up, f.R_i_up[i]);
    f.R_down = std::max(f.R_down, f.R_i_down[i]);
    f.R = std::max(f.R, f.R_i[i]);
    max_up = std::max(max_up, u), min_up = std::min(min_up, u);
    max_dn = std::max(max_dn, d), min_dn = std::min(min_dn, d);
    max_bi = std::max(max_bi, f.mean_bi[i]), min_bi = std::min(min_bi, f.mean_bi[i]);
    a_up_hi = std::max(a_up_hi, u + k_up * s_up[i]);
    a_up_lo = std::min(a_up_lo, u - k_up * s_up[i]);
    a_dn_hi = std::max(a_dn_hi, d + k_down * s_down[i]);
    a_dn_lo = std::min(a_dn_lo, d - k_down * s_down[i]);
  }
  f.B_mean = sum_b / static_cast<double>(m);
  f.E_up = max_up - min_up;
  f.E_down = max_dn - min_dn;
  f.E = std::max(max_up, max_dn) - std::min(min_up, min_dn);
  f.M = max_bi - min_bi;
  f.A_up = a_up_hi - a_up_lo;
  f.A_down = a_dn_hi - a_dn_lo;
  f.A = std::max(a_up_hi, a_dn_hi) - std::min(a_up_lo, a_dn_lo);
  return f;
}

// ---- Classical evaluation --------------------------------------------------------------------

void Iso230_2Options::validate() const {
  if (!(coverage > 0)) throw std::invalid_argument("ISO 230-2: the coverage factor must be > 0");
}

Iso230_2Evaluation::Iso230_2Evaluation(Iso230_2Options options) : options_(options) {
  options_.validate();
}

Iso230_2Result Iso230_2Evaluation::run(const IsoRuns& runs_) const {
  const std::size_t m = runs_.targets();
  std::array<std::vector<double>, 2> mean, s;
  for (int d = 0; d < 2; ++d) {
    for (std::size_t i = 0; i < m; ++i) {
      mean[d].push_back(sample_mean(runs_.x[d][i]));
      s[d].push_back(sample_sd(runs_.x[d][i]));
    }
  }
  Iso230_2Result result_;
  result_.figures =
      iso_figures(mean[kUp], mean[kDown], s[kUp], s[kDown], options_.coverage, options_.coverage);
  if (options_.student) {
    const double ku = student_coverage_factor(runs_.cycles[kUp].size() - 1, options_.coverage);
    const double kd = student_coverage_factor(runs_.cycles[kDown].size() - 1, options_.coverage);
    result_.student = iso_figures(mean[kUp], mean[kDown], s[kUp], s[kDown], ku, kd);
  }
  return result_;
}

}  // namespace weilgen
