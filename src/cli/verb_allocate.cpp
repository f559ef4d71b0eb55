// weilgen allocate: tolerance allocation by the grinder seed's step procedure (tighten the most
// reliability-sensitive errors step by step until the targets hold) and a cost-aware optimum
// (min sum w_i / sigma_i subject to the same targets). docs/reliability.md.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "reliability_sweep.hpp"
#include "verbs.hpp"
#include "weilgen/analysis/tolerance_file.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/machine/description.hpp"
#include "weilgen/uq/allocation.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

namespace {

// --step: "10%" (of each chosen error's starting spread), "0.005/6mm" (every length error),
// "0.005/6000rad" (every angular error), "E_C0X=0.005/3000rad" (one error). Later flags win
// over earlier ones of the same scope; per-error flags over kind-wide ones.
std::vector<double> parse_steps(const Description& d, const std::vector<std::string>& flags,
                                const std::vector<InputDistribution>& inputs) {
  const std::size_t ne = d.errors.size();
  std::vector<double> step(ne, 0.0), per_error(ne, 0.0);
  std::vector<bool> set_error(ne, false);
  bool any_kind = false;
  for (const auto& flag : flags) {
    const auto eq = flag.find('=');
    if (eq != std::string::npos) {
      const std::string name = trim(flag.substr(0, eq));
      const int i = d.error_index(name);
      if (i < 0) throw std::invalid_argument("--step: unknown error \"" + name + "\"");
      const auto& e = d.errors[i];
      const std::string def = e.effect == ErrorEffect::Rotation ? "rad" : "mm";
      per_error[i] = parse_quantity(flag.substr(eq + 1), def, "--step " + name);
      set_error[i] = true;
      continue;
    }
    const std::string t = trim(flag);
    if (!t.empty() && t.back() == '%') {
      const double pct = parse_quantity_unit(t.substr(0, t.size() - 1), "mm", "--step").number;
      if (!(pct > 0 && pct < 100))
        throw std::invalid_argument("--step: percentage must be in (0, 100)");
      for (std::size_t i = 0; i < ne; ++i) step[i] = pct / 100 * inputs[i].stddev();
      any_kind = true;
      continue;
    }
    const Quantity q = parse_quantity_unit(t, "", "--step");
    for (std::size_t i = 0; i < ne; ++i)
      if ((d.errors[i].effect == ErrorEffect::Rotation) == q.unit.angle) step[i] = q.value();
    any_kind = true;
  }
  if (!any_kind && flags.empty())
    for (std::size_t i = 0; i < ne; ++i) step[i] = 0.1 * inputs[i].stddev();
  for (std::size_t i = 0; i < ne; ++i) {
    if (set_error[i]) step[i] = per_error[i];
    if (step[i] < 0 || !std::isfinite(step[i]))
      throw std::invalid_argument("--step: steps must be positive");
  }
  return step;
}

// A spread in the error's declared unit, 4 significant digits.
std::string sigma_text(const ErrorDef& e, double sigma_base) {
  std::ostringstream s;
  s << std::setprecision(4) << sigma_base / e.to_base;
  return s.str();
}

}  // namespace

