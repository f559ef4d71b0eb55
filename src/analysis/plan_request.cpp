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
  if (!rq.time_budget.empty()) {
    o.budget_s = parse_duration_s(rq.time_budget, "h", "--time-budget");
    if (!(o.budget_s > 0)) throw std::invalid_argument("--time-budget must be > 0");
  }
  o.restarts = rq.restarts;
  o.seed = rq.seed;
  o.threads = rq.threads;
  o.random_sets = rq.random_sets;
  o.rank_tolerance = rq.rank_tolerance;
  o.fixed = rq.fixed;
  o.bound_iterations = rq.bound;
  return o;
}

// --instruments: "points:0.5um,ballbar:0.2um,line6d:1um": each instrument once, its noise for
// its length kinds (an angle for line6d's angular channels), else --noise's.
std::vector<std::pair<Instrument, std::string>> parse_instruments(const std::string& text) {
  std::vector<std::pair<Instrument, std::string>> out;
  for (const std::string& raw : split(text, ',')) {
    const std::string item = trim(raw);
    if (item.empty()) throw std::invalid_argument("--instruments: empty item in " + quoted(text));
    const auto colon = item.find(':');
    const Instrument i = parse_instrument(item.substr(0, colon), "--instruments");
    for (const auto& [seen, noise] : out)
      if (seen == i)
        throw std::invalid_argument("--instruments: " + std::string(instrument_name(i)) +
                                    " is given twice");
    out.emplace_back(i, colon == std::string::npos ? "" : trim(item.substr(colon + 1)));
  }
  if (out.empty()) throw std::invalid_argument("--instruments: no instrument given");
  return out;
}

}  // namespace

void PlanRequest::validate() const {
  check_machine();
  const bool several = !instruments.empty();
  if (several) {
    if (!instrument.empty())
      throw std::invalid_argument("--instrument and --instruments: give one of them");
    if (time_budget.empty())
      throw std::invalid_argument("--instruments needs --time-budget (e.g. --time-budget 4h)");
    if (!candidates.empty())
      throw std::invalid_argument(
          "--candidates is for one instrument; with --instruments each takes its default "
          "candidates (--set still holds axes)");
    parse_instruments(instruments);
  } else {
    if (!time_budget.empty())
      throw std::invalid_argument(
          "--time-budget is for --instruments (e.g. --instruments points:1um,ballbar:0.3um)");
    if (!times.empty()) throw std::invalid_argument("--times is for --instruments");
    parse_instrument(instrument.empty() ? "points" : instrument);
  }
  parse_noise(noise);
  options_of(*this).validate();
  if (angles < 4 || angles > 100000)
    throw std::invalid_argument("--angles must be 4 to 100000 (points per ballbar circle)");
  std::vector<Instrument> used;
  if (several)
    for (const auto& [i, n] : parse_instruments(instruments)) used.push_back(i);
  else
    used.push_back(parse_instrument(instrument.empty() ? "points" : instrument));
  auto uses = [&](Instrument i) { return std::find(used.begin(), used.end(), i) != used.end(); };
  if (!uses(Instrument::Ballbar) && !planes.empty())
    throw std::invalid_argument("--plane is for --instrument ballbar (the circles' planes)");
  if (!uses(Instrument::RTest) && !nests.empty())
    throw std::invalid_argument("--nest is for --instrument rtest (where the sphere sits)");
  length_um(radius, "--radius");
  std::size_t files = 0;
  for (const std::string& c : candidates) files += c.find('=') == std::string::npos ? 1 : 0;
  if (files > 1 || (files == 1 && candidates.size() > 1))
    throw std::invalid_argument(
        "--candidates: give one pose file or grid items (AXIS=start:stop:count), not both");
}

std::vector<PathArg> PlanRequest::input_files() const {
  std::vector<PathArg> inputs;
  for (const std::string& c : candidates)
    if (c.find('=') == std::string::npos) inputs.push_back({"--candidates", c});
  for (const std::string& f : include) inputs.push_back({"--include", f});
  if (!times.empty()) inputs.push_back({"--times", times});
  return inputs;
}

