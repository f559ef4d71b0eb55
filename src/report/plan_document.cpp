#include "weilgen/report/plan_document.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/report/identify_document.hpp"
#include "weilgen/report/json_common.hpp"
#include "weilgen/report/measurement_document.hpp"

namespace weilgen {

using nlohmann::json;

namespace {

const char* unit_word(Instrument i) {
  switch (i) {
    case Instrument::Ballbar:
      return "circles";
    case Instrument::Line6d:
      return "positions";
    default:
      return "poses";
  }
}

json pose_object(const Description& d, const std::vector<double>& pose) {
  json p = json::object();
  for (std::size_t a = 0; a < pose.size(); ++a) p[d.axis_joint(a).coordinate] = pose[a];
  return p;
}

std::string pose_line(const Description& d, const std::vector<double>& pose) {
  std::string s;
  for (std::size_t a = 0; a < pose.size(); ++a)
    s += (a ? " " : "") + d.axis_joint(a).coordinate + "=" + format_number(pose[a]);
  return s;
}

json observability_json(const ObservabilityIndices& o) {
  return {{"O1", json_number(o.o1)},
          {"O2", json_number(o.o2)},
          {"O3", json_number(o.o3)},
          {"O4", json_number(o.o4)},
          {"O5", json_number(o.o5)}};
}

// The noise of `kinds` as {dx_um: .., ang_urad: ..}.
json noise_json(const std::vector<std::size_t>& kinds, const KindNoise& noise) {
  json j = json::object();
  for (std::size_t k : kinds)
    j[std::string(observation_name(k)) +
      (std::string(observation_unit(k)) == "µrad" ? "_urad" : "_um")] = noise[k];
  return j;
}

// " dx 1 µm dy 1 µm dz 1 µm"
std::string noise_text(const std::vector<std::size_t>& kinds, const KindNoise& noise) {
  std::string s;
  for (std::size_t k : kinds)
    s += " " + std::string(observation_name(k)) + " " + format_significant(noise[k], 3) + " " +
         observation_unit(k);
  return s;
}

// Time budget: an instrument's first set-up (its noise and times are every set-up's).
const PlanSetup& setup_of(const PlanResult& r, Instrument i) {
  for (const PlanSetup& s : r.candidates.setups)
    if (s.instrument == i) return s;
  return r.candidates.setups.front();
}

// A duration for people: "45 s", "12 min", "3 h 52 min".
std::string duration_text(double s) {
  if (s < 60) return format_significant(s, 3) + " s";
  const long minutes = std::lround(s / 60);
  if (minutes < 60) return std::to_string(minutes) + " min";
  return std::to_string(minutes / 60) + " h" +
         (minutes % 60 ? " " + std::to_string(minutes % 60) + " min" : std::string());
}

// How much lower the plan's prediction SD is than `f`'s, in %: one decimal below 100 %.
std::string below_text(double plan_sd, double sd) {
  const double pct = 100 * (1 - plan_sd / sd);
  return format_fixed(pct, std::abs(pct) < 100 ? 1 : 0) + " %";
}

json unit_json(const PlanRun& run, const PlanUnit& u) {
  const Description& d = run.model->description();
  const PlanSetup& s = run.result.candidates.setups[u.setup];
  json j = {{"setup", s.tag}, {"pose", pose_object(d, u.pose)}};
  if (s.instrument == Instrument::Ballbar) {
    j["plane"] = s.circle.plane;
    j["radius_mm"] = s.circle.radius_mm;
  } else if (s.instrument == Instrument::Line6d) {
    j["axis"] = s.axis;
    j["position_mm"] = u.position;
  }
  return j;
}

json figures_json(const PlanRun& run, const LayoutFigures& f, const LayoutFigures* plan) {
  json j = {{"name", f.name},
            {"units", f.layout.size()},
            {"observations", f.observations},
            {"rank", f.rank},
            {"lost_combinations", f.lost},
            {"condition", json_number(f.condition)},
            {"log_det", json_number(f.log_det)},
            {"criterion_value", json_number(f.criterion)},
            {"prediction_sd_um", json_number(f.prediction_sd_um)},
            {"observability", observability_json(f.observability)}};
  if (plan)
    j["plan_below_pct"] = json_number(100 * (1 - plan->prediction_sd_um / f.prediction_sd_um));
  json poses = json::array();
  for (const PlanUnit& u : f.layout) poses.push_back(pose_object(run.model->description(), u.pose));
  j["poses"] = poses;
  return j;
}

// The file of set-up `tag` for `--out PATH`: PATH itself when the plan has one set-up.
std::string plan_file_path(const std::string& out, const std::string& tag, std::size_t files) {
  if (files <= 1) return out;
  const auto slash = out.find_last_of('/');
  const auto dot = out.find_last_of('.');
  const bool ext = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  return (ext ? out.substr(0, dot) : out) + "_" + tag + (ext ? out.substr(dot) : ".csv");
}

}  // namespace

std::vector<std::pair<std::string, std::string>> plan_files(const PlanRun& run,
                                                            const std::string& out,
                                                            const std::vector<PathArg>& inputs) {
  std::vector<std::pair<std::string, std::string>> files;
  if (out.empty()) return files;
  const Description& d = run.model->description();
  std::vector<PathArg> targets;
  for (const auto& [tag, table] : run.templates) {
    // The set-up's own instrument: with --instruments the files are of several.
    const PlanSetup* setup = nullptr;
    for (const PlanSetup& s : run.result.candidates.setups)
      if (s.tag == tag) setup = &s;
    std::vector<std::string> comments = {
        "measurement template written by weilgen plan (" +
            std::string(instrument_name(setup ? setup->instrument : run.result.instrument)) +
            ", criterion " + design_criterion_name(run.options.criterion) + ") for " + d.name,
        "fill the empty output cells with the measured values; weilgen identify " + d.name +
            " --data <this file> reads it"};
    if (setup) comments.push_back("set-up " + setup->what);
    files.emplace_back(plan_file_path(out, tag, run.templates.size()),
                       measurement_csv(table, comments));
    targets.push_back({"--out", files.back().first});
  }
  check_output_paths(inputs, targets);
  return files;
}

json plan_json(const PlanRun& run, const std::vector<std::string>& files) {
  const PlanResult& r = run.result;
  const Description& d = run.model->description();
  const ErrorParameterisation& param = *run.param;
  const bool budget = !r.instruments.empty();
  json noise = noise_json(observed_kinds(r.instrument), r.noise);
  json instruments = nullptr, time_budget = nullptr;
  if (budget) {
    noise = json::object();
    instruments = json::array();
    for (Instrument i : r.instruments) {
      const PlanSetup& s = setup_of(r, i);
      noise[instrument_name(i)] = noise_json(observed_kinds(i), s.noise);
      instruments.push_back({{"name", instrument_name(i)},
                             {"noise", noise_json(observed_kinds(i), s.noise)},
                             {"setup_s", s.setup_s},
                             {"unit_s", s.pose_s}});
    }
    json uses = json::array();
    for (const TimeUse& t : r.time_use) {
      const PlanSetup& s = r.candidates.setups[t.setup];
      uses.push_back({{"setup", s.tag},
                      {"instrument", instrument_name(s.instrument)},
                      {"what", s.what},
                      {"units", t.units},
                      {"setup_s", t.setup_s},
                      {"units_s", t.units_s}});
    }
    time_budget = {{"budget_s", run.options.budget_s}, {"used_s", r.time_used_s}, {"setups", uses}};
  }
  json poses = json::array(), units = json::array();
  for (const PlanUnit& u : r.plan.layout) {
    poses.push_back(pose_object(d, u.pose));
    units.push_back(unit_json(run, u));
  }
  json setups = json::array();
  std::vector<bool> used(r.candidates.setups.size(), false);
  for (const PlanUnit& u : r.plan.layout) used[u.setup] = true;
  for (std::size_t s = 0; s < r.candidates.setups.size(); ++s)
    if (used[s])
      setups.push_back(
          {{"tag", r.candidates.setups[s].tag}, {"what", r.candidates.setups[s].what}});
  json params = json::array();
  for (std::size_t p = 0; p < param.size(); ++p) {
    const IdentParameter& ip = param.parameters()[p];
    params.push_back({{"label", ip.label},
                      {"error", d.errors[static_cast<std::size_t>(ip.error)].name},
                      {"unit", ip.unit},
                      {"identifiable", std::isfinite(r.plan.parameter_sd[p])},
                      {"sd", json_number(r.plan.parameter_sd[p])}});
  }
  const json null = null_combinations_json(param, r.unidentifiable);
  json compare = json::array();
  for (const LayoutFigures& f : r.compare) compare.push_back(figures_json(run, f, &r.plan));
  json target = nullptr;
  if (run.options.target_sd_um > 0) {
    json tried = json::array();
    for (const auto& [n, sd] : r.target_search)
      tried.push_back({{"units", n}, {"prediction_sd_um", json_number(sd)}});
    target = {{"target_sd_um", run.options.target_sd_um}, {"tried", tried}};
  }
  json map = {{"x_axis", r.sd_map.x_axis},
              {"y_axis", r.sd_map.y_axis},
              {"x", r.sd_map.x},
              {"y", r.sd_map.y},
              {"sd_um", json_numbers(r.sd_map.sd_um)},
              {"other_axes", pose_object(d, r.sd_map.middle)}};
  return json_document(
      "plan", {{"model", model_json(*run.model)},
               {"instrument", budget ? json(nullptr) : json(instrument_name(r.instrument))},
               {"instruments", instruments},
               {"time_budget", time_budget},
               {"criterion", design_criterion_name(run.options.criterion)},
               {"noise", noise},
               {"units", r.plan.layout.size()},
               {"unit", budget ? "units" : unit_word(r.instrument)},
               {"poses", poses},
               {"layout", units},
               {"setups", setups},
               {"files", files},
               {"free_parameters", r.free_parameters},
               {"log_det", json_number(r.plan.log_det)},
               {"criterion_value", json_number(r.plan.criterion)},
               {"rank", r.plan.rank},
               {"condition", json_number(r.plan.condition)},
               {"observations", r.plan.observations},
               {"candidates",
                {{"units", r.candidates.units.size()},
                 {"dropped", r.candidates.dropped},
                 {"forced", r.candidates.forced.size()},
                 {"rank", r.candidate_rank},
                 {"minimum_units", r.minimum_units},
                 {"sequential_full_rank_units", r.greedy_units}}},
               {"unidentifiable", null},
               {"prediction_sd_um", json_number(r.plan.prediction_sd_um)},
               {"parameters", params},
               {"observability", observability_json(r.plan.observability)},
               {"compare", compare},
               {"bound",
                {{"iterations", r.bound_iterations},
                 {"criterion_value", json_number(r.criterion_bound)},
                 {"prediction_sd_um", json_number(r.prediction_sd_bound_um)}}},
               {"random_sd_um", json_numbers(r.random_sd_um)},
               {"target", target},
               {"exchange",
                {{"restarts", run.options.restarts},
                 {"seed", run.options.seed},
                 {"best_restart", r.exchange.best_restart},
                 {"restart_values", json_numbers(r.exchange.restart_values)},
                 {"passes", r.exchange.passes},
                 {"exchanges", r.exchange.exchanges}}},
               {"sd_map", map},
               {"seconds", r.seconds}});
}

std::string plan_text(const PlanRun& run, const std::vector<std::string>& files) {
  const PlanResult& r = run.result;
  const Description& d = run.model->description();
  std::ostringstream os;
  const bool budget = !r.instruments.empty();
  const std::string units = budget ? "units" : unit_word(r.instrument);
  os << "plan " << d.name << " (";
  if (budget) {
    for (std::size_t i = 0; i < r.instruments.size(); ++i)
      os << (i ? ", " : "") << instrument_name(r.instruments[i]);
    os << " within " << duration_text(run.options.budget_s);
  } else {
    os << instrument_name(r.instrument);
  }
  os << ", criterion " << design_criterion_name(run.options.criterion)
     << "): " << r.plan.layout.size() << " " << units << " of " << r.candidates.units.size()
     << " candidates";
  if (r.candidates.dropped) os << " (" << r.candidates.dropped << " outside the travel left out)";
  os << "\nparameters: " << r.free_parameters << " free; the candidates identify "
     << r.candidate_rank << " combinations";
  if (!r.unidentifiable.empty())
    os << " (" << r.unidentifiable.size() << " not identifiable by any candidate set, below)";
  os << "\nplan: rank " << r.plan.rank << ", condition " << format_significant(r.plan.condition, 3)
     << ", log det " << format_significant(r.plan.log_det, 6) << ", " << r.plan.observations
     << " observations";
  if (!budget)
    os << "; at least " << r.minimum_units << " " << units
       << " for full rank (the sequential design needed " << r.greedy_units << ")";
  os << "\nnoise:";
  if (budget) {
    for (std::size_t i = 0; i < r.instruments.size(); ++i)
      os << (i ? ";" : "") << " " << instrument_name(r.instruments[i])
         << noise_text(observed_kinds(r.instruments[i]), setup_of(r, r.instruments[i]).noise);
    os << "\ntime: " << duration_text(r.time_used_s) << " of "
       << duration_text(run.options.budget_s) << ":";
    for (std::size_t i = 0; i < r.time_use.size(); ++i) {
      const TimeUse& t = r.time_use[i];
      const PlanSetup& s = r.candidates.setups[t.setup];
      std::string word = unit_word(s.instrument);
      if (t.units == 1) word.pop_back();  // "1 circle"
      os << (i ? ";" : "") << " " << s.tag << " " << duration_text(t.setup_s) << " + " << t.units
         << " " << word << " " << duration_text(t.units_s);
    }
  } else {
    os << noise_text(observed_kinds(r.instrument), r.noise);
  }
  os << "\n\nlayout                      units  rank  prediction SD  vs plan   O1        O2        "
        "O3        O4        O5\n";
  auto row = [&](const LayoutFigures& f, bool is_plan) {
    os << std::left << std::setw(26) << f.name << std::right << std::setw(7) << f.layout.size()
       << std::setw(6) << f.rank << std::setw(12) << format_significant(f.prediction_sd_um, 3)
       << " um" << std::setw(9)
       << (is_plan
               ? std::string("")
               : below_text(r.plan.prediction_sd_um, f.prediction_sd_um) + (f.lost ? "*" : " "));
    for (double v : {f.observability.o1, f.observability.o2, f.observability.o3, f.observability.o4,
                     f.observability.o5})
      os << std::setw(10) << format_significant(v, 3);
    os << "\n";
  };
  row(r.plan, true);
  for (const LayoutFigures& f : r.compare) row(f, false);
  os << "(prediction SD: √ of the mean variance of dx, dy, dz over a 5-level grid of every "
        "axis's travel; 'vs plan': how much lower the plan's is)\n";
  if (budget && r.plan.lost)
    os << "note: within " << duration_text(run.options.budget_s) << " the plan determines "
       << r.plan.rank << " of the " << r.candidate_rank
       << " combinations the candidates identify; its prediction SD leaves the other "
       << r.plan.lost << " out (a bias of unknown size): a longer budget determines them\n";
  for (const LayoutFigures& f : r.compare)
    if (f.lost)
      os << "note: " << f.name << " does not determine " << f.lost << " of the " << r.candidate_rank
         << " combinations the candidates identify: its prediction SD "
         << "leaves them out (they are a bias of unknown size), so its 'vs plan' (*) flatters "
            "it\n";
  if (r.bound_iterations) {
    os << "bound (continuous design, " << r.bound_iterations
       << " iterations): no design of this size on these candidates reaches a prediction SD "
          "below "
       << format_significant(r.prediction_sd_bound_um, 3) << " um";
    if (run.options.criterion != DesignCriterion::E)
      os << "; criterion " << design_criterion_name(run.options.criterion) << " bound "
         << format_significant(r.criterion_bound, 6) << " (plan "
         << format_significant(r.plan.criterion, 6) << ")";
    os << "\n";
  }
  if (run.options.target_sd_um > 0) {
    os << "\n--target-sd " << format_significant(run.options.target_sd_um, 3) << " um: tried";
    for (const auto& [n, sd] : r.target_search)
      os << " " << n << " ("
         << (std::isfinite(sd) ? format_significant(sd, 3) + " um" : std::string("rank short"))
         << ")";
    os << "; the fewest reaching it: " << r.plan.layout.size() << "\n";
  }
  os << "\nplanned " << units << ":\n";
  for (std::size_t i = 0; i < r.plan.layout.size(); ++i) {
    const PlanUnit& u = r.plan.layout[i];
    const PlanSetup& s = r.candidates.setups[u.setup];
    os << "  " << std::setw(3) << i + 1 << "  ";
    if (s.instrument == Instrument::Ballbar)
      os << s.circle.plane << " circle R " << format_significant(s.circle.radius_mm, 3)
         << " mm, centre " << pose_line(d, u.pose) << "\n";
    else if (s.instrument == Instrument::Line6d)
      os << s.axis << " = " << format_number(u.position) << " mm\n";
    else
      os << pose_line(d, u.pose) << "\n";
  }
  os << "\nparameter                      predicted SD  unit\n";
  for (std::size_t p = 0; p < run.param->size(); ++p) {
    const IdentParameter& ip = run.param->parameters()[p];
    os << "  " << std::left << std::setw(28) << ip.label << std::right << std::setw(12)
       << (std::isfinite(r.plan.parameter_sd[p]) ? format_significant(r.plan.parameter_sd[p], 3)
                                                 : std::string("n.i."))
       << "  " << ip.unit << "\n";
  }
  if (!r.unidentifiable.empty()) {
    os << "\nNot identifiable from any of the candidates (n.i.; identify takes the minimum-norm "
          "choice):\n";
    for (std::size_t i = 0; i < r.unidentifiable.size(); ++i)
      os << "  " << i + 1 << ". " << r.unidentifiable[i].str(run.param->parameters()) << "\n";
  }
  os << "\nplanner: " << format_significant(r.seconds, 3) << " s (" << run.options.restarts
     << " restarts, best " << r.exchange.best_restart << ", " << r.exchange.passes << " passes, "
     << r.exchange.exchanges << " exchanges)\n";
  for (const std::string& f : files) os << "wrote " << f << "\n";
  return os.str();
}

std::vector<Panel> plan_panels(const PlanRun& run) {
  const PlanResult& r = run.result;
  const Description& d = run.model->description();
  std::vector<Panel> panels;
  // The poses: the planned units in the map's two axes, and a third when there is one.
  const SdMap& m = r.sd_map;
  std::size_t ax = 0, ay = 0;
  for (std::size_t a = 0; a < d.axes().size(); ++a) {
    if (d.axis_joint(a).coordinate == m.x_axis) ax = a;
    if (d.axis_joint(a).coordinate == m.y_axis) ay = a;
  }
  StyledLinePlot scatter;
  scatter.plot.title =
      "planned " + std::string(unit_word(r.instrument)) + " (" + m.x_axis + ", " + m.y_axis + ")";
  scatter.plot.xlabel = m.x_axis + " (" + m.x_unit + ")";
  scatter.plot.ylabel = m.y_axis + " (" + m.y_unit + ")";
  std::vector<double> ys;
  for (const PlanUnit& u : r.plan.layout) {
    scatter.plot.x.push_back(u.pose[ax]);
    ys.push_back(u.pose[ay]);
  }
  scatter.plot.lines.emplace_back("plan", ys);
  scatter.styles.push_back(LineStyle::Points);
  if (!m.y_axis.empty()) panels.push_back(scatter);
  HeatMap h;
  h.title = "prediction SD (um), other axes at mid travel";
  h.xlabel = scatter.plot.xlabel;
  h.ylabel = m.y_axis.empty() ? "" : scatter.plot.ylabel;
  h.zlabel = "um";
  h.x = m.x;
  h.y = m.y;
  h.z = m.sd_um;
  h.annotate = false;
  panels.push_back(h);
  BarChart bars;
  bars.title = "prediction SD (um): plan and comparison layouts of the same size";
  bars.ylabel = "um";
  BarSeries s{"prediction SD", {}, {}, {}};
  bars.categories.push_back("plan");
  s.value.push_back(r.plan.prediction_sd_um);
  for (const LayoutFigures& f : r.compare) {
    bars.categories.push_back(f.name);
    s.value.push_back(f.prediction_sd_um);
  }
  bars.series.push_back(s);
  panels.push_back(bars);
  return panels;
}

}  // namespace weilgen
