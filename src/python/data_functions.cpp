// weilgen.iso230_2, weilgen.fit_pdge, weilgen.identify, weilgen.gap: the verbs that read
// measurements. Keywords are the verbs' flags (docs/python.md); the requests, analyses and
// documents are the ones the verbs use.
#include "binding.hpp"
#include "weilgen/analysis/axis_comp_table.hpp"
#include "weilgen/analysis/ballbar_request.hpp"
#include "weilgen/analysis/gap_request.hpp"
#include "weilgen/analysis/identify_request.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/measure/instrument_import.hpp"
#include "weilgen/measure/iso230_2_study.hpp"
#include "weilgen/measure/pdge_fit_study.hpp"
#include "weilgen/report/ballbar_document.hpp"
#include "weilgen/report/comp_table_document.hpp"
#include "weilgen/report/gap_document.hpp"
#include "weilgen/report/identify_document.hpp"
#include "weilgen/report/iso230_2_document.hpp"
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
  const Keywords kw("iso230_2", kwargs,
                    {"axis", "column", "reference_position", "reference_cycle", "alpha",
                     "target_tolerance", "allow_unknown", "plot", "comp_table", "comp_type",
                     "comp_units", "comp_source", "normalise", "iso_only", "uncertainty"});
  const std::string path = data_path(data, "data file");
  Iso230_2StudyOptions so;
  kw.set("axis", so.axis);
  kw.set("column", so.column);
  kw.set("alpha", so.drift.alpha);
  kw.set("target_tolerance", so.target_tolerance_mm);
  if (auto p = kw.number("reference_position")) so.drift.reference_position_mm = *p;
  if (auto c = kw.integer("reference_cycle")) so.drift.reference_cycle = *c;
  // --normalise, --iso-only, --uncertainty (issue 29's flags).
  std::string normalise, uncertainty;
  kw.set("normalise", normalise);
  if (!normalise.empty()) so.normalisation.mode = parse_normalise_mode(normalise);
  so.iso_only = kw.flag("iso_only");
  kw.set("uncertainty", uncertainty);
  if (!uncertainty.empty()) so.uncertainty = uncertainty_budget_from_flag(uncertainty);
  const Iso230_2Study study(so);  // validates
  // Laser exports too (format auto, as the CLI's default): their compensation state counts.
  ImportOptions io;
  io.read.allow_unknown = kw.flag("allow_unknown");
  io.axis = so.axis;
  std::string plot;
  kw.set("plot", plot);
  if (!plot.empty()) check_plot_target(plot);
  const CompTableCall comp(kw, false, {{"data file", path}});
  Messages messages(true);
  const nlohmann::json doc = without_gil([&] {
    const ImportResult imported = read_instrument_file(path, io);
    for (const auto& w : imported.table.warnings) messages.warn()(w);
    const Iso230_2StudyResult r = study.run(imported.table);
    for (const auto& w : r.normalisation.warnings) messages.warn()(w);
    const CompTable comp_table =
        comp.path.empty() ? CompTable{} : comp_table_from_iso(r, comp.options.table);
    if (!plot.empty())
      write_plot(plot, iso230_2_panels(r), "ISO 230-2, " + r.columns.axis + ": " + path);
    comp.write(comp_table);
    return iso230_2_json(path, r, to_string(imported.format));
  });
  messages.issue();
  return to_python(doc);
}

py::object fit_pdge(py::handle data, const py::kwargs& kwargs) {
  const Keywords kw("fit_pdge", kwargs,
                    {"basis", "order", "min_order", "max_order", "period", "cv", "folds", "rule",
                     "column", "axis", "travel", "keep_line", "angular_reference", "plot"});
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
  std::string plot;
  kw.set("plot", plot);
  const nlohmann::json doc = without_gil([&] {
    if (!plot.empty()) check_plot_target(plot);
    const PdgeFitStudyResult r = study.run(path);
    if (!plot.empty()) write_plot(plot, pdge_fit_panels(r), "weilgen fit-pdge: " + path);
    return pdge_fit_json(so, r);
  });
  return to_python(doc);
}

py::object identify(py::handle machine, const py::kwargs& kwargs) {
  const Keywords kw(
      "identify", kwargs,
      with_model({"data", "pdge", "fix", "rank_tol", "predict", "predict_out", "emit_params",
                  "comp_table", "comp_type", "comp_units", "axis", "comp_points", "comp_at"}));
  IdentifyRequest rq;
  Messages messages(kw.flag("quiet"));
  measurement_keywords(machine, kw, rq, messages);
  rq.data = kw.items("data", false);
  rq.pdge = kw.items("pdge", false);
  rq.fixed = kw.items("fix", false);
  rq.predict = kw.items("predict", false);
  kw.set("predict_out", rq.predict_out);
  kw.set("rank_tol", rq.rank_tolerance);
  std::string emit;
  kw.set("emit_params", emit);
  rq.validate();
  std::vector<PathArg> inputs;
  for (const std::string& d : rq.data) inputs.push_back({"--data", d});
  for (const std::string& p : rq.predict) inputs.push_back({"--predict", p});
  const CompTableCall comp(kw, true, inputs);
  const nlohmann::json doc = without_gil([&] {
    if (!comp.path.empty()) check_axis_comp_table(rq.description(), comp.options);
    const IdentifyRun run = run_identify(rq);
    const CompTable comp_table =
        comp.path.empty() ? CompTable{}
                          : axis_comp_table(*run.model, *run.param, run.result.theta, comp.options);
    if (!rq.predict_out.empty())
      write_file_atomically(
          rq.predict_out, prediction_csv(*run.predictions.back().points, run.model->description()));
    if (!emit.empty())
      write_file_atomically(emit, params_header(*run.model, *run.param, run.result.theta,
                                                identify_provenance(run.result)));
    comp.write(comp_table);
    return identify_json(run);
  });
  messages.issue();
  return to_python(doc);
}