int verb_allocate(const Args& args) {
  po::options_description opts(
      "weilgen allocate <machine> --grid ... --tolerance ... --min 0.95 --mean 0.97 [options]\n\n"
      "Tolerance allocation. The step procedure (Wang & Yuan 2021): rank the errors by\n"
      "reliability sensitivity |dR/dsigma| sigma, choose the most sensitive ones per output\n"
      "that misses its targets, lower their spreads by --step each step, recompute, stop when\n"
      "min R >= --min and mean R >= --mean over the poses for every output. With --cost-aware,\n"
      "also the spreads minimising sum w_i/sigma_i under the same targets.\n\nOptions");
  StudyFlags f;
  ReliabilityFlags rf;
  rf.samples = 1u << 13;
  std::string errors_text, save, rank = "scaled";
  std::vector<std::string> step_flags, weight_flags;
  double min_target = 0.95, mean_target = 0.97, loosen = 4.0;
  std::size_t choose = 4, max_steps = 100;
  opts.add_options()("help,h", "show this help")(
      "min", po::value<double>(&min_target)->default_value(min_target),
      "target for the minimum reliability over the poses (per output)")(
      "mean", po::value<double>(&mean_target)->default_value(mean_target),
      "target for the mean reliability over the poses (per output)")(
      "step", po::value<std::vector<std::string>>(&step_flags)->composing(),
      "spread decrement per step: 10% (of the starting sigma; default), 0.005/6mm (all length\n"
      "errors), 0.005/6000rad (all angular errors) or E_C0X=0.005/3000rad; repeatable")(
      "choose", po::value<std::size_t>(&choose)->default_value(choose),
      "errors chosen per output that misses its targets")(
      "rank", po::value<std::string>(&rank)->default_value("scaled"),
      "how --choose ranks the errors: scaled (mean |dR/dsigma_i| sigma_i, unit-free) | raw\n"
      "(mean |dR/dsigma_i| per base unit, mm or rad: the seed's ranking, which favours the\n"
      "angular errors because a rad is 1000 mm/m)")(
      "errors", po::value<std::string>(&errors_text),
      "explicit comma-separated choice of the errors to tighten (overrides --choose)")(
      "max-steps", po::value<std::size_t>(&max_steps)->default_value(max_steps), "step limit")(
      "per-output",
      "tighten at each step only the errors chosen by outputs still missing a target")(
      "cost-aware", "also minimise sum w_i/sigma_i subject to the targets")(
      "weight", po::value<std::vector<std::string>>(&weight_flags)->composing(),
      "NAME=w cost weight of an error, in the unit of its spread (default: its starting\n"
      "spread, so that cost = sum sigma0_i/sigma_i); repeatable")(
      "max-loosen", po::value<double>(&loosen)->default_value(loosen),
      "cost-aware bound: no spread above this factor times its starting value")(
      "save-tolerances", po::value<std::string>(&save),
      "write the step procedure's final spreads as a tolerance file");
  add_reliability_options(opts, rf);
  add_study_options(opts, f, true);
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("allocate", args, opts, "machine", 1, vm)) return *stop;
  if (vm.count("machine")) f.machine = vm["machine"].as<std::string>();
  if (!(min_target > 0 && min_target < 1) || !(mean_target > 0 && mean_target < 1))
    return usage_error("allocate", "--min and --mean must be in (0, 1)");
  if (!(loosen >= 1)) return usage_error("allocate", "--max-loosen must be >= 1");
  auto [limit, sens, ro] = parse_reliability_flags(rf, f.seed);

  const Study st = open_study(f, true);
  ro.threads = st.threads;
  const Description& d = st.model->description();
  const std::size_t ne = d.errors.size();

  AllocationProblem prob;
  for (const auto& e : d.errors) prob.names.push_back(e.name);
  prob.inputs = st.inputs;
  for (const auto& t : st.tolerances) prob.groups.push_back(output_name(t.output));
  std::size_t evaluations = 0;
  prob.evaluate = [&](const std::vector<InputDistribution>& inputs) {
    std::vector<AllocationCase> out;
    for (auto& c : reliability_sweep(st, inputs, limit, ro, sens, true)) {
      evaluations += c.result.evaluations;
      out.push_back({c.tolerance, c.result.reliability, c.result.dR_dsigma});
    }
    return out;
  };
  AllocationOptions ao;
  ao.min_target = min_target;
  ao.mean_target = mean_target;
  ao.step = parse_steps(d, step_flags, st.inputs);
  ao.choose = choose;
  ao.max_steps = max_steps;
  ao.per_group = vm.count("per-output") > 0;
  if (!errors_text.empty())
    for (const auto& item : split(errors_text, ',')) {
      const int i = d.error_index(trim(item));
      if (i < 0) throw std::invalid_argument("--errors: unknown error \"" + trim(item) + "\"");
      ao.chosen.push_back(static_cast<std::size_t>(i));
    }
  if (rank != "scaled" && rank != "raw")
    return usage_error("allocate", "--rank must be scaled or raw, not '" + rank + "'");
  if (rank == "raw" && ao.chosen.empty()) {
    // The seed's choice: per output that misses a target, the `choose` errors with the largest
    // mean |dR/dsigma| in base units.
    const auto cases = prob.evaluate(st.inputs);
    for (std::size_t g = 0; g < prob.groups.size(); ++g) {
      std::vector<double> score(ne, 0.0);
      double mean = 0, min = 1;
      std::size_t n = 0;
      for (const auto& c : cases)
        if (c.group == g) {
          for (std::size_t i = 0; i < ne; ++i) score[i] += std::abs(c.dR_dsigma[i]);
          mean += c.reliability, min = std::min(min, c.reliability), ++n;
        }
      if (n == 0 || (min >= min_target && mean / n >= mean_target)) continue;
      std::vector<std::size_t> idx(ne);
      for (std::size_t i = 0; i < ne; ++i) idx[i] = i;
      std::stable_sort(idx.begin(), idx.end(), [&](auto a, auto b) { return score[a] > score[b]; });
      for (std::size_t k = 0; k < std::min(choose, ne); ++k)
        if (score[idx[k]] > 0 && ao.step[idx[k]] > 0 &&
            std::find(ao.chosen.begin(), ao.chosen.end(), idx[k]) == ao.chosen.end())
          ao.chosen.push_back(idx[k]);
    }
  }
  // Default weights: the starting spreads, so that the cost sum sigma0_i / sigma_i is free of
  // units and every error costs 1 at the start (a raw sum of 1/sigma would let the rad-valued
  // errors, ~1e-5, outweigh the mm-valued ones, ~1e-2, by three orders of magnitude).
  for (std::size_t i = 0; i < ne; ++i) ao.cost_weights.push_back(st.inputs[i].stddev());
  for (const auto& w : weight_flags) {
    const auto eq = w.find('=');
    const int i = eq == std::string::npos ? -1 : d.error_index(trim(w.substr(0, eq)));
    if (i < 0)
      throw std::invalid_argument("--weight: expected NAME=w with a known error, not \"" + w +
                                  "\"");
    const auto& e = d.errors[i];
    ao.cost_weights[i] = parse_quantity(
        w.substr(eq + 1), e.effect == ErrorEffect::Rotation ? "rad" : "mm", "--weight");
    if (!(ao.cost_weights[i] >= 0)) throw std::invalid_argument("--weight: must be >= 0");
  }
  for (std::size_t i = 0; i < ne; ++i) {
    ao.sigma_lower.push_back(0.01 * st.inputs[i].stddev());
    ao.sigma_upper.push_back(loosen * st.inputs[i].stddev());
  }

  AllocationResult res = StepAllocation(ao).run(prob);
  if (vm.count("cost-aware")) res = CostAwareAllocation(ao).run(prob, res);

  // ---- stdout: the seed's Tables 5-7 ----
  std::cout << "weilgen allocate: " << st.model->name() << " (order " << st.model->order() << ", "
            << st.model->origin() << "), " << st.poses.poses.size()
            << " poses, targets min >= " << 100 * min_target << " %, mean >= " << 100 * mean_target
            << " %\n";
  std::cout << "chosen errors:";
  for (std::size_t i : res.chosen) std::cout << " " << d.errors[i].name;
  std::cout << "\n\n";
  std::ostringstream h;
  h << std::setw(5) << "step";
  for (std::size_t i : res.chosen)
    h << std::setw(14) << (d.errors[i].name + " (" + d.errors[i].unit + ")");
  for (const auto& g : prob.groups)
    h << std::setw(11) << ("mean " + g) << std::setw(10) << ("min " + g);
  std::cout << h.str() << "\n";
  for (const auto& s : res.steps) {
    std::ostringstream line;
    line << std::setw(5) << s.step;
    for (std::size_t i : res.chosen) line << std::setw(14) << sigma_text(d.errors[i], s.stddev[i]);
    line << std::fixed << std::setprecision(3);
    for (std::size_t g = 0; g < prob.groups.size(); ++g)
      line << std::setw(11) << 100 * s.group_mean[g] << std::setw(10) << 100 * s.group_min[g];
    std::cout << line.str() << "\n";
  }
  std::cout << (res.met ? "targets met" : "targets NOT met") << " after "
            << (res.steps.empty() ? 0 : res.steps.back().step) << " steps\n";
  if (!res.note.empty()) std::cout << "note: " << res.note << "\n";
  if (vm.count("cost-aware")) {
    std::cout << "\ncost-aware (min sum w/sigma): "
              << (res.cost_aware_met ? "targets met" : "targets NOT met") << ", cost "
              << std::setprecision(6) << res.cost_aware << " vs step procedure " << res.cost_step
              << " (" << std::setprecision(3) << std::fixed
              << 100 * (1 - res.cost_aware / res.cost_step) << " % cheaper)\n";
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
    std::cout << "  spreads of the " << n_matter << " errors that move the toleranced outputs: "
              << "geometric mean " << std::exp(log_ratio / std::max<std::size_t>(1, n_matter))
              << " x the step procedure's (> 1: looser); the other errors go to the --max-loosen "
                 "bound\n";
    double c_aware = 0, c_step = 0;
    for (std::size_t i = 0; i < ne; ++i)
      if (matters[i]) {
        c_aware += ao.cost_weights[i] / res.cost_aware_stddev[i];
        c_step += ao.cost_weights[i] / res.steps.back().stddev[i];
      }
    std::cout << "  cost over those errors: " << c_aware << " vs " << c_step << " ("
              << 100 * (1 - c_aware / c_step) << " % cheaper)\n";
    std::cout << std::defaultfloat;
    for (std::size_t i = 0; i < ne; ++i) {
      const double s0 = st.inputs[i].stddev(), s1 = res.cost_aware_stddev[i];
      const double sstep = res.steps.back().stddev[i];
      std::cout << "  " << std::left << std::setw(8) << d.errors[i].name << std::right << " sigma "
                << std::setw(12) << sigma_text(d.errors[i], s1) << " " << d.errors[i].unit
                << "  (start " << sigma_text(d.errors[i], s0) << ", steps "
                << sigma_text(d.errors[i], sstep) << ", x" << std::setprecision(3) << s1 / sstep
                << " the step result)" << (matters[i] ? "" : ", no effect") << "\n";
    }
    for (std::size_t g = 0; g < prob.groups.size(); ++g)
      std::cout << "  " << prob.groups[g] << ": mean " << 100 * res.cost_aware_group_mean[g]
                << " %, min " << 100 * res.cost_aware_group_min[g] << " %\n";
  }

  std::vector<InputDistribution> final_inputs = st.inputs;
  if (!res.steps.empty())
    for (std::size_t i = 0; i < ne; ++i)
      final_inputs[i] =
          st.inputs[i].with_mean_stddev(st.inputs[i].mean(), res.steps.back().stddev[i]);
  if (!save.empty())
    write_tolerance_file(save, d, final_inputs,
                         "weilgen allocate " + d.name + ": spreads after " +
                             std::to_string(res.steps.empty() ? 0 : res.steps.back().step) +
                             " steps (" + (res.met ? "targets met" : "targets not met") + ")");
  if (!f.json.empty()) {
    nlohmann::json steps = nlohmann::json::array();
    for (const auto& s : res.steps) {
      nlohmann::json sig = nlohmann::json::object(), groups = nlohmann::json::array(),
                     tight = nlohmann::json::array();
      for (std::size_t i = 0; i < ne; ++i) sig[d.errors[i].name] = s.stddev[i];
      for (std::size_t i : s.tightened) tight.push_back(d.errors[i].name);
      for (std::size_t g = 0; g < prob.groups.size(); ++g)
        groups.push_back(
            {{"output", prob.groups[g]},
             {"min", s.group_min[g]},
             {"mean", s.group_mean[g]},
             {"argmin", pose_json(st.poses, s.group_argmin[g] % st.poses.poses.size())}});
      steps.push_back(
          {{"step", s.step}, {"stddev", sig}, {"tightened", tight}, {"outputs", groups}});
    }
    nlohmann::json chosen = nlohmann::json::array();
    for (std::size_t i : res.chosen) chosen.push_back(d.errors[i].name);
    nlohmann::json j = {{"weilgen", kVersion},
                        {"verb", "allocate"},
                        {"model", model_json(*st.model)},
                        {"settings",
                         {{"min", min_target},
                          {"mean", mean_target},
                          {"limit", rf.limit},
                          {"method", rf.method},
                          {"seed", f.seed}}},
                        {"inputs", inputs_json(*st.model, st.inputs)},
                        {"stddev_unit", "base units: mm for translations, rad for rotations"},
                        {"chosen", chosen},
                        {"steps", steps},
                        {"met", res.met},
                        {"note", res.note}};
    if (vm.count("cost-aware")) {
      nlohmann::json sig = nlohmann::json::object();
      for (std::size_t i = 0; i < ne; ++i) sig[d.errors[i].name] = res.cost_aware_stddev[i];
      j["cost_aware"] = {{"met", res.cost_aware_met},
                         {"stddev", sig},
                         {"cost", res.cost_aware},
                         {"cost_step", res.cost_step}};
    }
    write_output(f.json, j.dump(1) + "\n");
  }
  if (!f.csv.empty()) {
    std::ostringstream c;
    c << "step";
    for (const auto& e : d.errors) c << ",sigma_" << e.name;
    for (const auto& g : prob.groups) c << ",mean_" << g << ",min_" << g;
    c << "\n";
    for (const auto& s : res.steps) {
      c << s.step;
      for (std::size_t i = 0; i < ne; ++i) c << "," << csv_number(s.stddev[i]);
      for (std::size_t g = 0; g < prob.groups.size(); ++g)
        c << "," << csv_number(s.group_mean[g]) << "," << csv_number(s.group_min[g]);
      c << "\n";
    }
    write_output(f.csv, c.str());
  }
  (void)evaluations;
  return res.met ? 0 : 1;
}

}  // namespace weilgen::cli
