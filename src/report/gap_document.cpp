#include "weilgen/report/gap_document.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <set>
#include <sstream>

#include "weilgen/base/format.hpp"
#include "weilgen/measure/measurement_csv.hpp"
#include "weilgen/report/csv_table.hpp"
#include "weilgen/report/json_common.hpp"

namespace weilgen {

namespace {

using nlohmann::json;

std::string f3(double v) { return std::isfinite(v) ? format_short(v) : "-"; }

json region_json(const GapRegion& g) {
  return {{"by", g.by},
          {"output", g.output},
          {"unit", g.unit},
          {"same_as", g.same_as},
          {"explained", json_number(g.explained)},
          {"source", g.source},
          {"from", json_number(g.from)},
          {"to", json_number(g.to)},
          {"n", g.n},
          {"rms_um", json_number(g.rms_um)},
          {"excess_um", json_number(g.excess_um)},
          {"p_value", json_number(g.p_value)},
          {"significant", g.significant}};
}

json per_output_json(const std::array<double, kObservationKinds>& v,
                     const std::array<std::size_t, kObservationKinds>& count) {
  json j = json::object();
  for (std::size_t o = 0; o < kObservationKinds; ++o)
    if (count[o]) j[observation_name(o)] = json_number(v[o]);
  return j;
}

json effect_json(const EffectFit& e, const std::array<std::size_t, kObservationKinds>& count) {
  json params = json::object();
  for (const auto& [k, v] : e.params) params[k] = json_number(v);
  json j = {{"name", e.name},
            {"variant", e.variant},
            {"summary", e.summary},
            {"params", params},
            {"extra_parameters", e.extra_parameters},
            {"tested_variants", e.tested_variants},
            {"heldout_rms_before_um", json_number(e.heldout_rms_before_um)},
            {"heldout_rms_after_um", json_number(e.heldout_rms_after_um)},
            {"heldout_rms_before_per_output_um", per_output_json(e.rms_before, count)},
            {"heldout_rms_after_per_output_um", per_output_json(e.rms_after, count)},
            {"shrink_pct", json_number(e.shrink_pct)},
            {"explained_fraction", json_number(e.explained_fraction)},
            {"f_statistic", json_number(e.f_statistic)},
            {"p_value", json_number(e.p_value)},
            {"significant", e.significant}};
  if (e.region) j["region"] = region_json(*e.region);
  if (e.shape_dof_free || e.shape_dof_used)
    j["shape_dof"] = {{"free", e.shape_dof_free}, {"used", e.shape_dof_used}};
  j["distinguishable"] = e.distinguishable;
  if (e.terms) j["shape_terms"] = {{"fitted", e.terms}, {"absorbed", e.terms_absorbed}};
  return j;
}

// Why the verdict cannot name it: too many shape degrees of freedom used, else the effect's own
// reason (a bump narrower than the sampling, a tool offset no tool has).
std::string not_distinguishable(const EffectFit& e) {
  if (e.shape_dof_free == 0 || e.shape_dof_used < e.shape_dof_free)
    return e.indistinct_reason.empty() ? "" : " (" + e.indistinct_reason + ")";
  return " (needs " + std::to_string(e.shape_dof_used) + " shape degrees of freedom where the " +
         "data leave " + std::to_string(e.shape_dof_free) + ": any shape fits)";
}

// What a candidate's row says: its fit when significant; a rejected candidate's parameters
// are whatever least squares made of noise (a tool offset of -2.6e5 mm) and are not shown.
std::string candidate_text(const EffectFit& e) {
  if (!e.significant) return "not significant";
  return e.summary + (e.distinguishable ? "" : not_distinguishable(e));
}

}  // namespace

std::string gap_csv(const GapResult& r, const std::string& data) {
  CsvTable t;
  t.comment("weilgen gap " + data + ": candidate effects in ranking order (held-out " + r.holdout +
            ")");
  t.column("rank");
  t.column("effect");
  t.column("variant");
  t.column("extra_parameters");
  t.column("heldout_rms_before", "um");
  t.column("heldout_rms_after", "um");
  t.column("shrink", "%");
  for (const char* c :
       {"explained_fraction", "f_statistic", "p_value", "significant", "in_explanation", "summary"})
    t.column(c);
  for (std::size_t k = 0; k < r.effects.size(); ++k) {
    const EffectFit& e = r.effects[k];
    bool explains = false;
    for (const EffectFit& x : r.explanation) explains = explains || x.name == e.name;
    t.count(k + 1).text(e.name).text(e.variant).count(e.extra_parameters);
    t.number(e.heldout_rms_before_um).number(e.heldout_rms_after_um).number(e.shrink_pct);
    t.number(e.explained_fraction).number(e.f_statistic).number(e.p_value);
    t.text(e.significant ? "yes" : "no").text(explains ? "yes" : "no").text(candidate_text(e));
    t.end_row();
  }
  return t.str();
}

nlohmann::json gap_json(const GapResult& r, const Model& model, const std::string& data) {
  json where = json::array(), effects = json::array(), expl = json::array(), names = json::array();
  for (const GapRegion& g : r.where) where.push_back(region_json(g));
  for (const EffectFit& e : r.effects) effects.push_back(effect_json(e, r.count));
  for (const EffectFit& e : r.explanation)
    expl.push_back(effect_json(e, r.count)), names.push_back(e.name);
  json outliers = json::array();
  for (const GapOutlier& g : r.outliers)
    outliers.push_back({{"observation", g.observation},
                        {"line", g.line},
                        {"output", g.output},
                        {"value_um", g.value_um},
                        {"residual_um", g.residual_um},
                        {"robust_sigmas", g.sigmas}});
  return json_document("gap",
                       {{"model", model_json(model)},
                        {"outliers", outliers},
                        {"data", data},
                        {"baseline",
                         {{"holdout", r.holdout},
                          {"holdout_reason", r.holdout_reason},
                          {"observations", r.observations},
                          {"parameters", r.parameters},
                          {"rank", r.rank},
                          {"heldout_rms_um", per_output_json(r.baseline.rms, r.count)},
                          {"heldout_max_um", per_output_json(r.baseline.max, r.count)},
                          {"heldout_rms_all_um", json_number(r.baseline.rms_um)},
                          {"heldout_rms_ideal_um", per_output_json(r.baseline.ideal, r.count)},
                          {"excess_um", json_number(r.baseline.excess_um)},
                          {"p_value", json_number(r.baseline.p_value)},
                          {"lack_of_fit_p_value", json_number(r.baseline_lack_of_fit_p)},
                          {"lack_of_fit_along", r.baseline_lack_of_fit_along}}},
                        {"noise_floor_um", json_number(r.noise.sigma_um)},
                        {"noise_floor_source", r.noise.source},
                        {"noise_floor_detail", r.noise.detail},
                        {"noise_floor_per_output_um", per_output_json(r.noise.per_output, r.count)},
                        {"where", where},
                        {"effects", effects},
                        {"verdict",
                         {{"effect", r.verdict.str()},
                          {"reason", r.verdict.reason},
                          {"explanation", names},
                          {"steps", expl},
                          {"heldout_rms_after_um", per_output_json(r.final.rms, r.count)},
                          {"heldout_rms_after_all_um", json_number(r.final.rms_um)},
                          {"heldout_rms_ideal_um", per_output_json(r.final.ideal, r.count)},
                          {"heldout_rms_ideal_all_um", json_number(r.final.ideal_um)},
                          {"remaining_excess_um", json_number(r.final.excess_um)},
                          {"remaining_p_value", json_number(r.final.p_value)}}}});
}

std::string gap_text(const GapResult& r, const Model& model, const std::string& data,
                     bool markdown) {
  std::ostringstream os;
  const char* h2 = markdown ? "## " : "";
  os << (markdown ? "# " : "") << "Gap diagnosis: " << model.name() << " against " << data
     << "\n\n";
  os << "Verdict: " << (markdown ? "**" : "") << r.verdict.str() << (markdown ? "**" : "");
  if (!r.explanation.empty()) {
    os << " (";
    for (std::size_t i = 0; i < r.explanation.size(); ++i)
      os << (i ? ", then " : "") << r.explanation[i].summary;
    os << ")";
  }
  os << "\n"
     << (markdown ? "\n" : "") << "Why: " << r.verdict.reason << ".\n\n"
     << h2 << "Baseline\n\n";
  if (!r.outliers.empty()) {
    os << r.outliers.size() << " gross reading" << (r.outliers.size() > 1 ? "s" : "")
       << " removed before the diagnosis (beyond max(6, z_n) robust standard deviations and "
          "unlike their neighbours):\n";
    for (const GapOutlier& g : r.outliers)
      os << (markdown ? "- " : "  ") << "line " << g.line << ", " << g.output << " "
         << f3(g.value_um) << " (residual " << f3(g.residual_um) << ", " << f3(g.sigmas)
         << " sigma)\n";
    os << "\n";
  }
  os << "identified on the training part, predicted on the held-out part (" << r.holdout << "; "
     << r.holdout_reason << "): " << r.observations << " observations, " << r.parameters
     << " parameters (rank " << r.rank << ").\n";
  os << "noise floor " << f3(r.noise.sigma_um) << " µm (" << r.noise.source << ": "
     << r.noise.detail << ")\n";
  os << "held-out gap: RMS " << f3(r.baseline.rms_um) << " µm, excess over the floor "
     << f3(r.baseline.excess_um) << " µm, p = " << f3(r.baseline.p_value)
     << "; lack of fit on all data p = " << f3(r.baseline_lack_of_fit_p)
     << (r.baseline_lack_of_fit_along.empty() ? ""
                                              : " (along " + r.baseline_lack_of_fit_along + ")")
     << "\n\n";
  if (markdown)
    os << "| output | held-out RMS before | max | after the explanation |\n|---|---|---|---|\n";
  else
    os << "output  held-out rms  max      after\n";
  for (std::size_t o = 0; o < kObservationKinds; ++o) {
    if (!r.count[o]) continue;
    if (markdown)
      os << "| " << observation_name(o) << " | " << f3(r.baseline.rms[o]) << " | "
         << f3(r.baseline.max[o]) << " | " << f3(r.final.rms[o]) << " |\n";
    else
      os << std::left << std::setw(8) << observation_name(o) << std::right << std::setw(12)
         << f3(r.baseline.rms[o]) << std::setw(9) << f3(r.baseline.max[o]) << std::setw(11)
         << f3(r.final.rms[o]) << "  " << observation_unit(o) << "\n";
  }
  os << "\n" << h2 << "Where\n\n";
  std::size_t shown = 0;
  for (const GapRegion& g : r.where) {
    if (!g.significant || shown == 12) break;
    ++shown;
    os << (markdown ? "- " : "  ") << g.output;
    if (g.by != "output") {
      os << " along " << g.by;
      for (const std::string& s : g.same_as) os << " (= " << s << ")";
      os << " " << f3(g.from) << " .. " << f3(g.to) << (g.unit.empty() ? "" : " " + g.unit);
    }
    os << ": RMS " << f3(g.rms_um) << ", excess " << f3(g.excess_um) << " over the floor (n "
       << g.n;
    if (g.by != "output" && g.source == "residual")
      os << "; the dimension explains " << f3(100 * g.explained) << " % of the residual";
    if (g.source == "effect") os << "; where the accepted effect acts";
    os << ", p " << f3(g.p_value) << ")\n";
  }
  if (!shown) os << (markdown ? "- " : "  ") << "no region above the noise floor\n";
  os << "\n" << h2 << "Which effect\n\n";
  if (markdown)
    os << "| effect | fit | held-out RMS before → after (µm) | shrink | p (corrected) | "
          "significant |\n|---|---|---|---|---|---|\n";
  for (const EffectFit& e : r.effects) {
    if (markdown)
      os << "| " << e.name << " | " << candidate_text(e) << " | " << f3(e.heldout_rms_before_um)
         << " → " << f3(e.heldout_rms_after_um) << " | " << f3(e.shrink_pct) << " % | "
         << f3(e.p_value) << " | " << (e.significant ? "yes" : "no") << " |\n";
    else
      os << "  " << std::left << std::setw(14) << e.name << std::right << std::setw(8)
         << f3(e.heldout_rms_after_um) << " µm (" << std::setw(6) << f3(e.shrink_pct) << " %)  p "
         << std::setw(8) << f3(e.p_value) << (e.significant ? "  *  " : "     ")
         << candidate_text(e) << "\n";
  }
  os << "\n" << h2 << "How far it shrinks\n\n";
  os << "held-out RMS " << f3(r.baseline.rms_um) << " → " << f3(r.final.rms_um) << " µm ("
     << f3(100 * (1 - r.final.rms_um / r.baseline.rms_um)) << " %); remaining excess over the "
     << "floor " << f3(r.final.excess_um) << " µm (p " << f3(r.final.p_value) << "); a right "
     << "model would leave " << f3(r.final.ideal_um)
     << " µm (the floor with the folds' prediction error)\n";
  return os.str();
}

namespace {

// RMS of the held-out residual per bin of a coordinate, before and after.
LinePlot residual_plot(const GapData& d, const GapResult& r, const std::string& by) {
  LinePlot p;
  p.title = "held-out residual RMS along " + by;
  // In the dimension's unit: the machine's for a coordinate, else the data format's (degC, 1/min).
  std::string unit = classify_column(by, ReadOptions{}).unit;
  for (std::size_t a = 0; a < d.axes.size() && a < d.axis_units.size(); ++a)
    if (d.axes[a] == by) unit = d.axis_units[a];
  p.xlabel = by == "t_s" ? "t" : by;
  if (!unit.empty()) p.xlabel += " (" + unit + ")";
  p.ylabel = "RMS (µm)";
  const auto& obs = d.points.observations;
  std::vector<std::pair<double, std::size_t>> key;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    double v = NAN;
    if (by == "t_s") v = d.time_s[obs[i].row];
    for (std::size_t a = 0; a < d.axes.size(); ++a)
      if (d.axes[a] == by) v = d.points.poses[obs[i].row][a];
    if (d.temperature.count(by)) v = d.temperature.at(by)[obs[i].row];
    if (d.covariate.count(by)) v = d.covariate.at(by)[obs[i].row];
    if (std::isfinite(v) && std::isfinite(r.residual_before[i])) key.push_back({v, i});
  }
  std::sort(key.begin(), key.end());
  // Bins: each distinct value when there are few (rpm steps, directions), else 40 of equal count.
  std::vector<std::size_t> edges = {0};
  std::size_t distinct = 0;
  for (std::size_t k = 0; k < key.size(); ++k)
    if (k == 0 || key[k].first != key[k - 1].first) ++distinct;
  if (distinct <= 12) {
    for (std::size_t k = 1; k < key.size(); ++k)
      if (key[k].first != key[k - 1].first) edges.push_back(k);
  } else {
    for (std::size_t b = 1; b < 40; ++b) edges.push_back(b * key.size() / 40);
  }
  edges.push_back(key.size());
  std::vector<double> before, after;
  for (std::size_t b = 0; b + 1 < edges.size(); ++b) {
    const std::size_t lo = edges[b], hi = edges[b + 1];
    if (hi == lo) continue;
    double sb = 0, sa = 0, x = 0;
    for (std::size_t k = lo; k < hi; ++k) {
      sb += r.residual_before[key[k].second] * r.residual_before[key[k].second];
      sa += r.residual_after[key[k].second] * r.residual_after[key[k].second];
      x += key[k].first;
    }
    const double n = static_cast<double>(hi - lo);
    p.x.push_back(x / n);
    before.push_back(std::sqrt(sb / n));
    after.push_back(std::sqrt(sa / n));
  }
  // Without an accepted effect "after" is "before": one line, not two on top of each other.
  p.lines = {{"baseline", before}};
  if (!r.explanation.empty()) p.lines.push_back({"with the explanation", after});
  p.lines.push_back({"noise floor", std::vector<double>(before.size(), r.noise.sigma_um)});
  return p;
}

}  // namespace

