// weilgen identify: fit a machine model's error parameters (PIGEs and PDGE basis coefficients)
// to point measurements, report what the data cannot identify, predict other measurements and
// write the parameters as a controller header. docs/identify.md.
#include <iostream>

#include "comp_table.hpp"
#include "flags.hpp"
#include "study.hpp"
#include "verbs.hpp"
#include "weilgen/analysis/identify_request.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/report/identify_document.hpp"
#include "weilgen/report/params_header.hpp"
#include "weilgen/report/plot.hpp"
#include "weilgen/report/prediction_document.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

int verb_identify(const Args& args) {
  StudyFlags flags;
  IdentifyRequest rq;
  po::options_description opts(
      "weilgen identify <machine> --data FILE [options]\n\n"
      "Fits the model's error parameters to point measurements (docs/data-format.md): each\n"
      "PIGE a constant, each PDGE a basis in its own axis position (the machine file's\n"
      "pdge_basis / basis:, else poly:3 on a linear axis and fourier:2 with a one-turn period\n"
      "on a rotary one; --pdge overrides). Linear least squares through the\n"
      "generated coefficient matrix (column-equilibrated SVD: minimum-norm solution, rank, the\n"
      "parameter combinations the data cannot identify); Gauss-Newton for order >= 2. Predicts\n"
      "other measurements (points, ballbar circles) and writes the parameters as a standalone\n"
      "controller header. docs/identify.md.\n\nOptions");
  std::string json_path, csv_path, plot_path, emit, emit_json;
  opts.add_options()("help,h", "show this help")(
      "data", po::value<std::vector<std::string>>(&rq.data)->composing(),
      "measurement CSV (poses + deviations); repeatable")(
      "pdge", po::value<std::vector<std::string>>(&rq.pdge)->composing(),
      "basis of every PDGE (poly:3, fourier:2, legendre:4, chebyshev:4, fourier:2:20 = period "
      "20 mm, or 20 deg on a rotary axis) or of one error (E_YY=fourier:3); repeatable, applied "
      "in order")(
      "fix", po::value<std::vector<std::string>>(&rq.fixed)->composing(),
      "hold an error at zero: a name, an alias or group:<group> (as --set); repeatable")(
      "rank-tol",
      ranged(&rq.rank_tolerance, NumberRange::open(0, 1))->default_value(rq.rank_tolerance, "1e-9"),
      "singular values below rank-tol x the largest (equilibrated columns) count as zero")(
      "predict", po::value<std::vector<std::string>>(&rq.predict)->composing(),
      "predict the deviations at the poses of a CSV (compared with its measured deviations "
      "when present) or a ballbar trace (angle_deg, or a '# plane:' header); repeatable")(
      "predict-out", po::value<std::string>(&rq.predict_out),
      "write the predictions of the last --predict file to FILE (CSV)")(
      "json", po::value<std::string>(&json_path), "write the results as JSON to FILE")(
      "csv", po::value<std::string>(&csv_path),
      "write the parameters (value, standard error, unit, identifiable) to FILE (CSV)")(
      "plot", po::value<std::string>(&plot_path),
      "draw the residuals per output before and after, and the parameters with their 95 %\n"
      "intervals, to FILE (.png or .svg, gnuplot)")(
      "emit-params", po::value<std::string>(&emit),
      "write the identified parameters as a standalone C++ header to FILE")(
      "emit-params-json", po::value<std::string>(&emit_json),
      "write the identified parameters as JSON to FILE (loaded at run time by a controller: the\n"
      "LinuxCNC component's params_file, docs/controllers.md)")(
      "allow-unknown", "warn about unknown columns instead of failing")(
      "quiet,q", po::bool_switch(&flags.quiet), "no model messages on stderr");
  opts.add(ballbar_circle_options(rq.circle));
  opts.add(model_options(flags));
  CompTableFlags comp;
  opts.add(comp_table_options(comp, true));
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("identify", args, opts, "machine", 1, vm)) return *stop;
  fill_measurement_request(vm, flags, rq);
  try {
    rq.validate();
  } catch (const std::invalid_argument& e) {
    return usage_error("identify", e.what());
  }
  std::vector<PathArg> inputs = study_inputs(flags);
  for (const std::string& d : rq.data) inputs.push_back({"--data", d});
  for (const std::string& p : rq.predict) inputs.push_back({"--predict", p});
  check_output_paths(inputs, {{"--json", json_path},
                              {"--csv", csv_path},
                              {"--plot", plot_path},
                              {"--emit-params", emit},
                              {"--emit-params-json", emit_json},
                              {"--predict-out", rq.predict_out},
                              {"--comp-table", comp.path}});
  if (!plot_path.empty()) check_plot_target(plot_path);
  check_comp_table_flags(comp, vm, true);
  if (!comp.path.empty()) check_axis_comp_table(rq.description(), comp.options);

  const IdentifyRun run = run_identify(rq);
  const CompTable comp_table =
      comp.path.empty() ? CompTable{}
                        : axis_comp_table(*run.model, *run.param, run.result.theta, comp.options);
  std::cout << identify_text(run);
  if (!rq.predict_out.empty())
    write_file_atomically(rq.predict_out,
                          prediction_csv(*run.predictions.back().points, run.model->description()));
  if (!emit.empty()) {
    write_file_atomically(
        emit, params_header(*run.model, *run.param, run.result, identify_provenance(run.result)));
    std::cout << "\nwrote " << emit << "\n";
  }
  if (!emit_json.empty()) {
    write_file_atomically(emit_json, params_json(*run.model, *run.param, run.result));
    std::cout << "\nwrote " << emit_json << "\n";
  }
  if (!json_path.empty()) write_file_atomically(json_path, identify_json(run).dump(2) + "\n");
  if (!csv_path.empty())
    write_file_atomically(csv_path, identify_csv(*run.model, *run.param, run.result));
  if (!plot_path.empty())
    write_plot(plot_path, identify_panels(*run.param, run.result),
               "weilgen identify: " + run.model->name());
  if (!comp.path.empty()) std::cout << "\n" << write_comp_table(comp, comp_table);
  return 0;
}

}  // namespace weilgen::cli
