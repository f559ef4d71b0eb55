// weilgen.sensitivity, weilgen.reliability, weilgen.allocate: the study verbs. Keywords are the
// flags of `weilgen sensitivity|reliability|allocate` (docs/python.md); the options, the
// analyses and the documents are the ones the verbs use.
#include "binding.hpp"
#include "weilgen/analysis/allocation_study.hpp"
#include "weilgen/analysis/reliability_sweep.hpp"
#include "weilgen/analysis/sensitivity_study.hpp"
#include "weilgen/analysis/tolerance_file.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/output_paths.hpp"
#include "weilgen/base/parallel.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/report/allocation_document.hpp"
#include "weilgen/report/plot.hpp"
#include "weilgen/report/reliability_document.hpp"
#include "weilgen/report/sensitivity_document.hpp"

namespace weilgen::python {

namespace {

std::vector<const char*> keywords(std::initializer_list<const char*> own,
                                  bool with_reliability = false) {
  std::vector<const char*> v(own);
  for (const char* k : {"at", "grid", "tolerances", "set", "seed", "threads", "csv", "plot"})
    v.push_back(k);
  for (const char* k : model_keywords()) v.push_back(k);
  if (with_reliability)
    for (const char* k : {"limit", "method", "samples", "confidence", "sensitivities"})
      v.push_back(k);
  return v;
}

// The keywords of each function: the flags of its verb (tests/python/test_parity.py compares
// them with `weilgen <verb> --flags-json`).
const std::vector<const char*>& sensitivity_keywords() {
  static const std::vector<const char*> v = keywords(
      {"method", "outputs", "samples", "sampling", "replicates", "bootstrap", "confidence"});
  return v;
}
const std::vector<const char*>& reliability_keywords() {
  static const std::vector<const char*> v = keywords({"tolerance"}, true);
  return v;
}
const std::vector<const char*>& allocate_keywords() {
  static const std::vector<const char*> v =
      keywords({"tolerance", "min", "mean", "step", "choose", "rank", "errors", "max_steps",
                "per_output", "cost_aware", "weight", "max_loosen", "save_tolerances"},
               true);
  return v;
}

// Progress of a run: the poll point of a cancelled run between parallel loops.
void progress(std::size_t, std::size_t) { throw_if_cancelled(); }

// The study part of a request: --at --grid --tolerances --set --threads (and --tolerance).
void study_keywords(const Keywords& kw, StudyRequest& r, bool with_tolerance) {
  r.at = kw.items("at", true);
  r.grid = kw.items("grid", true);
  r.tolerance_files = kw.items("tolerances", false);
  r.set = kw.items("set", false);
  if (with_tolerance) r.tolerance = kw.items("tolerance", true);
  kw.set("threads", r.threads);
}

// The parts of a study call every verb shares: the model, the study inputs, the output files.
struct StudyCall {
  StudyRequest request;
  std::shared_ptr<const Model> opened;
  std::string csv, plot;