std::vector<GapPlot> gap_plots(const GapData& gd, const GapResult& r) {
  std::vector<GapPlot> out;
  std::vector<std::string> bys;
  if (std::any_of(gd.time_s.begin(), gd.time_s.end(), [](double t) { return std::isfinite(t); }))
    bys.push_back("t_s");                     // the drift view, always
  if (gd.circle) bys.push_back("angle_deg");  // the trace view
  auto add = [&](const std::string& by, std::size_t most) {
    if (by != "output" && by.rfind("dir", 0) != 0 && by != "cycle" && by != "feed" &&
        std::find(bys.begin(), bys.end(), by) == bys.end() && bys.size() < most)
      bys.push_back(by);
  };
  for (const EffectFit& e : r.explanation)  // where the named effects act
    if (e.region) add(e.region->by, 100);
  // Every coordinate that varies, in its unit (deg for a rotary axis); never one that does not.
  for (std::size_t a = 0; a < gd.axes.size(); ++a) {
    std::set<double> v;
    for (const auto& o : gd.points.observations) v.insert(gd.points.poses[o.row][a]);
    if (v.size() > 1) add(gd.axes[a], 100);
  }
  for (const GapRegion& g : r.where)
    if (g.significant) add(g.by, 100);
  for (const std::string& by : bys)
    out.push_back({"residual_" + by, "held-out residual along " + by, {residual_plot(gd, r, by)}});
  BarChart bc;
  bc.title = "held-out RMS after each candidate (µm)";
  bc.ylabel = "µm";
  BarSeries s{"after", {}, {}, {}};
  for (const EffectFit& e : r.effects)
    bc.categories.push_back(e.name), s.value.push_back(e.heldout_rms_after_um);
  bc.categories.push_back("baseline");
  s.value.push_back(r.baseline.rms_um);
  bc.series = {s};
  out.push_back({"effects", "effect ranking", {bc}});
  return out;
}

std::string gap_markdown(const GapResult& r, const Model& model, const std::string& data,
                         const std::vector<std::string>& pngs, const std::string& report_path) {
  std::string md = gap_text(r, model, data, true);
  if (!pngs.empty()) {
    md += "\n## Plots\n\n";
    const std::filesystem::path base = std::filesystem::absolute(report_path).parent_path();
    for (const std::string& p : pngs)
      md += "![" + std::filesystem::path(p).stem().string() + "](" +
            std::filesystem::relative(std::filesystem::absolute(p), base).string() + ")\n";
  }
  return md;
}

std::vector<std::string> write_gap_plots(const std::string& dir, const GapData& gd,
                                         const GapResult& r) {
  std::filesystem::create_directories(dir);
  std::vector<std::string> pngs;
  for (const GapPlot& p : gap_plots(gd, r)) {
    pngs.push_back(dir + "/" + p.stem + ".png");
    write_plot(pngs.back(), p.panels, p.title);
  }
  return pngs;
}

}  // namespace weilgen
