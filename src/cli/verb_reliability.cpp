// weilgen reliability: P(deviation within tolerance) per pose and output, its sensitivities
// to every error's mean and spread, and grid summaries. The sweep is analysis/reliability_sweep,
// the documents report/reliability_document; docs/reliability.md.
#include <iostream>

#include "study.hpp"
#include "verbs.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/report/reliability_document.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

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
  opts.add_options()("help,h", "show this help")(
      "top", ranged(&top, NumberRange::whole_numbers(0, 1e9))->default_value(top),
      "sensitive errors listed per output");
  add_reliability_options(opts, rf);
  add_study_options(opts, f, true);
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("reliability", args, opts, "machine", 1, vm))
    return *stop;
  if (vm.count("machine")) f.request.machine = vm["machine"].as<std::string>();
  const ReliabilitySettings settings = parse_reliability_flags(rf, f.seed);
  check_output_paths(study_inputs(f), study_outputs(f));
  if (!f.plot.empty()) check_plot_target(f.plot);  // before a long run, not after
  const Study st = open_study(f, true);
  if (!f.plot.empty()) check_reliability_plot(st);
  Progress progress("reliability", st.tolerances.size() * st.poses.poses.size(), f.quiet);
  const auto cases = ReliabilitySweep(settings).run(
      st, st.inputs, [&](std::size_t done, std::size_t) { progress.update(done); });

  std::cout << reliability_text(st, settings, cases, top);
  if (!f.json.empty()) {
    const ReliabilitySettingsText text{rf.method, rf.limit, rf.samples, f.seed, rf.confidence};
    write_file_atomically(f.json, reliability_json(st, settings, text, cases).dump(1) + "\n");
  }
  if (!f.csv.empty()) write_file_atomically(f.csv, reliability_csv(st, settings, cases));
  if (!f.plot.empty())
    write_plot(f.plot, reliability_panels(st, cases), "weilgen reliability: " + st.model->name());
  return 0;
}

}  // namespace weilgen::cli