py::object gap(py::handle machine, const py::kwargs& kwargs) {
  const Keywords kw("gap", kwargs,
                    with_model({"data", "holdout", "effects", "at", "pdge", "alpha", "threads",
                                "report", "plot"}));
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
  std::string report, plot_dir;
  kw.set("report", report);
  kw.set("plot", plot_dir);
  rq.validate();
  const nlohmann::json doc = without_gil([&] {
    if (!plot_dir.empty()) check_plot_target(plot_dir + "/x.png");
    const GapRun run = run_gap(rq);
    const std::vector<std::string> pngs = plot_dir.empty()
                                              ? std::vector<std::string>{}
                                              : write_gap_plots(plot_dir, run.data, run.result);
    if (!report.empty())
      write_file_atomically(report, gap_markdown(run.result, *run.model, rq.data, pngs, report));
    return gap_json(run.result, *run.model, rq.data);
  });
  messages.issue();
  return to_python(doc);
}

}  // namespace

// weilgen ballbar (issue 29): a trace on its own, or through a machine's model (machine=).
py::object ballbar(py::handle trace, const py::kwargs& kwargs) {
  std::vector<const char*> names = {"machine", "feedrate", "alpha",  "min_contribution",
                                    "pdge",    "plot",     "report", "plane",
                                    "centre",  "radius",   "feed",   "allow_unknown"};
  for (const char* k : model_keywords()) names.push_back(k);
  const Keywords kw("ballbar", kwargs, names);
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
  std::string plot, report;
  kw.set("plot", plot);
  kw.set("report", report);
  rq.validate();
  rq.check_outputs("", plot, report);
  const nlohmann::json doc = without_gil([&] {
    const BallbarStudy st = run_ballbar(rq);
    if (!plot.empty()) write_file_atomically(plot, ballbar_polar_svg(st));
    if (!report.empty()) write_file_atomically(report, ballbar_html(st));
    return ballbar_json(st);
  });
  messages.issue();
  return to_python(doc);
}

void register_data_functions(py::module_& m) {
  m.def("iso230_2", &iso230_2, py::arg("data"),
        R"doc(weilgen iso230-2: ISO 230-2 positioning figures of one axis, with the
thermal-drift-eliminated evaluation.

iso230_2(data, *, axis, column, reference_position, reference_cycle, alpha, target_tolerance,
         allow_unknown, plot, comp_table, comp_type, comp_units, comp_source, normalise,
         iso_only, uncertainty) -> dict: the document `weilgen iso230-2 --json` writes
(docs/iso230-2.md). None: the CLI's default.)doc");
  m.def("ballbar", &ballbar, py::arg("trace"),
        R"doc(weilgen ballbar: a ballbar trace on its own — ISO 230-4 G (least-squares and minimum
zone), F, H per run, and the usual causes fitted on the trace and ranked.

ballbar(trace, *, radius, plane, centre, feed, feedrate, alpha, min_contribution, plot, report,
        allow_unknown, machine, pdge, order, engine, compiler, param, quiet) -> dict: the
document `weilgen ballbar --json` writes (docs/ballbar.md). plot= an .svg, report= an .html.)doc");
  m.def("fit_pdge", &fit_pdge, py::arg("data"),
        R"doc(weilgen fit-pdge: fits of position-dependent errors, order by cross-validation.

fit_pdge(data, *, basis, order, min_order, max_order, period, cv, folds, rule, column, axis,
         travel, keep_line, angular_reference, plot) -> dict: the document
`weilgen fit-pdge --json` writes (docs/fit-pdge.md); its failures are in the document.)doc");
  m.def("identify", &identify, py::arg("machine"),
        R"doc(weilgen identify: fit the error parameters to point measurements, and predict.

identify(machine, *, data, pdge, fix, rank_tol, predict, predict_out, emit_params, comp_table,
         comp_type, comp_units, axis, comp_points, comp_at, plane, centre, radius, feed,
         allow_unknown, order, engine, compiler, param, quiet) -> dict:
the document `weilgen identify --json` writes (docs/identify.md).)doc");
  m.def("gap", &gap, py::arg("machine"),
        R"doc(weilgen gap: where model and machine disagree, which unmodelled effect, how far
the gap shrinks.

gap(machine, *, data, holdout, effects, at, pdge, alpha, threads, report, plot, plane, centre,
    radius, feed, allow_unknown, order, engine, compiler, param, quiet) -> dict: the document
`weilgen gap --json` writes (docs/gap.md).)doc");
}

}  // namespace weilgen::python
