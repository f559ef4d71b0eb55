// weilgen.iso230_2, weilgen.fit_pdge, weilgen.identify, weilgen.gap: the verbs that read
// measurements. Keywords are the verbs' flags (docs/python.md); the requests, analyses and
// documents are the ones the verbs use.
#include "binding.hpp"
#include "weilgen/analysis/axis_comp_table.hpp"
#include "weilgen/analysis/ballbar_request.hpp"
#include "weilgen/analysis/gap_request.hpp"
#include "weilgen/analysis/identify_request.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/output_paths.hpp"
#include "weilgen/measure/instrument_import.hpp"
#include "weilgen/measure/iso230_2_flags.hpp"
#include "weilgen/measure/iso230_2_study.hpp"
#include "weilgen/measure/pdge_fit_study.hpp"
#include "weilgen/report/ballbar_document.hpp"
#include "weilgen/report/comp_table_document.hpp"
#include "weilgen/report/gap_document.hpp"
#include "weilgen/report/identify_document.hpp"
#include "weilgen/report/iso230_2_document.hpp"
#include "weilgen/report/iso230_2_html.hpp"
#include "weilgen/report/params_header.hpp"
#include "weilgen/report/pdge_fit_document.hpp"
#include "weilgen/report/plot.hpp"
#include "weilgen/report/prediction_document.hpp"

namespace weilgen::python {

namespace {

std::vector<const char*> with_model(std::initializer_list<const char*> own) {
  std::vector<const char*> v(own);
  for (const char* k : {"plane", "centre", "radius", "feed", "allow_unknown"}) v.push_back(k);
  for (const char* k : model_keywords()) v.push_back(k);
  return v;
}

// The keywords of each function: the flags of its verb (tests/python/test_parity.py compares
// them with `weilgen <verb> --flags-json`).
const std::vector<const char*>& iso230_2_keywords() {
  // One line per group of flags (clang-format would put one name per line).
  // clang-format off
  static const std::vector<const char*> v = {
      "axis", "column", "reference_position", "reference_cycle", "alpha", "target_tolerance",
      "allow_unknown", "csv", "plot",
      "comp_table", "comp_type", "comp_units", "comp_source",
      "format", "normalise", "expansion", "material_temperature", "air_compensation",
      "air_temperature", "air_pressure", "air_humidity", "wavelength", "air_index_assumed",
      "datum", "tolerance", "report", "iso_only", "uncertainty"};
  // clang-format on
  return v;
}
const std::vector<const char*>& fit_pdge_keywords() {
  static const std::vector<const char*> v = {"basis",
                                             "order",
                                             "min_order",
                                             "max_order",
                                             "period",
                                             "cv",
                                             "folds",
                                             "rule",
                                             "column",
                                             "axis",
                                             "travel",
                                             "keep_line",
                                             "angular_reference",
                                             "csv",
                                             "plot"};
  return v;
}
const std::vector<const char*>& identify_keywords() {
  static const std::vector<const char*> v =
      with_model({"data", "pdge", "fix", "rank_tol", "predict", "predict_out", "emit_params",
                  "emit_params_json", "csv", "plot", "comp_table", "comp_type", "comp_units",
                  "axis", "comp_points", "comp_at"});
  return v;
}
const std::vector<const char*>& ballbar_keywords() {
  static const std::vector<const char*> v =
      with_model({"machine", "feedrate", "alpha", "min_contribution", "pdge", "plot", "report"});
  return v;
}
const std::vector<const char*>& gap_keywords() {
  static const std::vector<const char*> v = with_model(
      {"data", "holdout", "effects", "at", "pdge", "alpha", "threads", "csv", "report", "plot"});
  return v;
}

// An output path keyword: "" when not given.
std::string output(const Keywords& kw, const char* name) {
  std::string path;
  kw.set(name, path);
  return path;
}

// The ballbar circle --plane --centre --radius --feed (centre also as a dict: {"X": 250,
// "Y": 0}), --allow-unknown, and the readers' warnings to `messages`.
void circle_keywords(const Keywords& kw, MeasurementRequest& rq, Messages& messages) {
  rq.allow_unknown = kw.flag("allow_unknown");
  kw.set("plane", rq.circle.plane);
  const std::vector<std::string> centre = kw.items("centre", true);
  if (!centre.empty()) rq.circle.centre = centre.front();
  kw.set("radius", rq.circle.radius);
  kw.set("feed", rq.circle.feed);
  rq.warn = messages.warn();
}

// The keywords identify and gap share: the machine and model keywords and circle_keywords.
void measurement_keywords(py::handle machine, const Keywords& kw, MeasurementRequest& rq,
                          Messages& messages) {
  model_request(machine, kw, rq.model, rq.opened);
  circle_keywords(kw, rq, messages);
}

// --comp-table FILE and its flags (docs/controllers.md), checked like the CLI checks them:
// identify's table along --axis (`model_axis`), or iso230-2's from the evaluation.
struct CompTableCall {
  std::string path;
  AxisCompTableOptions options;

