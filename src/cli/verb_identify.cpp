// weilgen identify: fit a machine model's error parameters (PIGEs and PDGE basis coefficients)
// to point measurements, report what the data cannot identify, predict other measurements and
// write the parameters as a controller header. docs/identify.md.
#include <iostream>

#include "comp_table.hpp"
#include "study.hpp"
#include "verbs.hpp"
#include "weilgen/analysis/identify.hpp"
#include "weilgen/analysis/prediction.hpp"
#include "weilgen/analysis/study_spec.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/report/identify_document.hpp"
#include "weilgen/report/params_header.hpp"
#include "weilgen/report/prediction_document.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

int verb_identify(const Args& args) {
  StudyFlags flags;
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
  std::vector<std::string> data, pdge, fixed, predict;
  std::string json_path, csv_path, plot_path, emit, predict_out;
  BallbarFlags circle;
  double rank_tol = 1e-9;
  opts.add_options()("help,h", "show this help")(
      "data", po::value<std::vector<std::string>>(&data)->composing(),
      "measurement CSV (poses + deviations); repeatable")(
      "pdge", po::value<std::vector<std::string>>(&pdge)->composing(),
      "basis of every PDGE (poly:3, fourier:2, legendre:4, chebyshev:4, fourier:2:20 = period "
      "20 mm, or 20 deg on a rotary axis) or of one error (E_YY=fourier:3); repeatable, applied "
      "in order")(
      "fix", po::value<std::vector<std::string>>(&fixed)->composing(),
      "hold an error at zero: a name, an alias or group:<group> (as --set); repeatable")(
      "rank-tol", ranged(&rank_tol, NumberRange::open(0, 1))->default_value(rank_tol, "1e-9"),
      "singular values below rank-tol x the largest (equilibrated columns) count as zero")(
      "predict", po::value<std::vector<std::string>>(&predict)->composing(),
      "predict the deviations at the poses of a CSV (compared with its measured deviations "
      "when present) or a ballbar trace (angle_deg, or a '# plane:' header); repeatable")(
      "predict-out", po::value<std::string>(&predict_out),
      "write the predictions of the last --predict file to FILE (CSV)")(
      "json", po::value<std::string>(&json_path), "write the results as JSON to FILE")(
      "csv", po::value<std::string>(&csv_path),
      "write the parameters (value, standard error, unit, identifiable) to FILE (CSV)")(
      "plot", po::value<std::string>(&plot_path),
      "draw the residuals per output before and after, and the parameters with their 95 %\n"
      "intervals, to FILE (.png or .svg, gnuplot)")(
      "emit-params", po::value<std::string>(&emit),
      "write the identified parameters as a standalone C++ header to FILE")(
      "allow-unknown", "warn about unknown columns instead of failing")(
      "quiet,q", po::bool_switch(&flags.quiet), "no model messages on stderr");
  opts.add(ballbar_circle_options(circle));
  opts.add(model_options(flags));
  CompTableFlags comp;
  opts.add(comp_table_options(comp, true));
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("identify", args, opts, "machine", 1, vm)) return *stop;
  if (!vm.count("machine")) return usage_error("identify", "no machine given");
  if (data.empty()) return usage_error("identify", "no --data file given");
  if (!predict_out.empty() && predict.empty())
    return usage_error("identify", "--predict-out needs a --predict file");
  flags.machine = vm["machine"].as<std::string>();
  std::vector<PathArg> inputs = study_inputs(flags);
  for (const std::string& d : data) inputs.push_back({"--data", d});
  for (const std::string& p : predict) inputs.push_back({"--predict", p});
  check_output_paths(inputs, {{"--json", json_path},
                              {"--csv", csv_path},
                              {"--plot", plot_path},
                              {"--emit-params", emit},
                              {"--predict-out", predict_out},
                              {"--comp-table", comp.path}});
  if (!plot_path.empty()) check_plot_target(plot_path);
  check_comp_table_flags(comp, vm, true);

  // Every input read and every output checked before the work, so that nothing fails after it.
  const Description desc = load_machine_file(resolve_machine(flags.machine));
  if (!comp.path.empty()) check_axis_comp_table(desc, comp.options);
  const PdgeBasisChoice choice = parse_pdge_flags(desc, pdge);
  const ReadOptions ro = machine_read_options(desc, vm.count("allow-unknown") > 0);
  const auto warn = [](const std::string& w) { std::cerr << w << "\n"; };
  const PointData points = merged_point_data(data, desc, ro, warn);
  std::vector<MeasurementTable> predict_tables;
  for (const std::string& p : predict) {
    predict_tables.push_back(read_measurements(p, ro));
    for (const auto& w : predict_tables.back().warnings) warn(w);
  }
  if (!predict_out.empty() && is_ballbar_table(predict_tables.back()))
    throw std::invalid_argument("--predict-out: " + predict.back() +
                                " is a ballbar trace; the JSON carries its predicted trace");
  for (const std::string& f : fixed) select_errors(desc, f, "--fix " + quoted(f));
  const std::shared_ptr<Model> model = open_model(flags, desc);
  const ErrorParameterisation param(model->description(), choice, model->parameters());

  IdentifyOptions io;
  io.rank_tolerance = rank_tol;
  io.fixed = fixed;
  const IdentifyResult r = Identification(io).run(*model, param, points);
  const CompTable comp_table =
      comp.path.empty() ? CompTable{} : axis_comp_table(*model, param, r.theta, comp.options);
  std::cout << identify_text(*model, param, r, points);

  nlohmann::json j = identify_json(*model, param, r, data);
  j["predictions"] = nlohmann::json::array();
  for (std::size_t i = 0; i < predict.size(); ++i) {
    const MeasurementTable& t = predict_tables[i];
    if (is_ballbar_table(t)) {
      const BallbarPrediction bp = predict_ballbar_table(*model, param, r.theta, t, circle);
      std::cout << "\n" << ballbar_prediction_text(bp);
      j["predictions"].push_back(ballbar_prediction_json(bp));
      continue;
    }
    const Prediction pr = predict_table(*model, param, r.theta, t);
    std::cout << "\n" << prediction_text(pr);
    j["predictions"].push_back(prediction_json(pr));
    if (i + 1 == predict.size() && !predict_out.empty())
      write_file_atomically(predict_out, prediction_csv(pr, desc));
  }
  if (!emit.empty()) {
    write_file_atomically(emit, params_header(*model, param, r.theta, identify_provenance(r)));
    std::cout << "\nwrote " << emit << "\n";
  }
  if (!json_path.empty()) write_file_atomically(json_path, j.dump(2) + "\n");
  if (!csv_path.empty()) write_file_atomically(csv_path, identify_csv(*model, param, r));
  if (!plot_path.empty())
    write_plot(plot_path, identify_panels(param, r), "weilgen identify: " + model->name());
  if (!comp.path.empty()) std::cout << "\n" << write_comp_table(comp, comp_table);
  return 0;
}

}  // namespace weilgen::cli
