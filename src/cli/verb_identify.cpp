// weilgen identify: fit a machine model's error parameters (PIGEs and PDGE basis coefficients)
// to point measurements, report what the data cannot identify, predict other measurements and
// write the parameters as a controller header. docs/identify.md.
#include <iomanip>
#include <iostream>
#include <sstream>

#include "prediction.hpp"
#include "study.hpp"
#include "verbs.hpp"
#include "weilgen/analysis/identify.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/measure/measurement_csv.hpp"
#include "weilgen/report/params_header.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

namespace {

using nlohmann::json;

std::string fmt(double v, int precision = 3) {
  if (!std::isfinite(v)) return "-";
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

// All --data files as one set of observations (rows keep their file for messages).
PointData merged_data(const std::vector<std::string>& files, const Description& desc,
                      const ReadOptions& ro) {
  PointData all;
  for (const std::string& f : files) {
    const MeasurementTable t = read_measurements(f, ro);
    for (const auto& w : t.warnings) std::cerr << w << "\n";
    PointData d = point_data(t, desc);
    const std::size_t base = all.poses.size();
    for (auto& p : d.poses) all.poses.push_back(std::move(p));
    for (PointObservation ob : d.observations) {
      ob.row += base;
      all.observations.push_back(ob);
    }
    for (std::size_t o = 0; o < 6; ++o) all.count[o] += d.count[o];
    all.file += (all.file.empty() ? "" : ", ") + f;
  }
  return all;
}

json result_json(const Model& model, const ErrorParameterisation& param, const IdentifyResult& r,
                 const std::vector<std::string>& files) {
  const Description& d = model.description();
  json params = json::array();
  for (std::size_t p = 0; p < param.size(); ++p) {
    const IdentParameter& ip = param.parameters()[p];
    const auto& basis = param.basis_of(static_cast<std::size_t>(ip.error));
    params.push_back({{"label", ip.label},
                      {"error", d.errors[static_cast<std::size_t>(ip.error)].name},
                      {"basis", basis ? basis->name() : "constant"},
                      {"term", ip.term},
                      {"value", json_number(r.theta[p])},
                      {"standard_error", json_number(r.standard_error[p])},
                      {"unit", ip.unit},
                      {"identifiable", static_cast<bool>(r.identifiable[p])},
                      {"fixed", static_cast<bool>(r.fixed[p])}});
  }
  json bases = json::object();
  for (std::size_t k = 0; k < d.errors.size(); ++k) {
    const auto& b = param.basis_of(k);
    if (b)
      bases[d.errors[k].name] = {{"basis", b->name()},
                                 {"coordinate", param.coordinate_of(k)},
                                 {"from", b->a},
                                 {"to", b->b}};
  }
  json null = json::array();
  for (const NullCombination& c : r.unidentifiable) {
    json terms = json::array();
    for (const auto& [p, v] : c.terms)
      terms.push_back({{"parameter", param.parameters()[p].label}, {"coefficient", v}});
    null.push_back({{"text", c.str(param.parameters())}, {"terms", terms}});
  }
  json outputs = json::object();
  for (int o = 0; o < 6; ++o) {
    if (!r.count[static_cast<std::size_t>(o)]) continue;
    const std::string u = o < 3 ? "_um" : "_urad";
    outputs[output_name(static_cast<std::size_t>(o))] = {
        {"observations", r.count[static_cast<std::size_t>(o)]},
        {"rms_before" + u, json_number(r.rms_before[static_cast<std::size_t>(o)])},
        {"rms_after" + u, json_number(r.rms_after[static_cast<std::size_t>(o)])},
        {"max_after" + u, json_number(r.max_after[static_cast<std::size_t>(o)])}};
  }
  return {{"weilgen", kVersion},
          {"model", model_json(model)},
          {"data", files},
          {"observations", r.observations},
          {"parameters", params},
          {"bases", bases},
          {"free_parameters", r.free_parameters},
          {"rank", r.rank},
          {"condition", json_number(r.condition)},
          {"singular_values", r.singular_values},
          {"unidentifiable", null},
          {"residual_sigma", json_number(r.residual_sigma)},
          {"gauss_newton_iterations", r.gauss_newton_iterations},
          {"outputs", outputs}};
}

void print_result(std::ostream& os, const Model& model, const ErrorParameterisation& param,
                  const IdentifyResult& r, const PointData& data) {
  const Description& d = model.description();
  os << "identify " << d.name << " (order " << model.order() << ", " << model.origin()
     << "): " << r.observations << " observations from " << data.file << " (";
  bool first = true;
  for (int o = 0; o < 6; ++o)
    if (r.count[static_cast<std::size_t>(o)])
      os << (first ? "" : ", ") << output_name(static_cast<std::size_t>(o)) << " "
         << r.count[static_cast<std::size_t>(o)],
          first = false;
  os << ")\n";
  std::map<std::string, int> kinds;
  for (std::size_t k = 0; k < d.errors.size(); ++k)
    ++kinds[param.basis_of(k) ? param.basis_of(k)->name() : std::string("constant")];
  os << "parameters: " << param.size() << " for " << d.errors.size() << " errors (";
  first = true;
  for (const auto& [k, n] : kinds) os << (first ? "" : ", ") << n << " " << k, first = false;
  os << ")";
  if (r.free_parameters < param.size()) os << ", " << param.size() - r.free_parameters << " fixed";
  os << "\nrank " << r.rank << " of " << r.free_parameters << " (condition " << fmt(r.condition)
     << ")";
  if (!r.unidentifiable.empty())
    os << ": " << r.unidentifiable.size() << " combination"
       << (r.unidentifiable.size() > 1 ? "s" : "") << " not identifiable (below)";
  os << "\nresidual sigma " << fmt(r.residual_sigma) << " (µm, µrad as measured)";
  if (r.gauss_newton_iterations) os << ", " << r.gauss_newton_iterations << " Gauss-Newton steps";
  os << "\n\noutput  rms before  rms after  max after\n";
  for (int o = 0; o < 6; ++o) {
    const auto u = static_cast<std::size_t>(o);
    if (!r.count[u]) continue;
    os << std::left << std::setw(8) << output_name(u) << std::right << std::setw(10)
       << fmt(r.rms_before[u]) << std::setw(11) << fmt(r.rms_after[u]) << std::setw(11)
       << fmt(r.max_after[u]) << "  " << observation_unit(static_cast<std::size_t>(o)) << "\n";
  }
  os << "\nparameter" << std::string(16, ' ') << "value      ± s.e.  unit\n";
  for (std::size_t p = 0; p < param.size(); ++p) {
    const IdentParameter& ip = param.parameters()[p];
    os << std::left << std::setw(24) << ip.label << std::right << std::setw(10)
       << (r.fixed[p] ? "fixed" : fmt(r.theta[p], 4)) << std::setw(10)
       << (r.identifiable[p] ? fmt(r.standard_error[p], 2) : std::string("n.i.")) << "  " << ip.unit
       << "\n";
  }
  if (!r.unidentifiable.empty()) {
    os << "\nNot identifiable from these data (n.i.): adding any multiple of a combination "
          "changes\nno prediction at the measured poses; the values above are the minimum-norm "
          "choice.\n";
    for (std::size_t i = 0; i < r.unidentifiable.size(); ++i)
      os << "  " << i + 1 << ". " << r.unidentifiable[i].str(param.parameters()) << "\n";
  }
}

}  // namespace

int verb_identify(const Args& args) {
  StudyFlags flags;
  po::options_description opts(
      "weilgen identify <machine> --data FILE [options]\n\n"
      "Fits the model's error parameters to point measurements (docs/data-format.md): each\n"
      "PIGE a constant, each PDGE a basis in its own axis position (the machine file's\n"
      "pdge_basis / basis:, else poly:3; --pdge overrides). Linear least squares through the\n"
      "generated coefficient matrix (column-equilibrated SVD: minimum-norm solution, rank, the\n"
      "parameter combinations the data cannot identify); Gauss-Newton for order >= 2. Predicts\n"
      "other measurements (points, ballbar circles) and writes the parameters as a standalone\n"
      "controller header. docs/identify.md.\n\nOptions");
  std::vector<std::string> data, pdge, fixed, predict;
  std::string json_path, emit, predict_out;
  BallbarFlags circle;
  double rank_tol = 1e-9;
  opts.add_options()("help,h", "show this help")(
      "data", po::value<std::vector<std::string>>(&data)->composing(),
      "measurement CSV (poses + deviations); repeatable")(
      "pdge", po::value<std::vector<std::string>>(&pdge)->composing(),
      "basis of every PDGE (poly:3, fourier:2, legendre:4, chebyshev:4, fourier:2:20 = period "
      "20 mm) or of one error (E_YY=fourier:3); repeatable, applied in order")(
      "fix", po::value<std::vector<std::string>>(&fixed)->composing(),
      "hold an error at zero (name or alias); repeatable")(
      "rank-tol", po::value<double>(&rank_tol)->default_value(rank_tol, "1e-9"),
      "singular values below rank-tol x the largest (equilibrated columns) count as zero")(
      "predict", po::value<std::vector<std::string>>(&predict)->composing(),
      "predict the deviations at the poses of a CSV (compared with its measured deviations "
      "when present) or a ballbar trace (angle_deg, or a '# plane:' header); repeatable")(
      "predict-out", po::value<std::string>(&predict_out),
      "write the predictions of the last --predict file to FILE (CSV)")(
      "json", po::value<std::string>(&json_path), "write the results as JSON to FILE")(
      "emit-params", po::value<std::string>(&emit),
      "write the identified parameters as a standalone C++ header to FILE")(
      "allow-unknown", "warn about unknown columns instead of failing")(
      "quiet,q", po::bool_switch(&flags.quiet), "no model messages on stderr");
  opts.add(ballbar_circle_options(circle));
  opts.add(model_options(flags));
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("identify", args, opts, "machine", 1, vm)) return *stop;
  if (!vm.count("machine")) return usage_error("identify", "no machine given");
  if (data.empty()) return usage_error("identify", "no --data file given");
  if (!(rank_tol > 0 && rank_tol < 1))
    return usage_error("identify", "--rank-tol must be in (0, 1)");
  if (!predict_out.empty() && predict.empty())
    return usage_error("identify", "--predict-out needs a --predict file");
  flags.machine = vm["machine"].as<std::string>();

