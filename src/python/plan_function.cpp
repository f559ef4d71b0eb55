// weilgen.plan: `weilgen plan` with its flags as keywords (docs/planning.md, docs/python.md):
// the plan's document as --json writes it, the measurement templates (out=) and the plot (plot=)
// written as the CLI writes them.
#include "binding.hpp"
#include "weilgen/analysis/plan.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/output_paths.hpp"
#include "weilgen/report/plan_document.hpp"
#include "weilgen/report/plot.hpp"

namespace weilgen::python {

namespace {

const std::vector<const char*>& plan_keywords() {
  // One line per group of flags (clang-format would put one name per line).
  // clang-format off
  static const std::vector<const char*> v = [] {
    std::vector<const char*> k = {
        "instrument", "instruments", "time_budget", "times", "poses", "target_sd", "noise",
        "criterion", "candidates", "set", "include", "pdge", "fix", "rank_tol",
        "radius", "angles", "plane", "nest",
        "restarts", "random_sets", "bound", "seed", "threads", "out", "plot"};
    for (const char* m : model_keywords()) k.push_back(m);
    return k;
  }();
  // clang-format on
  return v;
}

py::object plan(py::handle machine, const py::kwargs& kwargs) {
  const Keywords kw("plan", kwargs, plan_keywords());
  PlanRequest rq;
  Messages messages(kw.flag("quiet"));
  model_request(machine, kw, rq.model, rq.opened);
  rq.warn = messages.warn();
  kw.set("instrument", rq.instrument);
  kw.set("instruments", rq.instruments);
  kw.set("time_budget", rq.time_budget);
  kw.set("times", rq.times);
  kw.set("poses", rq.poses);
  kw.set("target_sd", rq.target_sd);
  rq.noise = kw.items("noise", false);
  kw.set("criterion", rq.criterion);
  rq.candidates = kw.items("candidates", false);
  rq.set = kw.items("set", false);
  rq.include = kw.items("include", false);
  rq.pdge = kw.items("pdge", false);
  rq.fixed = kw.items("fix", false);
  kw.set("rank_tol", rq.rank_tolerance);
  kw.set("radius", rq.radius);
  kw.set("angles", rq.angles);
  rq.planes = kw.items("plane", false);
  rq.nests = kw.items("nest", false);
  kw.set("restarts", rq.restarts);
  kw.set("random_sets", rq.random_sets);
  kw.set("bound", rq.bound);
  kw.set("seed", rq.seed);
  kw.set("threads", rq.threads);
  std::string out, plot;
  kw.set("out", out);
  kw.set("plot", plot);
  rq.validate();
  const std::vector<PathArg> inputs = rq.input_files();
  check_output_paths(inputs, {{"--out", out}, {"--plot", plot}});
  if (!plot.empty()) check_plot_target(plot);
  const nlohmann::json doc = run_analysis([&] {
    const PlanRun run = run_plan(rq);
    const auto files = plan_files(run, out, inputs);
    std::vector<std::string> written;
    for (const auto& file : files) written.push_back(file.first);
    for (const auto& file : files) write_file_atomically(file.first, file.second);
    if (!plot.empty()) write_plot(plot, plan_panels(run), "weilgen plan: " + run.model->name());
    return plan_json(run, written);
  });
  messages.issue();
  return to_python(doc);
}

}  // namespace

void register_plan_function(py::module_& m) {
  m.def("plan", &plan, py::arg("machine"));
  implemented_keywords()["plan"].assign(plan_keywords().begin(), plan_keywords().end());
}

}  // namespace weilgen::python
