// `weilgen plan` as written: the flags, and the whole run from them, so that every front end (the
// CLI, the Python module) runs the same steps and gets the same documents.
#include <stdexcept>

#include "weilgen/analysis/plan.hpp"
#include "weilgen/analysis/study_spec.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"

namespace weilgen {

namespace {

double length_um(const std::string& text, const std::string& flag) {
  const Quantity q = parse_quantity_unit(text, "um", flag + " " + quoted(text));
  if (q.unit.angle)
    throw std::invalid_argument(flag + " " + quoted(text) + ": a length is expected (e.g. 2um)");
  const double v = q.in(parse_unit("um"));
  if (!(v > 0) || !std::isfinite(v))
    throw std::invalid_argument(flag + " " + quoted(text) + ": must be > 0");
  return v;
}

PlanOptions options_of(const PlanRequest& rq) {
  PlanOptions o;
  o.criterion = parse_design_criterion(rq.criterion);
  o.units = rq.poses;
  if (!rq.target_sd.empty()) o.target_sd_um = length_um(rq.target_sd, "--target-sd");
  o.restarts = rq.restarts;
  o.seed = rq.seed;
  o.threads = rq.threads;
  o.random_sets = rq.random_sets;
  o.rank_tolerance = rq.rank_tolerance;
  o.fixed = rq.fixed;
  o.bound_iterations = rq.bound;
  return o;
}

}  // namespace

void PlanRequest::validate() const {
  check_machine();
  parse_instrument(instrument);
  parse_noise(noise);
  options_of(*this).validate();
  if (angles < 4 || angles > 100000)
    throw std::invalid_argument("--angles must be 4 to 100000 (points per ballbar circle)");
  const Instrument i = parse_instrument(instrument);
  if (i != Instrument::Ballbar) {
    if (!planes.empty())
      throw std::invalid_argument("--plane is for --instrument ballbar (the circles' planes)");
  }
  if (i != Instrument::RTest && !nests.empty())
    throw std::invalid_argument("--nest is for --instrument rtest (where the sphere sits)");
  length_um(radius, "--radius");
  std::size_t files = 0;
  for (const std::string& c : candidates) files += c.find('=') == std::string::npos ? 1 : 0;
  if (files > 1 || (files == 1 && candidates.size() > 1))
    throw std::invalid_argument(
        "--candidates: give one pose file or grid items (AXIS=start:stop:count), not both");
}

PlanRun run_plan(const PlanRequest& rq) {
  rq.validate();
  PlanRun run;
  run.options = options_of(rq);
  const Description desc = rq.description();
  // Every flag that names the machine's errors or axes checked before the model is opened.
  const PdgeBasisChoice choice = parse_pdge_flags(desc, rq.pdge);
  for (const std::string& f : rq.fixed) select_errors(desc, f, "--fix " + quoted(f));
  run.model = rq.open(desc);
  run.param = std::make_shared<const ErrorParameterisation>(run.model->description(), choice,
                                                            run.model->parameters());
  CandidateSpec spec;
  spec.instrument = parse_instrument(rq.instrument);
  for (const std::string& c : rq.candidates) {
    if (c.find('=') == std::string::npos)
      spec.file = c;
    else
      spec.grid.push_back(c);
  }
  spec.set = rq.set;
  spec.include = rq.include;
  spec.radius_mm = length_um(rq.radius, "--radius") / 1000;
  spec.angles = rq.angles;
  spec.planes = rq.planes;
  spec.nests = rq.nests;
  PlanInput in;
  in.model = run.model;
  in.param = run.param;
  in.candidates = plan_candidates(*run.model, spec);
  in.instrument = spec.instrument;
  in.noise = parse_noise(rq.noise);
  in.angles = rq.angles;
  run.result = Planner(run.options).run(in);
  run.templates =
      plan_tables(*run.model, run.result.candidates, run.result.plan.layout, rq.angles, false);
  return run;
}

}  // namespace weilgen