  const Description desc = load_machine_file(resolve_machine(flags.machine));
  const PdgeBasisChoice choice = parse_pdge_flags(desc, pdge);
  const std::shared_ptr<Model> model = open_model(flags, desc);
  const ErrorParameterisation param(model->description(), choice, model->parameters());
  const ReadOptions ro = machine_read_options(desc, vm.count("allow-unknown") > 0);
  const PointData points = merged_data(data, desc, ro);

  IdentifyOptions io;
  io.rank_tolerance = rank_tol;
  io.fixed = fixed;
  Identification ident(*model, param, io);
  ident.run(points);
  const IdentifyResult& r = ident.result();
  print_result(std::cout, *model, param, r, points);

  json j = result_json(*model, param, r, data);
  j["predictions"] = json::array();
  for (std::size_t i = 0; i < predict.size(); ++i) {
    const MeasurementTable t = read_measurements(predict[i], ro);
    if (is_ballbar_table(t)) {
      if (i + 1 == predict.size() && !predict_out.empty())
        throw std::invalid_argument("--predict-out: " + predict[i] +
                                    " is a ballbar trace; the JSON carries its predicted trace");
      const BallbarPrediction bp = predict_ballbar_table(*model, param, r.theta, t, circle);
      std::cout << "\n";
      print_ballbar_prediction(std::cout, bp);
      j["predictions"].push_back(ballbar_prediction_json(bp));
      continue;
    }
    const Prediction pr = predict_table(*model, param, r.theta, t);
    std::cout << "\n";
    print_prediction(std::cout, pr);
    j["predictions"].push_back(prediction_json(pr));
    if (i + 1 == predict.size() && !predict_out.empty())
      write_output(predict_out, prediction_csv(pr, desc));
  }
  if (!emit.empty()) {
    write_output(emit, params_header(*model, param, r.theta, identify_provenance(r)));
    std::cout << "\nwrote " << emit << "\n";
  }
  if (!json_path.empty()) write_output(json_path, j.dump(2) + "\n");
  return 0;
}

}  // namespace weilgen::cli
