// weilgen gap: where a machine's model and its measurements disagree, which unmodelled effect
// causes it and how far the gap shrinks once it is modelled (docs/gap.md, JSON schema there).
#include <iostream>

#include "flags.hpp"
#include "study.hpp"
#include "verbs.hpp"
#include "weilgen/analysis/gap_request.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/report/gap_document.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

int verb_gap(const Args& args) {
  StudyFlags flags;
  GapRequest rq;
  po::options_description opts(
      "weilgen gap <machine> --data FILE [options]\n\n"
      "Sim-to-real gap diagnosis: identifies the model on the training part of the data and\n"
      "predicts the held-out part, localises the held-out residual against the noise floor\n"
      "(by output, coordinate, time, direction, cycle, temperatures, covariates), ranks the\n"
      "candidate unmodelled effects by held-out improvement with a test corrected for the extra\n"
      "parameters, and says how far the gap shrinks. docs/gap.md.\n\nOptions");
  std::string json_path, csv_path, report_path, plot_dir;
  const std::string effects_help =
      "candidate effects, comma-separated (default: the library: " + join(gap_effect_names()) + ")";
  opts.add_options()("help,h", "show this help")("data", po::value<std::string>(&rq.data),
                                                 "measurement CSV (docs/data-format.md)")(
      "holdout", po::value<std::string>(&rq.holdout)->default_value(rq.holdout),
      "cycle[:K] | time[:K] | space[:AXIS][:K] | forward[:FRACTION] | auto (cycle with >= 3 "
      "cycles, else time, else space)")(
      "effects", po::value<std::vector<std::string>>(&rq.effects)->composing(),
      effects_help.c_str())("at", po::value<std::vector<std::string>>(&rq.at)->composing(),
                            "coordinates the data do not list, e.g. X=0,Y=0,Z=0 (mm, deg)")(
      "pdge", po::value<std::vector<std::string>>(&rq.pdge)->composing(),
      "PDGE basis as for identify (poly:3, E_YY=fourier:3)")(
      "alpha", ranged(&rq.alpha, NumberRange::open(0, 0.5))->default_value(rq.alpha),
      "family-wise false-positive rate of each decision")(
      "json", po::value<std::string>(&json_path), "write the results as JSON to FILE")(
      "csv", po::value<std::string>(&csv_path),
      "write the candidate effects, one row each in ranking order, to FILE (CSV)")(
      "report", po::value<std::string>(&report_path), "write a Markdown report to FILE")(
      "plot", po::value<std::string>(&plot_dir),
      "draw residual-versus-coordinate and effect-ranking plots into DIR (PNG)")(
      "allow-unknown", "warn about unknown columns instead of failing")(
      "threads", ranged(&rq.threads, thread_range())->default_value(0),
      "worker threads (0 = all cores; the result is the same for any count)")(
      "quiet,q", po::bool_switch(&flags.quiet), "no model messages on stderr");
  opts.add(ballbar_circle_options(rq.circle));
  opts.add(model_options(flags));
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("gap", args, opts, "machine", 1, vm)) return *stop;
  fill_measurement_request(vm, flags, rq);
  try {
    rq.validate();
  } catch (const std::invalid_argument& e) {
    return usage_error("gap", e.what());
  }
  std::vector<PathArg> inputs = study_inputs(flags);
  inputs.push_back({"--data", rq.data});
  check_output_paths(inputs,
                     {{"--json", json_path}, {"--csv", csv_path}, {"--report", report_path}});
  check_output_dir(inputs, {"--plot", plot_dir});
  if (!plot_dir.empty()) check_plot_target(plot_dir + "/x.png");

  const GapRun run = run_gap(rq);
  std::cout << gap_text(run.result, *run.model, rq.data, false);
  const std::vector<std::string> pngs = plot_dir.empty()
                                            ? std::vector<std::string>{}
                                            : write_gap_plots(plot_dir, run.data, run.result);
  if (!report_path.empty())
    write_file_atomically(report_path,
                          gap_markdown(run.result, *run.model, rq.data, pngs, report_path));
  if (!json_path.empty())
    write_file_atomically(json_path, gap_json(run.result, *run.model, rq.data).dump(2) + "\n");
  if (!csv_path.empty()) write_file_atomically(csv_path, gap_csv(run.result, rq.data));
  return 0;
}

}  // namespace weilgen::cli
