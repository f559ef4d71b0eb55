// weilgen reliability: P(deviation within tolerance) per pose and output, its sensitivities
// to every error's mean and spread, and grid summaries. docs/reliability.md.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "reliability_sweep.hpp"
#include "verbs.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/report/plot.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

namespace {

// Errors ranked by the mean over poses of |dR/dsigma_i| * sigma_i (the change of R when the
// spread changes by 100 %), for one output.
std::vector<std::pair<std::size_t, double>> ranked_sensitivity(
    const std::vector<SweepCase>& cases, std::size_t tolerance,
    const std::vector<InputDistribution>& inputs) {
  std::vector<double> s(inputs.size(), 0.0);
  std::size_t n = 0;
  for (const auto& c : cases) {
    if (c.tolerance != tolerance) continue;
    ++n;
    for (std::size_t i = 0; i < inputs.size() && i < c.result.dR_dsigma.size(); ++i)
      s[i] += std::abs(c.result.dR_dsigma[i]) * inputs[i].stddev();
  }
  std::vector<std::pair<std::size_t, double>> r;
  for (std::size_t i = 0; i < s.size(); ++i) r.push_back({i, n ? s[i] / n : 0.0});
  std::stable_sort(r.begin(), r.end(), [](auto& a, auto& b) { return a.second > b.second; });
  return r;
}

}  // namespace

