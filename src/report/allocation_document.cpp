#include "weilgen/report/allocation_document.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "weilgen/base/format.hpp"
#include "weilgen/report/csv_table.hpp"
#include "weilgen/report/json_common.hpp"

namespace weilgen {

namespace {

// One verdict, with the comparison it rests on (AllocationOptions::target_tolerance).
std::string verdict(bool met, const AllocationOptions& o) {
  return std::string(met ? "targets met" : "targets NOT met") +
         " (min R >= " + format_short(100 * o.min_target) +
         " %, mean R >= " + format_short(100 * o.mean_target) + " %, within " +
         format_short(o.target_tolerance) + ")";
}

// A spread in the error's declared unit, 4 significant digits.
std::string sigma_text(const ErrorDef& e, double sigma_base) {
  std::ostringstream s;
  s << std::setprecision(4) << sigma_base / e.to_base;
  return s.str();
}

}  // namespace

std::string allocation_text(const Study& st, const AllocationStudyOptions& o,
                            const AllocationStudyResult& out) {
  std::ostringstream os;
  const Description& d = st.model->description();
  const std::size_t ne = d.errors.size();
  const AllocationResult& res = out.result;
  const auto& groups = out.groups;
  os << "weilgen allocate: " << st.model->name() << " (order " << st.model->order() << ", "
     << st.model->origin() << "), " << st.poses.poses.size()
     << " poses, targets min >= " << 100 * o.min_target << " %, mean >= " << 100 * o.mean_target
     << " %\n";
  os << "chosen errors:";
  for (std::size_t i : res.chosen) os << " " << d.errors[i].name;
  os << "\n\n";
  std::ostringstream h;
  h << std::setw(5) << "step";
  for (std::size_t i : res.chosen)
    h << std::setw(14) << (d.errors[i].name + " (" + d.errors[i].unit + ")");
  for (const auto& g : groups) h << std::setw(11) << ("mean " + g) << std::setw(10) << ("min " + g);
  os << h.str() << "\n";
  for (const auto& s : res.steps) {
    std::ostringstream line;
    line << std::setw(5) << s.step;
    for (std::size_t i : res.chosen) line << std::setw(14) << sigma_text(d.errors[i], s.stddev[i]);
    line << std::fixed << std::setprecision(3);
    for (std::size_t g = 0; g < groups.size(); ++g)
      line << std::setw(11) << 100 * s.group_mean[g] << std::setw(10) << 100 * s.group_min[g];
    os << line.str() << "\n";
  }
  os << verdict(res.met, out.options) << " after "
     << (res.steps.empty() ? 0 : res.steps.back().step) << " steps\n";
  if (!res.note.empty()) os << "note: " << res.note << "\n";
  if (!o.cost_aware) return os.str();
  os << "\ncost-aware (min sum w/sigma): " << verdict(res.cost_aware_met, out.options) << ", cost "
     << std::setprecision(6) << res.cost_aware << " vs step procedure " << res.cost_step << " ("
     << std::setprecision(3) << std::fixed << 100 * (1 - res.cost_aware / res.cost_step)
     << " % cheaper)\n";
  // Looseness over the errors that move a toleranced output (the others simply go to the
  // --max-loosen bound).
  std::vector<bool> matters(ne, false);
  for (const auto& scores : res.group_scores)
    for (std::size_t i = 0; i < ne && i < scores.size(); ++i)
      matters[i] = matters[i] || scores[i] > 0;
  double log_ratio = 0;
  std::size_t n_matter = 0;
  for (std::size_t i = 0; i < ne; ++i)
    if (matters[i]) {
      log_ratio += std::log(res.cost_aware_stddev[i] / res.steps.back().stddev[i]);
      ++n_matter;
    }
  os << "  spreads of the " << n_matter << " errors that move the toleranced outputs: "
     << "geometric mean "
     << std::exp(log_ratio / static_cast<double>(std::max<std::size_t>(1, n_matter)))
     << " x the step procedure's (> 1: looser); the other errors go to the --max-loosen "
        "bound\n";
  double c_aware = 0, c_step = 0;
  for (std::size_t i = 0; i < ne; ++i)
    if (matters[i]) {
      c_aware += out.options.cost_weights[i] / res.cost_aware_stddev[i];
      c_step += out.options.cost_weights[i] / res.steps.back().stddev[i];
    }
  os << "  cost over those errors: " << c_aware << " vs " << c_step << " ("
     << 100 * (1 - c_aware / c_step) << " % cheaper)\n";
  os << std::defaultfloat;
  for (std::size_t i = 0; i < ne; ++i) {
    const double s0 = st.inputs[i].stddev(), s1 = res.cost_aware_stddev[i];
    const double sstep = res.steps.back().stddev[i];
    os << "  " << std::left << std::setw(8) << d.errors[i].name << std::right << " sigma "
       << std::setw(12) << sigma_text(d.errors[i], s1) << " " << d.errors[i].unit << "  (start "
       << sigma_text(d.errors[i], s0) << ", steps " << sigma_text(d.errors[i], sstep) << ", x"
       << std::setprecision(3) << s1 / sstep << " the step result)"
       << (matters[i] ? "" : ", no effect") << "\n";
  }
  for (std::size_t g = 0; g < groups.size(); ++g)
    os << "  " << groups[g] << ": mean " << 100 * res.cost_aware_group_mean[g] << " %, min "
       << 100 * res.cost_aware_group_min[g] << " %\n";
  return os.str();
}

nlohmann::json allocation_json(const Study& st, const AllocationStudyOptions& o,
                               const AllocationSettingsText& text,
                               const AllocationStudyResult& out) {
  const Description& d = st.model->description();
  const std::size_t ne = d.errors.size();
  const AllocationResult& res = out.result;
  nlohmann::json steps = nlohmann::json::array();
  for (const auto& s : res.steps) {
    nlohmann::json sig = nlohmann::json::object(), groups = nlohmann::json::array(),
                   tight = nlohmann::json::array();
    for (std::size_t i = 0; i < ne; ++i) sig[d.errors[i].name] = s.stddev[i];
    for (std::size_t i : s.tightened) tight.push_back(d.errors[i].name);
    for (std::size_t g = 0; g < out.groups.size(); ++g)
      groups.push_back(
          {{"output", out.groups[g]},
           {"min", s.group_min[g]},
           {"mean", s.group_mean[g]},
           {"argmin", pose_json(st.poses, s.group_argmin[g] % st.poses.poses.size())}});
    steps.push_back({{"step", s.step}, {"stddev", sig}, {"tightened", tight}, {"outputs", groups}});
  }
  nlohmann::json chosen = nlohmann::json::array();
  for (std::size_t i : res.chosen) chosen.push_back(d.errors[i].name);
  nlohmann::json j = json_document(
      "allocate", {{"model", model_json(*st.model)},
                   {"settings",
                    {{"min", o.min_target},
                     {"mean", o.mean_target},
                     {"target_tolerance", out.options.target_tolerance},
                     {"limit", text.limit},
                     {"method", text.method},
                     {"seed", text.seed}}},
                   {"inputs", inputs_json(*st.model, st.inputs)},
                   {"stddev_unit", "base units: mm for translations, rad for rotations"},
                   {"chosen", chosen},
                   {"steps", steps},
                   {"met", res.met},
                   {"note", res.note}});
  if (o.cost_aware) {
    nlohmann::json sig = nlohmann::json::object();
    for (std::size_t i = 0; i < ne; ++i) sig[d.errors[i].name] = res.cost_aware_stddev[i];
    j["cost_aware"] = {{"met", res.cost_aware_met},
                       {"stddev", sig},
                       {"cost", res.cost_aware},
                       {"cost_step", res.cost_step}};
  }
  return j;
}

std::string allocation_csv(const Study& st, const AllocationStudyResult& out) {
  const Description& d = st.model->description();
  CsvTable t;
  t.column("step");
  // Spreads in each error's declared unit, as in the machine and tolerance files.
  for (const auto& e : d.errors) t.column("sigma_" + e.name, e.unit);
  for (const auto& g : out.groups) {
    t.column("mean_R_" + g);
    t.column("min_R_" + g);
  }
  for (const auto& s : out.result.steps) {
    t.count(static_cast<std::size_t>(s.step));
    for (std::size_t i = 0; i < d.errors.size(); ++i) t.number(s.stddev[i] / d.errors[i].to_base);
    for (std::size_t g = 0; g < out.groups.size(); ++g)
      t.number(s.group_mean[g]).number(s.group_min[g]);
    t.end_row();
  }
  return t.str();
}

std::vector<Panel> allocation_panels(const Study& st, const AllocationStudyOptions& o,
                                     const AllocationStudyResult& out) {
  const Description& d = st.model->description();
  const AllocationResult& res = out.result;
  std::vector<double> steps;
  for (const auto& s : res.steps) steps.push_back(static_cast<double>(s.step));
  std::vector<Panel> panels;
  for (std::size_t g = 0; g < out.groups.size(); ++g) {
    LinePlot l;
    l.title = "R(" + out.groups[g] + ") over the steps";
    l.xlabel = "step";
    l.ylabel = "R (%)";
    l.x = steps;
    std::vector<double> mean, min;
    for (const auto& s : res.steps) {
      mean.push_back(100 * s.group_mean[g]);
      min.push_back(100 * s.group_min[g]);
    }
    l.lines.push_back({"mean R", mean});
    l.lines.push_back({"min R", min});
    l.lines.push_back({"mean target", std::vector<double>(steps.size(), 100 * o.mean_target)});
    l.lines.push_back({"min target", std::vector<double>(steps.size(), 100 * o.min_target)});
    panels.push_back(l);
  }
  if (!res.chosen.empty() && !res.steps.empty()) {
    LinePlot l;
    l.title = "spreads of the chosen errors";
    l.xlabel = "step";
    l.ylabel = "sigma (% of its start)";
    l.x = steps;
    for (std::size_t i : res.chosen) {
      std::vector<double> y;
      for (const auto& s : res.steps) y.push_back(100 * s.stddev[i] / res.steps.front().stddev[i]);
      l.lines.push_back({d.errors[i].name, y});
    }
    panels.push_back(l);
  }
  if (o.cost_aware && !res.steps.empty() && res.cost_aware_stddev.size() == d.errors.size()) {
    BarChart b;
    b.title = "cost-aware optimum against the step procedure";
    b.ylabel = "sigma (% of its start)";
    BarSeries after{"after the steps", {}, {}, {}}, optimum{"cost-aware", {}, {}, {}};
    for (std::size_t i = 0; i < d.errors.size(); ++i) {
      const double s0 = res.steps.front().stddev[i];
      if (!(s0 > 0)) continue;  // a constant error has no spread to allocate
      b.categories.push_back(d.errors[i].name);
      after.value.push_back(100 * res.steps.back().stddev[i] / s0);
      optimum.value.push_back(100 * res.cost_aware_stddev[i] / s0);
    }
    b.series = {after, optimum};
    if (!b.categories.empty()) panels.push_back(b);
  }
  return panels;
}

std::string allocation_tolerance_comment(const Study& st, const AllocationStudyResult& out) {
  const auto& res = out.result;
  return "weilgen allocate " + st.model->description().name + ": spreads after " +
         std::to_string(res.steps.empty() ? 0 : res.steps.back().step) + " steps (" +
         (res.met ? "targets met" : "targets not met") + ")";
}

}  // namespace weilgen