  CompTableCall(const Keywords& kw, bool model_axis, const std::vector<PathArg>& inputs) {
    kw.set("comp_table", path);
    kw.set("comp_type", options.table.type);
    kw.set("comp_units", options.table.linear_unit);
    std::vector<const char*> names = {"comp_type", "comp_units"};
    if (model_axis) {
      kw.set("axis", options.axis);
      kw.set("comp_points", options.points);
      const std::vector<std::string> at = kw.items("comp_at", true);
      if (!at.empty()) options.at = at.front();
      names.insert(names.end(), {"axis", "comp_points", "comp_at"});
    } else {
      kw.set("comp_source", options.table.source);
      names.push_back("comp_source");
    }
    std::vector<std::string> given;
    for (const char* n : names)
      if (kw.given(n)) given.push_back(kw.flag_name(n));
    check_comp_table_flags(path, options, given, inputs, model_axis);
  }
  void write(const CompTable& table) const {
    if (!path.empty()) write_file_atomically(path, linuxcnc_comp_file(table, options.table.type));
  }
};

std::string data_path(py::handle data, const char* what) {
  if (data.is_none()) throw std::invalid_argument(std::string("no ") + what + " given");
  return value_text(data, what);
}

py::object iso230_2(py::handle data, const py::kwargs& kwargs) {
  const Keywords kw("iso230_2", kwargs, iso230_2_keywords());
  const std::string path = data_path(data, "data file");
  Iso230_2StudyOptions so;
  kw.set("axis", so.axis);
  kw.set("column", so.column);
  kw.set("alpha", so.drift.alpha);
  kw.set("target_tolerance", so.target_tolerance_mm);
  if (auto p = kw.number("reference_position")) so.drift.reference_position_mm = *p;
  if (auto c = kw.integer("reference_cycle")) so.drift.reference_cycle = *c;
  Iso230_2Flags flags;
  kw.set("format", flags.format);
  kw.set("normalise", flags.normalise);
  flags.iso_only = kw.flag("iso_only");
  flags.uncertainty = kw.text("uncertainty");
  flags.expansion_ppm_per_K = kw.number("expansion");
  flags.material_temperature = kw.text("material_temperature");
  flags.air_compensation = kw.text("air_compensation");
  flags.air_temperature = kw.text("air_temperature");
  flags.air_pressure = kw.text("air_pressure");
  flags.air_humidity = kw.text("air_humidity");
  flags.wavelength_nm = kw.number("wavelength");
  flags.air_index_assumed = kw.number("air_index_assumed");
  flags.datum_mm = kw.number("datum");
  kw.set("tolerance", flags.tolerance);
  kw.set("report", flags.report);
  ImportOptions io;
  io.read.allow_unknown = kw.flag("allow_unknown");
  io.axis = so.axis;
  flags.apply(so, io);
  const Iso230_2Study study(so);  // validates
  const std::string plot = output(kw, "plot"), csv = output(kw, "csv");
  const CompTableCall comp(kw, false, {{"data file", path}});
  check_output_paths(
      {{"data file", path}},
      {{"--plot", plot}, {"--csv", csv}, {"--report", flags.report}, {"--comp-table", comp.path}});
  if (!plot.empty()) check_plot_target(plot);
  Messages messages(true);
  const nlohmann::json doc = run_analysis([&] {
    const ImportResult imported = read_instrument_file(path, io);
    for (const auto& w : imported.table.warnings) messages.warn()(w);
    const Iso230_2StudyResult r = study.run(imported.table);
    for (const auto& w : r.normalisation.warnings) messages.warn()(w);
    const std::string format = to_string(imported.format);
    const CompTable comp_table =
        comp.path.empty() ? CompTable{} : comp_table_from_iso(r, comp.options.table);
    if (!plot.empty())
      write_plot(plot, iso230_2_panels(r), "ISO 230-2, " + r.columns.axis + ": " + path);
    if (!csv.empty()) write_file_atomically(csv, iso230_2_csv(r));
    if (!flags.report.empty()) write_file_atomically(flags.report, iso230_2_html(path, r, format));
    comp.write(comp_table);
    return iso230_2_json(path, r, format);
  });
  messages.issue();
  return to_python(doc);
}

py::object fit_pdge(py::handle data, const py::kwargs& kwargs) {
  const Keywords kw("fit_pdge", kwargs, fit_pdge_keywords());
  const std::string path = data_path(data, "data file");
  PdgeFitStudyOptions so;
  so.bases = kw.items("basis", false);
  kw.set("order", so.order);
  kw.set("min_order", so.min_order);
  kw.set("max_order", so.max_order);
  kw.set("period", so.period);
  kw.set("cv", so.cv);
  kw.set("folds", so.folds);
  kw.set("rule", so.rule);
  so.columns = kw.items("column", false);
  kw.set("axis", so.axis);
  kw.set("travel", so.travel);
  kw.set("keep_line", so.keep_line);
  kw.set("angular_reference", so.angular);
  const PdgeFitStudy study(so);  // validates
  const std::string plot = output(kw, "plot"), csv = output(kw, "csv");
  check_output_paths({{"data file", path}}, {{"--csv", csv}, {"--plot", plot}});
  if (!plot.empty()) check_plot_target(plot);
  Messages messages(true);
  const nlohmann::json doc = run_analysis([&] {
    const PdgeFitStudyResult r = study.run(path);
    for (const std::string& w : r.warnings) messages.warn()(w);
    if (!csv.empty()) write_file_atomically(csv, pdge_fit_csv(r));
    if (!plot.empty()) write_plot(plot, pdge_fit_panels(r), "weilgen fit-pdge: " + path);
    return pdge_fit_json(so, r);
  });
  messages.issue();
  return to_python(doc);
}

py::object identify(py::handle machine, const py::kwargs& kwargs) {
  const Keywords kw("identify", kwargs, identify_keywords());
  IdentifyRequest rq;
  Messages messages(kw.flag("quiet"));
  measurement_keywords(machine, kw, rq, messages);
  rq.data = kw.items("data", false);
  rq.pdge = kw.items("pdge", false);
  rq.fixed = kw.items("fix", false);
  rq.predict = kw.items("predict", false);
  kw.set("predict_out", rq.predict_out);
  kw.set("rank_tol", rq.rank_tolerance);
  const std::string emit = output(kw, "emit_params"), csv = output(kw, "csv"),
                    plot = output(kw, "plot"), emit_json = output(kw, "emit_params_json");
  rq.validate();
  std::vector<PathArg> inputs;
  for (const std::string& d : rq.data) inputs.push_back({"--data", d});
  for (const std::string& p : rq.predict) inputs.push_back({"--predict", p});
  const CompTableCall comp(kw, true, inputs);
  check_output_paths(inputs, {{"--csv", csv},
                              {"--plot", plot},
                              {"--emit-params", emit},
                              {"--emit-params-json", emit_json},
                              {"--predict-out", rq.predict_out},
                              {"--comp-table", comp.path}});
  if (!plot.empty()) check_plot_target(plot);
  std::vector<std::string> errors;
  const nlohmann::json doc = run_analysis([&] {
    if (!comp.path.empty()) check_axis_comp_table(rq.description(), comp.options);
    const IdentifyRun run = run_identify(rq);
    const CompTable comp_table =
        comp.path.empty() ? CompTable{}
                          : axis_comp_table(*run.model, *run.param, run.result.theta, comp.options);
    if (!rq.predict_out.empty())
      write_file_atomically(
          rq.predict_out, prediction_csv(*run.predictions.back().points, run.model->description()));
    if (!emit.empty())
      write_file_atomically(
          emit, params_header(*run.model, *run.param, run.result, identify_provenance(run.result)));
    if (!emit_json.empty())
      write_file_atomically(emit_json, params_json(*run.model, *run.param, run.result));
    if (!csv.empty()) write_file_atomically(csv, identify_csv(*run.model, *run.param, run.result));
    if (!plot.empty())
      write_plot(plot, identify_panels(*run.param, run.result),
                 "weilgen identify: " + run.model->name());
    comp.write(comp_table);
    errors = error_names(run.model->description());
    return identify_json(run);
  });
  messages.issue();
  return to_python(doc, errors);
}

py::object gap(py::handle machine, const py::kwargs& kwargs) {
  const Keywords kw("gap", kwargs, gap_keywords());
  GapRequest rq;
  Messages messages(kw.flag("quiet"));
  measurement_keywords(machine, kw, rq, messages);
  kw.set("data", rq.data);
  kw.set("holdout", rq.holdout);
  rq.effects = kw.items("effects", false);
  rq.at = kw.items("at", true);
  rq.pdge = kw.items("pdge", false);
  kw.set("alpha", rq.alpha);
  kw.set("threads", rq.threads);
  const std::string report = output(kw, "report"), plot_dir = output(kw, "plot"),
                    csv = output(kw, "csv");
  rq.validate();
  const std::vector<PathArg> inputs = {{"--data", rq.data}};
  check_output_paths(inputs, {{"--csv", csv}, {"--report", report}});
  check_output_dir(inputs, {"--plot", plot_dir});
  if (!plot_dir.empty()) check_plot_target(plot_dir + "/x.png");
  std::vector<std::string> errors;
  const nlohmann::json doc = run_analysis([&] {
    const GapRun run = run_gap(rq);
    const std::vector<std::string> pngs = plot_dir.empty()
                                              ? std::vector<std::string>{}
                                              : write_gap_plots(plot_dir, run.data, run.result);
    if (!report.empty())
      write_file_atomically(report, gap_markdown(run.result, *run.model, rq.data, pngs, report));
    if (!csv.empty()) write_file_atomically(csv, gap_csv(run.result, rq.data));
    errors = error_names(run.model->description());
    return gap_json(run.result, *run.model, rq.data);
  });
  messages.issue();
  return to_python(doc, errors);
}

// weilgen ballbar (issue 29): a trace on its own, or through a machine's model (machine=).
py::object ballbar(py::handle trace, const py::kwargs& kwargs) {
  const Keywords kw("ballbar", kwargs, ballbar_keywords());
  BallbarRequest rq;
  Messages messages(kw.flag("quiet"));
  rq.trace = data_path(trace, "trace file");
  if (kwargs.contains("machine") && !kwargs["machine"].is_none()) {
    model_request(kwargs["machine"], kw, rq.model, rq.opened);
  } else {
    for (const char* k : {"order", "engine", "compiler", "param", "pdge"})
      if (kw.given(k))
        throw std::invalid_argument(kw.flag_name(k) + ": the model's terms need machine=");
    rq.model.log = messages.log();
  }
  circle_keywords(kw, rq, messages);
  kw.set("feedrate", rq.feedrate);
  kw.set("alpha", rq.alpha);
  kw.set("min_contribution", rq.min_contribution_um);
  if (kw.given("pdge")) rq.pdge = kw.items("pdge", false);
  const std::string plot = output(kw, "plot"), report = output(kw, "report");
  rq.validate();
  rq.check_outputs("", plot, report);
  const nlohmann::json doc = run_analysis([&] {
    const BallbarStudy st = run_ballbar(rq);
    if (!plot.empty()) write_file_atomically(plot, ballbar_polar_svg(st));
    if (!report.empty()) write_file_atomically(report, ballbar_html(st));
    return ballbar_json(st);
  });
  messages.issue();
  return to_python(doc);
}

}  // namespace

void register_data_functions(py::module_& m) {
  // The documented functions are the package's (weilgen/_verbs.py, generated from the CLI's
  // flags, with signatures and docstrings); these take the keywords.
  const auto add = [&](const char* name, py::object (*f)(py::handle, const py::kwargs&),
                       const char* positional, const std::vector<const char*>& keywords) {
    m.def(name, f, py::arg(positional));
    implemented_keywords()[name].assign(keywords.begin(), keywords.end());
  };
  add("iso230_2", &iso230_2, "data", iso230_2_keywords());
  add("fit_pdge", &fit_pdge, "data", fit_pdge_keywords());
  add("identify", &identify, "machine", identify_keywords());
  add("gap", &gap, "machine", gap_keywords());
  add("ballbar", &ballbar, "trace", ballbar_keywords());
}

}  // namespace weilgen::python