PlanRun run_plan(const PlanRequest& rq) {
  rq.validate();
  PlanRun run;
  run.options = options_of(rq);
  const Description desc = rq.description();
  // Every flag that names the machine's errors or axes, and every file, checked before the
  // model is opened.
  const PdgeBasisChoice choice = parse_pdge_flags(desc, rq.pdge);
  for (const std::string& f : rq.fixed) select_errors(desc, f, "--fix " + quoted(f));
  const KindNoise base = parse_noise(rq.noise);
  std::vector<std::pair<Instrument, std::string>> list;
  if (rq.instruments.empty())
    list.emplace_back(parse_instrument(rq.instrument.empty() ? "points" : rq.instrument), "");
  else
    list = parse_instruments(rq.instruments);
  const std::map<Instrument, InstrumentTimes> times = rq.instruments.empty()
                                                          ? std::map<Instrument, InstrumentTimes>{}
                                                          : read_instrument_times(rq.times);
  run.model = rq.open(desc);
  run.param = std::make_shared<const ErrorParameterisation>(run.model->description(), choice,
                                                            run.model->parameters());
  PlanInput in;
  in.model = run.model;
  in.param = run.param;
  in.noise = base;
  in.angles = rq.angles;
  in.instrument = list.front().first;
  for (const auto& [inst, noise_text] : list) {
    CandidateSpec spec;
    spec.instrument = inst;
    for (const std::string& c : rq.candidates) {
      if (c.find('=') == std::string::npos)
        spec.file = c;
      else
        spec.grid.push_back(c);
    }
    spec.set = rq.set;
    if (inst == Instrument::Points || inst == Instrument::RTest || list.size() == 1)
      spec.include = rq.include;
    spec.radius_mm = length_um(rq.radius, "--radius") / 1000;
    spec.angles = rq.angles;
    if (inst == Instrument::Ballbar) spec.planes = rq.planes;
    if (inst == Instrument::RTest) spec.nests = rq.nests;
    PlanCandidates c = plan_candidates(*run.model, spec);
    // The instrument's own noise and times on each of its set-ups.
    KindNoise noise = base;
    if (!noise_text.empty()) {
      const std::string what = "--instruments " + std::string(instrument_name(inst));
      const Quantity q = parse_quantity_unit(noise_text, "um", what);
      const double v = q.unit.angle ? q.in(parse_unit("urad")) : q.in(parse_unit("um"));
      if (!(v > 0) || !std::isfinite(v))
        throw std::invalid_argument(what + ": the noise must be > 0");
      for (std::size_t k : observed_kinds(inst))
        if ((std::string(observation_unit(k)) == "µrad") == q.unit.angle) noise[k] = v;
    }
    const InstrumentTimes t = times.count(inst) ? times.at(inst) : InstrumentTimes{};
    const std::size_t setup0 = in.candidates.setups.size();
    for (PlanSetup& s : c.setups) {
      s.noise = noise;
      s.setup_s = t.setup_s;
      s.pose_s = t.pose_s;
      // Several instruments share one --out: the files say whose they are.
      if (list.size() > 1 && s.tag.rfind(instrument_name(inst), 0) != 0)
        s.tag = std::string(instrument_name(inst)) + "_" + s.tag;
      in.candidates.setups.push_back(std::move(s));
    }
    const std::size_t unit0 = in.candidates.units.size();
    for (PlanUnit& u : c.units) {
      u.setup += setup0;
      in.candidates.units.push_back(std::move(u));
    }
    for (std::size_t f : c.forced) in.candidates.forced.push_back(f + unit0);
    in.candidates.dropped += c.dropped;
    if (list.size() > 1) in.instruments.push_back(inst);
  }
  run.result = Planner(run.options).run(in);
  run.templates =
      plan_tables(*run.model, run.result.candidates, run.result.plan.layout, rq.angles, false);
  return run;
}

}  // namespace weilgen