  StudyCall(py::handle machine, const Keywords& kw, bool with_tolerance) {
    model_request(machine, kw, request, opened);
    study_keywords(kw, request, with_tolerance);
    kw.set("csv", csv);
    kw.set("plot", plot);
  }
  // Before a long run, as the verbs do: the outputs and the plot target are checked.
  void check_outputs(std::vector<PathArg> more = {}) const {
    std::vector<PathArg> inputs;
    for (const std::string& t : request.tolerance_files) inputs.push_back({"--tolerances", t});
    more.push_back({"--csv", csv});
    more.push_back({"--plot", plot});
    check_output_paths(inputs, more);
    if (!plot.empty()) check_plot_target(plot);
  }
  Study open(bool need_tolerances) const {
    if (opened) return open_study(request, opened, need_tolerances);
    return open_study(request, need_tolerances);
  }
};

ReliabilityFlags reliability_flags(const Keywords& kw, ReliabilityFlags f) {
  kw.set("limit", f.limit);
  kw.set("method", f.method);
  kw.set("samples", f.samples);
  kw.set("confidence", f.confidence);
  kw.set("sensitivities", f.sensitivities);
  return f;
}

py::object sensitivity(py::handle machine, const py::kwargs& kwargs) {
  const Keywords kw("sensitivity", kwargs, sensitivity_keywords());
  const StudyCall call(machine, kw, false);
  SensitivityOptions so;
  if (auto m = kw.text("method")) parse_sensitivity_method(*m, so);
  if (auto s = kw.text("sampling")) so.sobol_options.sampling = parse_sampling(*s);
  if (auto o = kw.list("outputs")) so.outputs = parse_output_list(*o);
  kw.set("samples", so.sobol_options.samples);
  kw.set("seed", so.sobol_options.seed);
  kw.set("confidence", so.sobol_options.confidence);
  // --replicates / --bootstrap as the CLI reads them: replicates by default.
  const std::optional<long> replicates = kw.integer("replicates"), boot = kw.integer("bootstrap");
  const long long reps = replicates.value_or(0), resamples = boot.value_or(0);
  if (so.sobol)
    set_sobol_intervals(so.sobol_options, replicates ? &reps : nullptr,
                        boot ? &resamples : nullptr);
  so.validate();
  call.check_outputs();
  std::vector<std::string> errors;
  const nlohmann::json doc = run_analysis([&] {
    const Study st = call.open(false);
    errors = error_names(st.model->description());
    const SensitivityResult r = SensitivityStudy(so).run(st, progress);
    if (!call.csv.empty()) write_file_atomically(call.csv, sensitivity_csv(st, r));
    if (!call.plot.empty())
      write_plot(call.plot, sensitivity_panels(st, so, r),
                 "weilgen sensitivity: " + st.model->name());
    return sensitivity_json(st, so, r);
  });
  return to_python(doc, errors);
}

py::object reliability(py::handle machine, const py::kwargs& kwargs) {
  const Keywords kw("reliability", kwargs, reliability_keywords());
  const StudyCall call(machine, kw, true);
  const ReliabilityFlags rf = reliability_flags(kw, ReliabilityFlags{});
  std::uint64_t seed = ReliabilityOptions{}.seed;
  kw.set("seed", seed);
  const ReliabilitySettings settings = parse_reliability_flags(rf, seed);
  call.check_outputs();
  std::vector<std::string> errors;
  const nlohmann::json doc = run_analysis([&] {
    const Study st = call.open(true);
    if (!call.plot.empty()) check_reliability_plot(st);
    errors = error_names(st.model->description());
    const auto cases = ReliabilitySweep(settings).run(st, st.inputs, progress);
    if (!call.csv.empty()) write_file_atomically(call.csv, reliability_csv(st, settings, cases));
    if (!call.plot.empty())
      write_plot(call.plot, reliability_panels(st, cases),
                 "weilgen reliability: " + st.model->name());
    const ReliabilitySettingsText text{rf.method, rf.limit, rf.samples, seed, rf.confidence};
    return reliability_json(st, settings, text, cases);
  });
  return to_python(doc, errors);
}

py::object allocate(py::handle machine, const py::kwargs& kwargs) {
  const Keywords kw("allocate", kwargs, allocate_keywords());
  const StudyCall call(machine, kw, true);
  if (!call.plot.empty())
    throw std::invalid_argument("--plot: allocate draws no plot (see the JSON's steps)");
  AllocationStudyOptions ao;
  kw.set("min", ao.min_target);
  kw.set("mean", ao.mean_target);
  kw.set("max_loosen", ao.max_loosen);
  kw.set("rank", ao.rank);
  ao.validate();
  const ReliabilityFlags rf = reliability_flags(kw, ReliabilityFlags::for_allocation());
  std::uint64_t seed = ReliabilityOptions{}.seed;
  kw.set("seed", seed);
  ao.reliability = parse_reliability_flags(rf, seed);
  ao.steps = kw.items("step", false);
  kw.set("choose", ao.choose);
  kw.set("max_steps", ao.max_steps);
  ao.per_output = kw.flag("per_output");
  ao.cost_aware = kw.flag("cost_aware");
  ao.weights = kw.items("weight", false);
  if (auto e = kw.list("errors")) ao.errors = split(*e, ',');
  std::string save;
  kw.set("save_tolerances", save);
  call.check_outputs({{"--save-tolerances", save}});
  std::vector<std::string> errors;
  const nlohmann::json doc = run_analysis([&] {
    const Study st = call.open(true);
    errors = error_names(st.model->description());
    const AllocationStudyResult out = AllocationStudy(ao).run(st);
    if (!save.empty())
      write_tolerance_file(save, st.model->description(), out.final_inputs,
                           allocation_tolerance_comment(st, out));
    if (!call.csv.empty()) write_file_atomically(call.csv, allocation_csv(st, out));
    const AllocationSettingsText text{rf.limit, rf.method, seed};
    return allocation_json(st, ao, text, out);
  });
  return to_python(doc, errors);
}

}  // namespace

void register_study_functions(py::module_& m) {
  // The documented functions are the package's (weilgen/_verbs.py, generated from the CLI's
  // flags, with signatures and docstrings); these take the keywords.
  const auto add = [&](const char* name, py::object (*f)(py::handle, const py::kwargs&),
                       const std::vector<const char*>& keywords) {
    m.def(name, f, py::arg("machine"));
    implemented_keywords()[name].assign(keywords.begin(), keywords.end());
  };
  add("sensitivity", &sensitivity, sensitivity_keywords());
  add("reliability", &reliability, reliability_keywords());
  add("allocate", &allocate, allocate_keywords());
}

}  // namespace weilgen::python
