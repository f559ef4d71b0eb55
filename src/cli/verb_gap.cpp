// weilgen gap: where a machine's model and its measurements disagree, which unmodelled effect
// causes it and how far the gap shrinks once it is modelled (docs/gap.md, JSON schema there).
#include <filesystem>
#include <iostream>

#include "study.hpp"
#include "verbs.hpp"
#include "weilgen/analysis/gap.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/report/gap_document.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

int verb_gap(const Args& args) {
  StudyFlags flags;
  po::options_description opts(
      "weilgen gap <machine> --data FILE [options]\n\n"
      "Sim-to-real gap diagnosis: identifies the model on the training part of the data and\n"
      "predicts the held-out part, localises the held-out residual against the noise floor\n"
      "(by output, coordinate, time, direction, cycle, temperatures, covariates), ranks the\n"
      "candidate unmodelled effects by held-out improvement with a test corrected for the extra\n"
      "parameters, and says how far the gap shrinks. docs/gap.md.\n\nOptions");
  std::string data, holdout = "auto", json_path, csv_path, report_path, plot_dir;
  std::vector<std::string> effects, pdge, at;
  double alpha = 0.01;
  unsigned threads = 0;
  opts.add_options()("help,h", "show this help")("data", po::value<std::string>(&data),
                                                 "measurement CSV (docs/data-format.md)")(
      "holdout", po::value<std::string>(&holdout)->default_value(holdout),
      "cycle[:K] | time[:K] | space[:AXIS][:K] | forward[:FRACTION] | auto (cycle with >= 3 "
      "cycles, else time, else space)")(
      "effects", po::value<std::vector<std::string>>(&effects)->composing(),
      "candidate effects, comma-separated (default: the library: thermal_drift, reversal, "
      "periodic, pdge_shape, higher_order, missing_error, tool_offset, setup)")(
      "at", po::value<std::vector<std::string>>(&at)->composing(),
      "coordinates the data do not list, e.g. X=0,Y=0,Z=0 (mm, deg)")(
      "pdge", po::value<std::vector<std::string>>(&pdge)->composing(),
      "PDGE basis as for identify (poly:3, E_YY=fourier:3)")(
      "alpha", ranged(&alpha, NumberRange::open(0, 0.5))->default_value(alpha),
      "family-wise false-positive rate of each decision")(
      "json", po::value<std::string>(&json_path), "write the results as JSON to FILE")(
      "csv", po::value<std::string>(&csv_path),
      "write the candidate effects, one row each in ranking order, to FILE (CSV)")(
      "report", po::value<std::string>(&report_path), "write a Markdown report to FILE")(
      "plot", po::value<std::string>(&plot_dir),
      "draw residual-versus-coordinate and effect-ranking plots into DIR (PNG)")(
      "allow-unknown", "warn about unknown columns instead of failing")(
      "threads", ranged(&threads, thread_range())->default_value(0),
      "worker threads (0 = all cores; the result is the same for any count)")(
      "quiet,q", po::bool_switch(&flags.quiet), "no model messages on stderr");
  BallbarFlags circle;
  opts.add(ballbar_circle_options(circle));
  opts.add(model_options(flags));
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("gap", args, opts, "machine", 1, vm)) return *stop;
  if (!vm.count("machine")) return usage_error("gap", "no machine given");
  if (data.empty()) return usage_error("gap", "no --data file given");
  flags.machine = vm["machine"].as<std::string>();
  std::vector<PathArg> inputs = study_inputs(flags);
  inputs.push_back({"--data", data});
  check_output_paths(inputs,
                     {{"--json", json_path}, {"--csv", csv_path}, {"--report", report_path}});
  check_output_dir(inputs, {"--plot", plot_dir});
  GapOptions go;
  for (const std::string& e : effects)
    for (const std::string& n : split(e, ',')) go.effects.push_back(trim(n));
  go.alpha = alpha;
  go.threads = threads;
  try {
    go.validate();
  } catch (const std::invalid_argument& e) {
    return usage_error("gap", e.what());
  }
  const std::optional<HoldoutScheme> given = parse_holdout(holdout);
  if (!plot_dir.empty()) check_plot_target(plot_dir + "/x.png");

  const Description desc = load_machine_file(resolve_machine(flags.machine));
  try {
    go.fixed = parse_fixed_coordinates(desc, at);
  } catch (const std::invalid_argument& e) {
    return usage_error("gap", e.what());
  }
  const std::shared_ptr<Model> model = open_model(flags, desc);
  const ErrorParameterisation param(model->description(), parse_pdge_flags(desc, pdge),
                                    model->parameters());
  const MeasurementTable table =
      read_measurements(data, machine_read_options(desc, vm.count("allow-unknown") > 0));
  for (const auto& w : table.warnings) std::cerr << w << "\n";
  const GapData gd = gap_data(table, desc, go.fixed, circle, model->parameters());
  const HoldoutScheme scheme = given ? *given : default_holdout(gd);
  const GapResult r =
      GapDiagnosis(go).run(*model, param, gd, scheme, holdout_reason(scheme, given.has_value()));
  std::cout << gap_text(r, *model, data, false);

  std::vector<std::string> pngs;
  if (!plot_dir.empty()) {
    std::filesystem::create_directories(plot_dir);
    for (const GapPlot& p : gap_plots(gd, r)) {
      pngs.push_back(plot_dir + "/" + p.stem + ".png");
      write_plot(pngs.back(), p.panels, p.title);
    }
  }
  if (!report_path.empty())
    write_file_atomically(report_path, gap_markdown(r, *model, data, pngs, report_path));
  if (!json_path.empty())
    write_file_atomically(json_path, gap_json(r, *model, data).dump(2) + "\n");
  if (!csv_path.empty()) write_file_atomically(csv_path, gap_csv(r, data));
  return 0;
}

}  // namespace weilgen::cli
