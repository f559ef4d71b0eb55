// weilgen sensitivity: local coefficients, exact (linear) and sampled Sobol' indices of every
// output at every pose. The study is analysis/sensitivity_study, the documents
// report/sensitivity_document; JSON schema and method: docs/sensitivity.md.
#include <iostream>

#include "flags.hpp"
#include "study.hpp"
#include "verbs.hpp"
#include "weilgen/analysis/sensitivity_study.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/report/sensitivity_document.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

int verb_sensitivity(const Args& args) {
  po::options_description opts(
      "weilgen sensitivity <machine> (--at ...|--grid ...) [options]\n\n"
      "Sensitivity of the tool-point deviation to every error, at every pose:\n"
      "  local  the coefficient c_i of each error and its contribution c_i*sigma_i, ranked;\n"
      "  exact  Sobol' indices of the linear model, S_i = c_i^2 s_i^2 / sum_j c_j^2 s_j^2\n"
      "         (exact at order 1; the first-order reference at order >= 2; not for dp);\n"
      "  sobol  first-order (Saltelli) and total (Jansen) indices by randomised quasi-Monte\n"
      "         Carlo on scrambled Sobol' points; intervals from R independent replicates\n"
      "         (Student t), or the bootstrap with --bootstrap B.\n"
      "Outputs: dx dy dz (mm), da db dc (rad), dp = |(dx,dy,dz)| (mm, sampling only).\n\n"
      "Options");
  StudyFlags f;
  std::string method = "all", outputs_text = "dx,dy,dz,da,db,dc,dp", sampling = "qmc";
  std::size_t samples = 1u << 14, top = 10;
  long long replicates = static_cast<long long>(SobolOptions{}.replicates), bootstrap = 200;
  double confidence = 0.95;
  opts.add_options()("help,h", "show this help")(
      "method", po::value<std::string>(&method)->default_value("all"),
      "local | sobol | exact | all")(
      "outputs", po::value<std::string>(&outputs_text)->default_value(outputs_text),
      "outputs to analyse, comma-separated")(
      "samples",
      ranged(&samples, NumberRange::whole_numbers(2, 4294967295.0))->default_value(samples),
      "Sobol' base sample size N (powers of two keep the Sobol' net property); N (k+2) model "
      "evaluations per pose")(
      "sampling", po::value<std::string>(&sampling)->default_value("qmc"),
      "qmc (Sobol' points with a seeded digital shift) | mc (pseudo-random)")(
      "replicates", ranged(&replicates, NumberRange::whole_numbers(2, 1024)),
      "R independent randomised replicates of N/R rows each (default 4): each index is their "
      "mean, its interval mean +- t sd/sqrt(R); N must be a multiple of R")(
      "bootstrap", ranged(&bootstrap, NumberRange::whole_numbers(0, 1e5)),
      "percentile bootstrap with B resamples instead of replicates (0 = no intervals); on QMC a "
      "conservative bound")("confidence",
                            ranged(&confidence, NumberRange::open(0, 1))->default_value(confidence),
                            "confidence level of the intervals")(
      "top", ranged(&top, NumberRange::whole_numbers(0, 1e9))->default_value(top),
      "rows per table on stdout (0 = all)");
  add_study_options(opts, f, false);
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("sensitivity", args, opts, "machine", 1, vm))
    return *stop;
  if (vm.count("machine")) f.request.machine = vm["machine"].as<std::string>();

  SensitivityOptions so;
  try {
    parse_sensitivity_method(method, so);
    so.sobol_options.sampling = parse_sampling(sampling);
    so.outputs = parse_output_list(outputs_text);
    so.sobol_options.samples = samples;
    so.sobol_options.seed = f.seed;
    so.sobol_options.confidence = confidence;
    if (so.sobol)
      set_sobol_intervals(so.sobol_options, vm.count("replicates") ? &replicates : nullptr,
                          vm.count("bootstrap") ? &bootstrap : nullptr);
    so.validate();
  } catch (const std::invalid_argument& e) {
    return usage_error("sensitivity", e.what());
  }

  check_output_paths(study_inputs(f), study_outputs(f));
  if (!f.plot.empty()) check_plot_target(f.plot);  // before a long run, not after
  const Study st = open_study(f, false);
  Progress progress("sensitivity", st.poses.poses.size(), f.quiet);
  const SensitivityResult r =
      SensitivityStudy(so).run(st, [&](std::size_t done, std::size_t) { progress.update(done); });

  std::cout << sensitivity_text(st, so, r, top);
  if (!f.json.empty()) write_file_atomically(f.json, sensitivity_json(st, so, r).dump(1) + "\n");
  if (!f.csv.empty()) write_file_atomically(f.csv, sensitivity_csv(st, r));
  if (!f.plot.empty())
    write_plot(f.plot, sensitivity_panels(st, so, r), "weilgen sensitivity: " + st.model->name());
  return 0;
}

}  // namespace weilgen::cli
