// weilgen plan: where to measure, with which instrument, how many poses, and how good the
// identification will be — the plan as measurement templates identify reads once filled.
// docs/planning.md.
#include <iostream>

#include "flags.hpp"
#include "study.hpp"
#include "verbs.hpp"
#include "weilgen/analysis/plan.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/report/plan_document.hpp"
#include "weilgen/report/plot.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

int verb_plan(const Args& args) {
  StudyFlags flags;
  PlanRequest rq;
  po::options_description opts(
      "weilgen plan <machine> (--poses N | --target-sd 2um) [options]\n\n"
      "Chooses the poses (circles, positions) an instrument should measure so that identify\n"
      "determines the machine's error parameters best: an exchange algorithm (modified\n"
      "Fedorov with random restarts) over candidate poses, by the D, A, E or I criterion on the\n"
      "parameters identify can estimate. Reports the predicted standard deviation of every\n"
      "parameter and of the volumetric error, the observability indices O1-O5, and the same\n"
      "for a regular layout and the best of random sets of the same size; writes the plan as\n"
      "measurement templates identify reads once filled. docs/planning.md.\n\nOptions");
  std::string out, json_path, plot_path;
  opts.add_options()("help,h", "show this help")(
      "instrument", po::value<std::string>(&rq.instrument),
      "points (dx dy dz at a pose) | line6d (a 6D laser along an axis) | ballbar (circles) |\n"
      "rtest (a sphere held at a nest while the rotary axes turn); default points")(
      "instruments", po::value<std::string>(&rq.instruments),
      "several instruments with their noise (points:0.5um,ballbar:0.2um,line6d:1um): which\n"
      "set-ups and units fit --time-budget")("time-budget", po::value<std::string>(&rq.time_budget),
                                             "with --instruments: the time available (4h, 90 min)")(
      "times", po::value<std::string>(&rq.times),
      "with --instruments: a YAML of each instrument's set-up and per-unit time\n"
      "(points: {setup: 60 min, pose: 1 min}; docs/planning.md has the defaults)")(
      "poses", ranged(&rq.poses, NumberRange::whole_numbers(1, 1e6)),
      "how many units to plan: poses (points, rtest), circles (ballbar), positions (line6d)")(
      "target-sd", po::value<std::string>(&rq.target_sd),
      "instead of --poses: the fewest units whose prediction SD reaches this (e.g. 2um)")(
      "noise", po::value<std::vector<std::string>>(&rq.noise)->composing(),
      "the instrument's noise: 1um (every length output), 2urad (every angle), or per kind\n"
      "dx= dy= dz= dr= lin= str= ang= (default 1 um and 1 urad); repeatable, comma-separated")(
      "criterion", po::value<std::string>(&rq.criterion)->default_value(rq.criterion),
      "D (log det) | A (sum of variances) | E (smallest eigenvalue) | I (mean prediction\n"
      "variance over a 5-level grid of the travel)")(
      "candidates", po::value<std::vector<std::string>>(&rq.candidates)->composing(),
      "candidate levels per axis as --grid takes them (X=0:500:21,Y=-400:0:17), axes not\n"
      "named over their travel; or a CSV of poses (points)")(
      "set", po::value<std::vector<std::string>>(&rq.set)->composing(),
      "hold an axis at a value (Z=-100); repeatable")(
      "include", po::value<std::vector<std::string>>(&rq.include)->composing(),
      "a CSV of poses the plan must contain (points, rtest); repeatable")(
      "pdge", po::value<std::vector<std::string>>(&rq.pdge)->composing(),
      "PDGE bases as identify takes them (poly:3, E_YY=fourier:3); repeatable")(
      "fix", po::value<std::vector<std::string>>(&rq.fixed)->composing(),
      "an error identify will hold at zero (as identify --fix); repeatable")(
      "rank-tol",
      ranged(&rq.rank_tolerance, NumberRange::open(0, 1))->default_value(rq.rank_tolerance, "1e-9"),
      "identify's rank tolerance")("radius",
                                   po::value<std::string>(&rq.radius)->default_value(rq.radius),
                                   "ballbar: the bar length (a length, mm when no unit)")(
      "angles", ranged(&rq.angles, NumberRange::whole_numbers(4, 100000))->default_value(rq.angles),
      "ballbar: points per circle")(
      "plane", po::value<std::vector<std::string>>(&rq.planes)->composing(),
      "ballbar: a plane of candidate circles (XY, YZ, ZX; X,Y for long names); repeatable;\n"
      "default every plane of two linear axes")(
      "nest", po::value<std::vector<std::string>>(&rq.nests)->composing(),
      "rtest: the linear axes where the sphere sits in the nest, rotary axes at rest\n"
      "(X=0,Y=0,Z=-200); repeatable (one set-up each); default the middle of the travel")(
      "restarts", ranged(&rq.restarts, NumberRange::whole_numbers(1, 1000))->default_value(8),
      "exchange restarts (the first from the sequential design, the others random)")(
      "random-sets",
      ranged(&rq.random_sets, NumberRange::whole_numbers(1, 100000))->default_value(20),
      "random layouts of the same size the plan is compared with (the best is reported)")(
      "bound", ranged(&rq.bound, NumberRange::whole_numbers(0, 100000))->default_value(0),
      "iterations of the continuous design that bounds every design of the same size (the\n"
      "plan's distance from the best possible; 300 is plenty; 0 = not computed)")(
      "seed", ranged(&rq.seed, NumberRange::whole_numbers(0, 1.8e19))->default_value(1),
      "random seed (restarts, random layouts)")(
      "threads", ranged(&rq.threads, thread_range())->default_value(0),
      "worker threads (0 = all cores; the result is the same for any count)")(
      "out", po::value<std::string>(&out),
      "write the plan as measurement templates: FILE, or FILE_<set-up>.csv per set-up")(
      "json", po::value<std::string>(&json_path), "write the plan as JSON to FILE")(
      "plot", po::value<std::string>(&plot_path),
      "draw the poses, the prediction SD map and the comparison to FILE (.png or .svg)")(
      "quiet,q", po::bool_switch(&flags.quiet), "no model messages on stderr");
  opts.add(model_options(flags));
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("plan", args, opts, "machine", 1, vm)) return *stop;
  fill_measurement_request(vm, flags, rq);
  try {
    rq.validate();
  } catch (const std::invalid_argument& e) {
    return usage_error("plan", e.what());
  }
  std::vector<PathArg> inputs = study_inputs(flags);
  for (const PathArg& f : rq.input_files()) inputs.push_back(f);
  check_output_paths(inputs, {{"--out", out}, {"--json", json_path}, {"--plot", plot_path}});
  if (!plot_path.empty()) check_plot_target(plot_path);

  const PlanRun run = run_plan(rq);
  const auto files = plan_files(run, out, inputs);
  std::vector<std::string> written;
  for (const auto& file : files) written.push_back(file.first);
  std::cout << plan_text(run, written);
  for (const auto& [path, text] : files) write_file_atomically(path, text);
  if (!json_path.empty()) write_file_atomically(json_path, plan_json(run, written).dump(2) + "\n");
  if (!plot_path.empty())
    write_plot(plot_path, plan_panels(run), "weilgen plan: " + run.model->name());
  return 0;
}

}  // namespace weilgen::cli
