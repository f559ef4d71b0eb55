#include "study.hpp"

#include <unistd.h>

#include <cmath>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/parallel.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/codegen/generate.hpp"
#include "weilgen/machine/model_key.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/model/builtin_models.hpp"
#include "weilgen/model/model_loader.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

po::options_description model_options(StudyFlags& f) {
  po::options_description model("Model");
  model.add_options()("order", po::value<int>(&f.order),
                      "algebra order r >= 1 overriding the machine file's (compiles a model)")(
      "engine", po::value<std::string>(&f.engine)->default_value("auto"),
      "auto (built-in, cached or compiled; numeric chain without a compiler) | compiled |\n"
      "numeric (the exact Eigen chain)")(
      "compiler", po::value<std::string>(&f.compiler),
      "C++ compiler for machines that are not built in (default $CXX, c++, g++, clang++;\n"
      "'none' disables compilation)")("param",
                                      po::value<std::vector<std::string>>(&f.params)->composing(),
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
  where.add_options()("at", po::value<std::vector<std::string>>(&f.at)->composing(),
                      "one pose, e.g. X=0,Y=1500,Z=600 (axis units mm/deg); repeatable")(
      "grid", po::value<std::vector<std::string>>(&f.grid)->composing(),
      "a grid of poses: each axis a value or start:stop:count, e.g.\n"
      "X=0:1000:5,Y=0,Z=600:1400:5")(
      "tolerances", po::value<std::vector<std::string>>(&f.tolerance_files)->composing(),
      "tolerance file overriding the machine file's distributions; repeatable")(
      "set", po::value<std::vector<std::string>>(&f.set)->composing(),
      "NAME=normal:0,0.005mm | sigma:5um | uniform:lo,hi | truncnormal:mu,s,lo,hi | const:v\n"
      "(NAME: error, alias or group:<group>); repeatable, applied last");
  if (with_tolerance)
    where.add_options()("tolerance", po::value<std::vector<std::string>>(&f.tolerance)->composing(),
                        "OUTPUT=VALUE, e.g. dx=0.03mm or dy=30um,dz=0.03mm (outputs dx dy dz\n"
                        "da db dc dp; dp = |(dx,dy,dz)|)");
  po::options_description out("Output and run");
  out.add_options()("json", po::value<std::string>(&f.json), "write every number to FILE (JSON)")(
      "csv", po::value<std::string>(&f.csv), "write the result table to FILE (CSV)")(
      "plot", po::value<std::string>(&f.plot), "draw the result to FILE (.png or .svg, gnuplot)")(
      "seed", po::value<std::uint64_t>(&f.seed)->default_value(1),
      "seed of every sampled result (same seed, same numbers, any --threads)")(
      "threads", po::value<unsigned>(&f.threads)->default_value(0),
      "worker threads (0 = all cores)")("quiet,q", po::bool_switch(&f.quiet),
                                        "no progress or model messages on stderr");
  opts.add(model).add(where).add(out);
}

namespace {

GeneratedHeader generate_for_loader(const Description& d, int order) {
  GeneratedHeader h;
  h.text = gen::generate_header(d, order, &h.name_space);
  return h;
}

std::vector<double> parse_params(const Description& d, const std::vector<std::string>& flags,
                                 std::vector<double> values) {
  for (const auto& flag : flags) {
    const auto eq = flag.find('=');
    if (eq == std::string::npos)
      throw std::invalid_argument("--param: \"" + flag + "\": expected NAME=VALUE");
    const std::string name = trim(flag.substr(0, eq));
    std::size_t k = 0;
    while (k < d.parameters.size() && d.parameters[k].name != name) ++k;
    if (k == d.parameters.size()) {
      std::string known;
      for (const auto& p : d.parameters) known += (known.empty() ? "" : ", ") + p.name;
      throw std::invalid_argument("--param: unknown parameter \"" + name + "\" (machine " + d.name +
                                  " has " + (known.empty() ? "none" : known) + ")");
    }
    const std::string unit = d.parameters[k].unit;
    values[k] =
        parse_quantity_unit(flag.substr(eq + 1), unit, "--param " + name).in(parse_unit(unit));
  }
  return values;
}

}  // namespace

std::shared_ptr<Model> open_model(const StudyFlags& f, const Description& desc) {
  if (f.order < 0) throw std::invalid_argument("--order must be >= 1");
  LoadOptions lo;
  lo.order = f.order;
  if (f.engine == "auto")
    lo.engine = EngineChoice::Auto;
  else if (f.engine == "compiled")
    lo.engine = EngineChoice::Compiled;
  else if (f.engine == "numeric")
    lo.engine = EngineChoice::Numeric;
  else
    throw std::invalid_argument("--engine must be auto, compiled or numeric, not '" + f.engine +
                                "'");
  lo.compiler = f.compiler;
  lo.builtins = builtin_models();
  lo.generate = generate_for_loader;
  if (!f.quiet) lo.log = [](const std::string& m) { std::cerr << "weilgen: " << m << "\n"; };
  std::shared_ptr<Model> model = load_model(desc, lo);
  // Parameters are part of what the machine is: set before the model is shared.
  if (!f.params.empty()) model->set_parameters(parse_params(desc, f.params, model->parameters()));
  return model;
}

Study open_study(const StudyFlags& f, bool need_tolerances) {
  if (f.machine.empty()) throw std::invalid_argument("no machine given");
  const Description desc = load_machine_file(resolve_machine(f.machine));
  Study s;
  s.poses = parse_poses(desc, f.at, f.grid);
  s.inputs = error_distributions(desc, f.tolerance_files, f.set);
  if (need_tolerances) {
    if (f.tolerance.empty()) throw std::invalid_argument("no --tolerance given (e.g. dx=0.03mm)");
    s.tolerances = parse_tolerances(f.tolerance);
  }
  s.model = open_model(f, desc);
  s.threads = resolve_threads(f.threads);
  return s;
}

std::string pose_label(const PoseSet& poses, std::size_t i) {
  std::string s;
  for (std::size_t a = 0; a < poses.axes.size(); ++a)
    s += (a ? " " : "") + poses.axes[a] + "=" + format_number(poses.poses[i][a]);
  return s;
}

nlohmann::json pose_json(const PoseSet& poses, std::size_t i) {
  nlohmann::json j = nlohmann::json::object();
  for (std::size_t a = 0; a < poses.axes.size(); ++a) j[poses.axes[a]] = poses.poses[i][a];
  return j;
}

nlohmann::json json_number(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

nlohmann::json model_json(const Model& m) {
  const Description& d = m.description();
  nlohmann::json axes = nlohmann::json::array();
  for (int b : d.axes())
    axes.push_back({{"name", d.bodies[b].joint.coordinate}, {"unit", d.bodies[b].joint.unit}});
  return {{"machine", d.name},
          {"source", d.source_file},
          {"order", m.order()},
          {"key", model_key(d.source_hash, m.order())},
          {"engine", engine_name(m.engine())},
          {"origin", m.origin()},
          {"axes", axes}};
}

nlohmann::json inputs_json(const Model& m, const std::vector<InputDistribution>& inputs) {
  nlohmann::json j = nlohmann::json::array();
  const auto& errs = m.description().errors;
  for (std::size_t i = 0; i < errs.size(); ++i) {
    const double f = errs[i].to_base;
    const InputDistribution in_unit = inputs[i].scaled(1.0 / f);
    j.push_back({{"error", errs[i].name},
                 {"unit", errs[i].unit},
                 {"distribution", in_unit.str()},
                 {"mean", in_unit.mean()},
                 {"stddev", in_unit.stddev()}});
  }
  return j;
}

void write_output(const std::string& path, const std::string& text) {
  write_file_atomically(path, text);
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string csv_number(double v) { return std::isfinite(v) ? format_number(v) : ""; }

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