int verb_reliability(const Args& args) {
  po::options_description opts(
      "weilgen reliability <machine> (--grid ...|--at ...) --tolerance dx=0.03mm [options]\n\n"
      "Machining-accuracy reliability R = P(deviation within tolerance) at every pose for every\n"
      "toleranced output, with dR/dmu and dR/dsigma for every error and per-output min/mean.\n"
      "Limit states: two-sided |d| <= t (default), one-sided d <= t (as in the grinder seed),\n"
      "radial |(dx,dy,dz)| <= t (the output dp). Methods: exact (linear output, Gaussian\n"
      "errors), form (HL-RF), is (axis-orthogonal importance sampling at the design points),\n"
      "mc (crude Monte Carlo); auto = exact where it is exact, else is.\n\nOptions");
  StudyFlags f;
  ReliabilityFlags rf;
  std::size_t top = 5;
  opts.add_options()("help,h", "show this help")("top",
                                                 po::value<std::size_t>(&top)->default_value(top),
                                                 "sensitive errors listed per output");
  add_reliability_options(opts, rf);
  add_study_options(opts, f, true);
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("reliability", args, opts, "machine", 1, vm))
    return *stop;
  if (vm.count("machine")) f.machine = vm["machine"].as<std::string>();
  auto [limit, sens, ro] = parse_reliability_flags(rf, f.seed);
  if (!f.plot.empty()) check_plot_target(f.plot);  // before a long run, not after
  const Study st = open_study(f, true);
  ro.threads = st.threads;
  const Model& model = *st.model;
  const auto& errors = model.description().errors;
  const auto cases = reliability_sweep(st, st.inputs, limit, ro, sens, f.quiet);
  const auto sums = summarize(st, cases);
  const std::size_t np = st.poses.poses.size();

  std::cout << "weilgen reliability: " << model.name() << " (order " << model.order() << ", "
            << model.origin() << "), " << np << " pose" << (np > 1 ? "s" : "") << "\n";
  for (std::size_t k = 0; k < st.tolerances.size(); ++k) {
    const auto& tol = st.tolerances[k];
    std::vector<const SweepCase*> mine;
    for (const auto& c : cases)
      if (c.tolerance == k) mine.push_back(&c);
    const ReliabilityResult& first = mine.front()->result;
    std::cout << "\n"
              << output_name(tol.output) << ": " << limit_name(limit, tol.output) << ", tolerance "
              << tol.text << ", method " << to_string(first.method) << " (R in %)\n";
    const auto& g = st.poses;
    if (g.grid_axes.size() == 2 && g.grid_size() == np) {
      // A table like the seed's Tables 2-4: rows = first grid axis, columns = second.
      const auto& rows = g.grid_values[0];
      const auto& cols = g.grid_values[1];
      std::ostringstream h;
      h << std::setw(12) << (g.axes[g.grid_axes[0]] + " \\ " + g.axes[g.grid_axes[1]]);
      for (double c : cols) h << std::setw(10) << format_number(c);
      std::cout << h.str() << "\n";
      for (std::size_t r = 0; r < rows.size(); ++r) {
        std::ostringstream line;
        line << std::setw(12) << format_number(rows[r]) << std::fixed << std::setprecision(3);
        for (std::size_t c = 0; c < cols.size(); ++c)
          line << std::setw(10) << 100 * mine[r * cols.size() + c]->result.reliability;
        std::cout << line.str() << "\n";
      }
    } else {
      for (const SweepCase* c : mine) {
        std::ostringstream line;
        line << "  " << std::left << std::setw(32) << pose_label(g, c->pose) << std::right
             << std::fixed << std::setprecision(3) << std::setw(9) << 100 * c->result.reliability
             << "  [" << 100 * c->result.ci_lo << ", " << 100 * c->result.ci_hi << "]";
        std::cout << line.str() << "\n";
      }
    }
    std::cout << std::fixed << std::setprecision(3) << "  min " << 100 * sums[k].min << " % at "
              << pose_label(g, sums[k].argmin) << ", mean " << 100 * sums[k].mean << " %\n";
    std::cout << "  most sensitive errors (mean |dR/dsigma|*sigma, percentage points):";
    const auto ranked = ranked_sensitivity(cases, k, st.inputs);
    for (std::size_t i = 0; i < std::min(top, ranked.size()); ++i)
      if (ranked[i].second > 0)
        std::cout << " " << errors[ranked[i].first].name << " " << std::setprecision(3)
                  << 100 * ranked[i].second;
    std::cout << std::defaultfloat << "\n";
    for (const SweepCase* c : mine)
      if (!c->result.note.empty() && c->result.method != ReliabilityMethod::Exact) {
        std::cout << "  note at " << pose_label(g, c->pose) << ": " << c->result.note << "\n";
        break;
      }
  }

  if (!f.json.empty()) {
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
                         {"limit", limit_name(limit, out)},
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
      for (const auto& [i, v] : ranked)
        ranking.push_back({{"error", errors[i].name}, {"value", v}});
      summary.push_back({{"output", output_name(st.tolerances[k].output)},
                         {"limit", limit_name(limit, st.tolerances[k].output)},
                         {"tolerance", st.tolerances[k].value},
                         {"tolerance_unit", output_unit(st.tolerances[k].output)},
                         {"min", sums[k].min},
                         {"mean", sums[k].mean},
                         {"argmin", pose_json(st.poses, sums[k].argmin)},
                         {"sensitivity", ranking}});
    }
    nlohmann::json j = {{"weilgen", kVersion},
                        {"verb", "reliability"},
                        {"model", model_json(model)},
                        {"settings",
                         {{"method", rf.method},
                          {"limit", rf.limit},
                          {"samples", rf.samples},
                          {"seed", f.seed},
                          {"confidence", rf.confidence}}},
                        {"inputs", inputs_json(model, st.inputs)},
                        {"results", results},
                        {"summary", summary}};
    write_output(f.json, j.dump(1) + "\n");
  }
  if (!f.csv.empty()) {
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
      c << output_name(out) << "," << limit_name(limit, out) << ","
        << csv_number(st.tolerances[x.tolerance].value) << "," << output_unit(out) << ","
        << to_string(r.method) << "," << csv_number(r.reliability) << "," << csv_number(r.ci_lo)
        << "," << csv_number(r.ci_hi) << "," << csv_number(r.cov) << "," << r.evaluations;
      for (std::size_t i = 0; i < errors.size(); ++i)
        c << "," << csv_number(i < r.dR_dmu.size() ? r.dR_dmu[i] : NAN);
      for (std::size_t i = 0; i < errors.size(); ++i)
        c << "," << csv_number(i < r.dR_dsigma.size() ? r.dR_dsigma[i] : NAN);
      c << "\n";
    }
    write_output(f.csv, c.str());
  }
  if (!f.plot.empty()) {
    std::vector<Panel> panels;
    const auto& g = st.poses;
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
    write_plot(f.plot, panels, "weilgen reliability: " + model.name());
  }
  return 0;
}

}  // namespace weilgen::cli
