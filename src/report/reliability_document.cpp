#include "weilgen/report/reliability_document.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "weilgen/base/format.hpp"
#include "weilgen/base/version.hpp"
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
      // A table like the seed's Tables 2-4: rows = first grid axis, columns = second.
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
  return {{"weilgen", kVersion},
          {"verb", "reliability"},
          {"model", model_json(model)},
          {"settings",
           {{"method", text.method},
            {"limit", text.limit},
            {"samples", text.samples},
            {"seed", text.seed},
            {"confidence", text.confidence}}},
          {"inputs", inputs_json(model, st.inputs)},
          {"results", results},
          {"summary", summary}};
}

std::string reliability_csv(const Study& st, const ReliabilitySettings& settings,
                            const std::vector<SweepCase>& cases) {
  const auto& errors = st.model->description().errors;
  std::ostringstream c;
  for (const auto& a : st.poses.axes) c << csv_field(a) << ",";
  c << "output,limit,tolerance,tolerance_unit,method,reliability,ci_lo,ci_hi,cov,evaluations";
  for (const auto& e : errors) c << ",dR_dmu_" << e.name;
  for (const auto& e : errors) c << ",dR_dsigma_" << e.name;
  c << "\n";
  for (const auto& x : cases) {
    const auto& r = x.result;
    const OutputId out = st.tolerances[x.tolerance].output;
    for (double v : st.poses.poses[x.pose]) c << csv_number(v) << ",";
    c << output_name(out) << "," << limit_name(settings.limit, out) << ","
      << csv_number(st.tolerances[x.tolerance].value) << "," << output_unit(out) << ","
      << to_string(r.method) << "," << csv_number(r.reliability) << "," << csv_number(r.ci_lo)
      << "," << csv_number(r.ci_hi) << "," << csv_number(r.cov) << "," << r.evaluations;
    for (std::size_t i = 0; i < errors.size(); ++i)
      c << "," << csv_number(i < r.dR_dmu.size() ? r.dR_dmu[i] : NAN);
    for (std::size_t i = 0; i < errors.size(); ++i)
      c << "," << csv_number(i < r.dR_dsigma.size() ? r.dR_dsigma[i] : NAN);
    c << "\n";
  }
  return c.str();
}

std::vector<Panel> reliability_panels(const Study& st, const std::vector<SweepCase>& cases) {
  std::vector<Panel> panels;
  const auto& g = st.poses;
  const std::size_t np = g.poses.size();
  for (std::size_t k = 0; k < st.tolerances.size(); ++k) {
    std::vector<double> r;
    for (const auto& c : cases)
      if (c.tolerance == k) r.push_back(100 * c.result.reliability);
    const std::string title = std::string("R(") + output_name(st.tolerances[k].output) +
                              ") %, t = " + st.tolerances[k].text;
    if (g.grid_axes.size() == 2 && g.grid_size() == np) {
      HeatMap h;
      h.title = title;
      h.ylabel = g.axes[g.grid_axes[0]] + " (" + g.units[g.grid_axes[0]] + ")";
      h.xlabel = g.axes[g.grid_axes[1]] + " (" + g.units[g.grid_axes[1]] + ")";
      h.zlabel = "R (%)";
      h.y = g.grid_values[0];
      h.x = g.grid_values[1];
      h.z = r;  // row-major over (first axis, second axis) = z[iy * nx + ix]
      panels.push_back(h);
    } else if (g.grid_axes.size() == 1 && g.grid_size() == np) {
      LinePlot l;
      l.title = title;
      l.xlabel = g.axes[g.grid_axes[0]] + " (" + g.units[g.grid_axes[0]] + ")";
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
