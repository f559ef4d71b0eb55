#include "study.hpp"

#include <unistd.h>

#include <cmath>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "flags.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/machine/algebra_size.hpp"
#include "weilgen/machine/yaml_loader.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

po::options_description model_options(StudyFlags& f) {
  po::options_description model("Model");
  model.add_options()("order",
                      ranged(&f.request.order, NumberRange::whole_numbers(1, kMaxAlgebraOrder)),
                      "algebra order r >= 1 overriding the machine file's (compiles a model)")(
      "engine", po::value<std::string>(&f.request.engine)->default_value("auto"),
      "auto (built-in, cached or compiled; numeric chain without a compiler) | compiled |\n"
      "numeric (the exact Eigen chain)")(
      "compiler", po::value<std::string>(&f.request.compiler),
      "C++ compiler for machines that are not built in (default $CXX, c++, g++, clang++;\n"
      "'none' disables compilation)")(
      "param", po::value<std::vector<std::string>>(&f.request.params)->composing(),
      "NAME=VALUE machine parameter (mm or deg), repeatable");
  return model;
}

po::options_description ballbar_circle_options(BallbarFlags& c) {
  po::options_description o("Ballbar circle (over the file's '# plane/centre/radius/feed' keys)");
  o.add_options()("plane", po::value<std::string>(&c.plane), "the circle's plane: XY, YZ, ZX")(
      "centre", po::value<std::string>(&c.centre), "the centre, e.g. X=250,Y=0,Z=-100 (mm, deg)")(
      "radius", po::value<std::string>(&c.radius), "the radius, e.g. 100mm")(
      "feed", po::value<std::string>(&c.feed), "ccw or cw");
  return o;
}

void add_study_options(po::options_description& opts, StudyFlags& f, bool with_tolerance) {
  const po::options_description model = model_options(f);
  po::options_description where("Poses and distributions (docs/study-inputs.md)");
  where.add_options()("at", po::value<std::vector<std::string>>(&f.request.at)->composing(),
                      "one pose, e.g. X=0,Y=1500,Z=600 (axis units mm/deg); repeatable")(
      "grid", po::value<std::vector<std::string>>(&f.request.grid)->composing(),
      "a grid of poses: each axis a value or start:stop:count, e.g.\n"
      "X=0:1000:5,Y=0,Z=600:1400:5")(
      "tolerances", po::value<std::vector<std::string>>(&f.request.tolerance_files)->composing(),
      "tolerance file overriding the machine file's distributions; repeatable")(
      "set", po::value<std::vector<std::string>>(&f.request.set)->composing(),
      "NAME=normal:0,0.005mm | sigma:5um | uniform:lo,hi | truncnormal:mu,s,lo,hi | const:v\n"
      "(NAME: error, alias or group:<group>); repeatable, applied last");
  if (with_tolerance)
    where.add_options()("tolerance",
                        po::value<std::vector<std::string>>(&f.request.tolerance)->composing(),
                        "OUTPUT=VALUE, e.g. dx=0.03mm or dy=30um,dz=0.03mm (outputs dx dy dz\n"
                        "da db dc dp; dp = |(dx,dy,dz)|)");
  po::options_description out("Output and run");
  out.add_options()("json", po::value<std::string>(&f.json), "write every number to FILE (JSON)")(
      "csv", po::value<std::string>(&f.csv), "write the result table to FILE (CSV)")(
      "plot", po::value<std::string>(&f.plot), "draw the result to FILE (.png or .svg, gnuplot)")(
      "seed",
      ranged(&f.seed, NumberRange::whole_numbers(0, 18446744073709551615.0))->default_value(1),
      "seed of every sampled result (same seed, same numbers, any --threads)")(
      "threads", ranged(&f.request.threads, thread_range())->default_value(0),
      "worker threads (0 = all cores)")("quiet,q", po::bool_switch(&f.quiet),
                                        "no progress or model messages on stderr");
  opts.add(model).add(where).add(out);
}

std::vector<PathArg> study_inputs(const StudyFlags& f) {
  std::vector<PathArg> in;
  try {
    if (!f.request.machine.empty())
      in.push_back({"machine file", resolve_machine(f.request.machine)});
  } catch (const InputError&) {
    // Reported when the study opens it.
  }
  for (const std::string& t : f.request.tolerance_files) in.push_back({"--tolerances", t});
  return in;
}

std::vector<PathArg> study_outputs(const StudyFlags& f) {
  return {{"--json", f.json}, {"--csv", f.csv}, {"--plot", f.plot}};
}

StudyRequest study_request(const StudyFlags& f) {
  StudyRequest r = f.request;
  if (!f.quiet) r.log = [](const std::string& m) { std::cerr << "weilgen: " << m << "\n"; };
  return r;
}

std::shared_ptr<Model> open_model(const StudyFlags& f, const Description& desc) {
  return weilgen::open_model(study_request(f), desc);
}

Study open_study(const StudyFlags& f, bool need_tolerances) {
  return weilgen::open_study(study_request(f), need_tolerances);
}

void fill_measurement_request(const po::variables_map& vm, StudyFlags& flags,
                              MeasurementRequest& request) {
  if (vm.count("machine")) flags.request.machine = vm["machine"].as<std::string>();
  request.model = study_request(flags);
  request.allow_unknown = vm.count("allow-unknown") > 0;
  request.warn = [](const std::string& w) { std::cerr << w << "\n"; };
}

void add_reliability_options(po::options_description& opts, ReliabilityFlags& f) {
  po::options_description r("Reliability");
  r.add_options()("limit", po::value<std::string>(&f.limit)->default_value(f.limit),
                  "two-sided | one-sided | radial")(
      "method", po::value<std::string>(&f.method)->default_value(f.method),
      "auto | exact | form | is | mc")(
      "samples", ranged(&f.samples, NumberRange::whole_numbers(1, 1e9))->default_value(f.samples),
      "importance-sampling lines or Monte Carlo samples per pose and output")(
      "confidence", ranged(&f.confidence, NumberRange::open(0, 1))->default_value(f.confidence),
      "confidence level of the intervals")(
      "sensitivities", po::value<std::string>(&f.sensitivities)->default_value(f.sensitivities),
      "dR/dmu, dR/dsigma by: auto (sampling for radial, else FORM; analytic when exact) |\n"
      "form | sampling (importance sampling differentiating its own estimate)");
  opts.add(r);
}

void write_output(const std::string& path, const std::string& text) {
  write_file_atomically(path, text);
}

Progress::Progress(std::string what, std::size_t total, bool quiet)
    : what_(std::move(what)),
      total_(total),
      quiet_(quiet),
      tty_(::isatty(2) != 0),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {}

void Progress::update(std::size_t done) {
  if (quiet_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double since = std::chrono::duration<double>(now - last_).count();
  if (elapsed < 1.0 || (since < (tty_ ? 0.2 : 5.0) && done < total_)) return;
  last_ = now;
  shown_ = true;
  std::ostringstream msg;
  msg.precision(1);
  msg << std::fixed << "weilgen: " << what_ << ": " << done << "/" << total_ << ", " << elapsed
      << " s";
  std::cerr << (tty_ ? "\r" : "") << msg.str() << (tty_ ? "" : "\n") << std::flush;
}

Progress::~Progress() {
  if (shown_ && tty_) std::cerr << "\n";
}

}  // namespace weilgen::cli
