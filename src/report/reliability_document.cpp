#include "weilgen/report/reliability_document.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "weilgen/base/format.hpp"
#include "weilgen/report/csv_table.hpp"
#include "weilgen/report/json_common.hpp"

namespace weilgen {

std::string reliability_text(const Study& st, const ReliabilitySettings& settings,
                             const std::vector<SweepCase>& cases, std::size_t top) {
  std::ostringstream os;
  const Model& model = *st.model;
  const auto& errors = model.description().errors;
  const auto sums = summarize(st, cases);
  const std::size_t np = st.poses.poses.size();
  os << "weilgen reliability: " << model.name() << " (order " << model.order() << ", "
     << model.origin() << "), " << np << " pose" << (np > 1 ? "s" : "") << "\n";
  for (std::size_t k = 0; k < st.tolerances.size(); ++k) {
    const auto& tol = st.tolerances[k];
    std::vector<const SweepCase*> mine;
    for (const auto& c : cases)
      if (c.tolerance == k) mine.push_back(&c);
    const ReliabilityResult& first = mine.front()->result;
    os << "\n"
       << output_name(tol.output) << ": " << limit_name(settings.limit, tol.output)
       << ", tolerance " << tol.text << ", method " << to_string(first.method) << " (R in %)\n";
    const auto& g = st.poses;
    if (g.grid_axes.size() == 2 && g.grid_size() == np) {
      // A table like Wang & Yuan 2021, Tables 2-4: rows = first grid axis, columns = second.
      const auto& rows = g.grid_values[0];
      const auto& cols = g.grid_values[1];
      std::ostringstream h;
      h << std::setw(12) << (g.axes[g.grid_axes[0]] + " \\ " + g.axes[g.grid_axes[1]]);
      for (double c : cols) h << std::setw(10) << format_number(c);
      os << h.str() << "\n";
      for (std::size_t r = 0; r < rows.size(); ++r) {
        std::ostringstream line;
        line << std::setw(12) << format_number(rows[r]) << std::fixed << std::setprecision(3);
        for (std::size_t c = 0; c < cols.size(); ++c)
          line << std::setw(10) << 100 * mine[r * cols.size() + c]->result.reliability;
        os << line.str() << "\n";
      }
    } else {
      for (const SweepCase* c : mine) {
        std::ostringstream line;
        line << "  " << std::left << std::setw(32) << pose_label(g, c->pose) << std::right
             << std::fixed << std::setprecision(3) << std::setw(9) << 100 * c->result.reliability
             << "  [" << 100 * c->result.ci_lo << ", " << 100 * c->result.ci_hi << "]";
        os << line.str() << "\n";
      }
    }
    os << std::fixed << std::setprecision(3) << "  min " << 100 * sums[k].min << " % at "
       << pose_label(g, sums[k].argmin) << ", mean " << 100 * sums[k].mean << " %\n";
    os << "  most sensitive errors (mean |dR/dsigma|*sigma, percentage points):";
    const auto ranked = ranked_sensitivity(cases, k, st.inputs);
    for (std::size_t i = 0; i < std::min(top, ranked.size()); ++i)
      if (ranked[i].second > 0)
        os << " " << errors[ranked[i].first].name << " " << std::setprecision(3)
           << 100 * ranked[i].second;
    os << std::defaultfloat << "\n";
    for (const SweepCase* c : mine)
      if (!c->result.note.empty() && c->result.method != ReliabilityMethod::Exact) {
        os << "  note at " << pose_label(g, c->pose) << ": " << c->result.note << "\n";
        break;
      }
  }
  return os.str();
}

nlohmann::json reliability_json(const Study& st, const ReliabilitySettings& settings,
                                const ReliabilitySettingsText& text,
                                const std::vector<SweepCase>& cases) {
  const Model& model = *st.model;
  const auto& errors = model.description().errors;
  const auto sums = summarize(st, cases);
  nlohmann::json results = nlohmann::json::array(), summary = nlohmann::json::array();
  for (const auto& c : cases) {
    const auto& r = c.result;
    nlohmann::json mu = nlohmann::json::object(), sg = nlohmann::json::object();
    for (std::size_t i = 0; i < errors.size(); ++i) {
      mu[errors[i].name] = json_number(i < r.dR_dmu.size() ? r.dR_dmu[i] : NAN);
      sg[errors[i].name] = json_number(i < r.dR_dsigma.size() ? r.dR_dsigma[i] : NAN);
    }
    nlohmann::json betas = nlohmann::json::array();
    for (const auto& d : r.design_points) betas.push_back(json_number(d.beta));
    const OutputId out = st.tolerances[c.tolerance].output;
    results.push_back({{"pose", pose_json(st.poses, c.pose)},
                       {"output", output_name(out)},
                       {"limit", limit_name(settings.limit, out)},
                       {"tolerance", st.tolerances[c.tolerance].value},
                       {"tolerance_unit", output_unit(out)},
                       {"method", to_string(r.method)},
                       {"reliability", r.reliability},
                       {"ci", {r.ci_lo, r.ci_hi}},
                       {"cov", r.cov},
                       {"beta", betas},
                       {"evaluations", r.evaluations},
                       {"note", r.note},
                       {"dR_dmu", mu},
                       {"dR_dsigma", sg}});
  }
  for (std::size_t k = 0; k < st.tolerances.size(); ++k) {
    const auto ranked = ranked_sensitivity(cases, k, st.inputs);
    nlohmann::json ranking = nlohmann::json::array();
    for (const auto& [i, v] : ranked) ranking.push_back({{"error", errors[i].name}, {"value", v}});
    summary.push_back({{"output", output_name(st.tolerances[k].output)},
                       {"limit", limit_name(settings.limit, st.tolerances[k].output)},
                       {"tolerance", st.tolerances[k].value},
                       {"tolerance_unit", output_unit(st.tolerances[k].output)},
                       {"min", sums[k].min},
                       {"mean", sums[k].mean},
                       {"argmin", pose_json(st.poses, sums[k].argmin)},
                       {"sensitivity", ranking}});
  }
  // R is a probability: dR/dmu_i and dR/dsigma_i are per base unit of error i (mm or rad).
  nlohmann::json units = nlohmann::json::object();
  for (const auto& e : errors) units[e.name] = std::string("1/") + e.base_unit();
  return json_document("reliability", {{"model", model_json(model)},
                                       {"derivative_units", units},
                                       {"settings",
                                        {{"method", text.method},
                                         {"limit", text.limit},
                                         {"samples", text.samples},
                                         {"seed", text.seed},
                                         {"confidence", text.confidence}}},
                                       {"inputs", inputs_json(model, st.inputs)},
                                       {"results", results},
                                       {"summary", summary}});
}

std::string reliability_csv(const Study& st, const ReliabilitySettings& settings,
                            const std::vector<SweepCase>& cases) {
  const auto& errors = st.model->description().errors;
  CsvTable t;
  t.pose_columns(st.poses);
  for (const char* c : {"output", "limit", "tolerance", "tolerance_unit", "method", "reliability",
                        "ci_lo", "ci_hi", "cov", "evaluations"})
    t.column(c);
  // R is a probability (unit 1): dR/dmu_i and dR/dsigma_i are per base unit of error i.
  for (const auto& e : errors) t.column("dR_dmu_" + e.name, std::string("1/") + e.base_unit());
  for (const auto& e : errors) t.column("dR_dsigma_" + e.name, std::string("1/") + e.base_unit());
  for (const auto& x : cases) {
    const auto& r = x.result;
    const OutputId out = st.tolerances[x.tolerance].output;
    t.pose(st.poses.poses[x.pose]).text(output_name(out)).text(limit_name(settings.limit, out));
    t.number(st.tolerances[x.tolerance].value).text(output_unit(out)).text(to_string(r.method));
    t.number(r.reliability).number(r.ci_lo).number(r.ci_hi).number(r.cov).count(r.evaluations);
    for (std::size_t i = 0; i < errors.size(); ++i)
      t.number(i < r.dR_dmu.size() ? r.dR_dmu[i] : NAN);
    for (std::size_t i = 0; i < errors.size(); ++i)
      t.number(i < r.dR_dsigma.size() ? r.dR_dsigma[i] : NAN);
    t.end_row();
  }
  return t.str();
}

namespace {

// Slices of a grid with more than two varying axes: one per value combination of the axes
// before the last two.
std::size_t grid_slices(const PoseSet& g) {
  std::size_t n = 1;
  for (std::size_t a = 0; a + 2 < g.grid_values.size(); ++a) n *= g.grid_values[a].size();
  return n;
}

std::string axis_label(const PoseSet& g, std::size_t k) {
  return g.axes[g.grid_axes[k]] + " (" + g.units[g.grid_axes[k]] + ")";
}

}  // namespace

void check_reliability_plot(const Study& st) {
  const PoseSet& g = st.poses;
  if (g.grid_axes.size() <= 2 || g.grid_size() != g.poses.size()) return;
  const std::size_t panels = grid_slices(g) * st.tolerances.size();
  if (panels > kMaxReliabilityPanels)
    throw std::invalid_argument(
        "--plot: a grid of " + std::to_string(g.grid_axes.size()) + " varying axes gives " +
        std::to_string(panels) +
        " heat maps (one per value of the axes before the last two, per "
        "toleranced output), more than " +
        std::to_string(kMaxReliabilityPanels) +
        " in one figure: plot fewer values of the first axes, or read the table (--csv)");
}

std::vector<Panel> reliability_panels(const Study& st, const std::vector<SweepCase>& cases) {
  std::vector<Panel> panels;
  const auto& g = st.poses;
  const std::size_t np = g.poses.size();
  const std::size_t na = g.grid_axes.size();
  const bool whole_grid = g.grid_size() == np;
  for (std::size_t k = 0; k < st.tolerances.size(); ++k) {
    std::vector<double> r;
    for (const auto& c : cases)
      if (c.tolerance == k) r.push_back(100 * c.result.reliability);
    const std::string title = std::string("R(") + output_name(st.tolerances[k].output) +
                              ") %, t = " + st.tolerances[k].text;
    if (na >= 2 && whole_grid) {
      // Small multiples over the last two axes (one panel for a two-axis grid); one colour
      // scale for all of them.
      const auto& ys = g.grid_values[na - 2];
      const auto& xs = g.grid_values[na - 1];
      const std::size_t block = ys.size() * xs.size();
      for (std::size_t s = 0; s < grid_slices(g); ++s) {
        HeatMap h;
        h.title = title;
        std::size_t rest = s;
        std::string where;
        for (std::size_t a = na - 2; a-- > 0;) {
          const std::size_t n = g.grid_values[a].size();
          where = g.axes[g.grid_axes[a]] + "=" + format_number(g.grid_values[a][rest % n]) +
                  (where.empty() ? "" : " ") + where;
          rest /= n;
        }
        if (!where.empty()) h.title += ", " + where;
        h.ylabel = axis_label(g, na - 2);
        h.xlabel = axis_label(g, na - 1);
        h.zlabel = "R (%)";
        h.y = ys;
        h.x = xs;
        // Row-major over the grid axes: the last two vary fastest, z[iy * nx + ix].
        h.z.assign(r.begin() + static_cast<std::ptrdiff_t>(s * block),
                   r.begin() + static_cast<std::ptrdiff_t>((s + 1) * block));
        if (grid_slices(g) > 1) {
          double lo = INFINITY, hi = -INFINITY;
          for (double v : r)
            if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
          if (hi > lo) h.zmin = lo, h.zmax = hi;
        }
        panels.push_back(h);
      }
    } else if (na == 1 && whole_grid) {
      LinePlot l;
      l.title = title;
      l.xlabel = axis_label(g, 0);
      l.ylabel = "R (%)";
      l.x = g.grid_values[0];
      l.lines.push_back({"R", r});
      panels.push_back(l);
    } else {
      BarChart b;
      b.title = title;
      b.ylabel = "R (%)";
      for (std::size_t p = 0; p < np; ++p) b.categories.push_back(pose_label(g, p));
      b.series.push_back({"R", r, {}, {}});
      panels.push_back(b);
    }
  }
  return panels;
}

}  // namespace weilgen
