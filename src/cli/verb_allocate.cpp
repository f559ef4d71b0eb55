// weilgen allocate: tolerance allocation by Wang & Yuan 2021's step procedure (tighten the most
// reliability-sensitive errors step by step until the targets hold) and a cost-aware optimum
// (min sum w_i / sigma_i subject to the same targets). The study is analysis/allocation_study,
// the documents report/allocation_document; docs/reliability.md.
#include <iostream>

#include "study.hpp"
#include "verbs.hpp"
#include "weilgen/analysis/allocation_study.hpp"
#include "weilgen/analysis/tolerance_file.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/report/allocation_document.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

int verb_allocate(const Args& args) {
  po::options_description opts(
      "weilgen allocate <machine> --grid ... --tolerance ... --min 0.95 --mean 0.97 [options]\n\n"
      "Tolerance allocation. The step procedure (Wang & Yuan 2021): rank the errors by\n"
      "reliability sensitivity |dR/dsigma| sigma, choose the most sensitive ones per output\n"
      "that misses its targets, lower their spreads by --step each step, recompute, stop when\n"
      "min R >= --min and mean R >= --mean over the poses for every output. With --cost-aware,\n"
      "also the spreads minimising sum w_i/sigma_i under the same targets.\n\nOptions");
  StudyFlags f;
  ReliabilityFlags rf = ReliabilityFlags::for_allocation();
  std::string errors_text, save, rank = "scaled";
  std::vector<std::string> step_flags, weight_flags;
  double min_target = 0.95, mean_target = 0.97, loosen = 4.0;
  std::size_t choose = 4, max_steps = 100;
  opts.add_options()("help,h", "show this help")(
      "min", ranged(&min_target, NumberRange::open(0, 1))->default_value(min_target),
      "target for the minimum reliability over the poses (per output)")(
      "mean", ranged(&mean_target, NumberRange::open(0, 1))->default_value(mean_target),
      "target for the mean reliability over the poses (per output)")(
      "step", po::value<std::vector<std::string>>(&step_flags)->composing(),
      "spread decrement per step: 10% (of the starting sigma; default), 0.005/6mm (all length\n"
      "errors), 0.005/6000rad (all angular errors) or E_C0X=0.005/3000rad; repeatable")(
      "choose", ranged(&choose, NumberRange::whole_numbers(1, 100000))->default_value(choose),
      "errors chosen per output that misses its targets")(
      "rank", po::value<std::string>(&rank)->default_value("scaled"),
      "how --choose ranks the errors: scaled (mean |dR/dsigma_i| sigma_i, unit-free) | raw\n"
      "(mean |dR/dsigma_i| per base unit, mm or rad: Wang & Yuan 2021's ranking, which favours "
      "the\n"
      "angular errors because a rad is 1000 mm/m)")(
      "errors", po::value<std::string>(&errors_text),
      "explicit comma-separated choice of the errors to tighten (overrides --choose)")(
      "max-steps",
      ranged(&max_steps, NumberRange::whole_numbers(1, 100000))->default_value(max_steps),
      "step limit")(
      "per-output",
      "tighten at each step only the errors chosen by outputs still missing a target")(
      "cost-aware", "also minimise sum w_i/sigma_i subject to the targets")(
      "weight", po::value<std::vector<std::string>>(&weight_flags)->composing(),
      "NAME=w cost weight of an error, in the unit of its spread (default: its starting\n"
      "spread, so that cost = sum sigma0_i/sigma_i); repeatable")(
      "max-loosen", ranged(&loosen, NumberRange::closed(1, 1e6))->default_value(loosen),
      "cost-aware bound: no spread above this factor times its starting value")(
      "save-tolerances", po::value<std::string>(&save),
      "write the step procedure's final spreads as a tolerance file");
  add_reliability_options(opts, rf);
  add_study_options(opts, f, true);
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("allocate", args, opts, "machine", 1, vm)) return *stop;
  if (vm.count("machine")) f.request.machine = vm["machine"].as<std::string>();
  AllocationStudyOptions ao;
  ao.min_target = min_target;
  ao.mean_target = mean_target;
  ao.max_loosen = loosen;
  ao.rank = rank;
  try {
    ao.validate();
  } catch (const std::invalid_argument& e) {
    return usage_error("allocate", e.what());
  }
  ao.reliability = parse_reliability_flags(rf, f.seed);
  ao.steps = step_flags;
  ao.choose = choose;
  ao.max_steps = max_steps;
  ao.per_output = vm.count("per-output") > 0;
  ao.cost_aware = vm.count("cost-aware") > 0;
  ao.weights = weight_flags;
  if (!errors_text.empty()) ao.errors = split(errors_text, ',');

  std::vector<PathArg> outputs = study_outputs(f);
  outputs.push_back({"--save-tolerances", save});
  check_output_paths(study_inputs(f), outputs);
  if (!f.plot.empty()) check_plot_target(f.plot);  // before a long run, not after
  const Study st = open_study(f, true);
  const AllocationStudyResult out = AllocationStudy(ao).run(st);
  std::cout << allocation_text(st, ao, out);
  if (!save.empty())
    write_tolerance_file(save, st.model->description(), out.final_inputs,
                         allocation_tolerance_comment(st, out));
  const AllocationSettingsText text{rf.limit, rf.method, f.seed};
  if (!f.json.empty())
    write_file_atomically(f.json, allocation_json(st, ao, text, out).dump(1) + "\n");
  if (!f.csv.empty()) write_file_atomically(f.csv, allocation_csv(st, out));
  if (!f.plot.empty())
    write_plot(f.plot, allocation_panels(st, ao, out), "weilgen allocate: " + st.model->name());
  return out.result.met ? 0 : 1;
}

}  // namespace weilgen::cli
