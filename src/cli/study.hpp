// What the analysis verbs (sensitivity, reliability, allocate) share: the model, poses, error
// distributions, tolerances and output options, from the common flags; progress reporting;
// pose labels; atomic JSON/CSV output. Flag grammar: docs/study-inputs.md.
#pragma once

#include <boost/program_options.hpp>
#include <chrono>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "weilgen/analysis/study_spec.hpp"
#include "weilgen/measure/ballbar.hpp"
#include "weilgen/model/model.hpp"
#include "weilgen/uq/distribution.hpp"

namespace weilgen::cli {

struct StudyFlags {
  std::string machine;
  int order = 0;
  std::string engine = "auto";
  std::string compiler;
  std::vector<std::string> params, at, grid, tolerance, set, tolerance_files;
  std::string json, csv, plot;
  std::uint64_t seed = 1;
  unsigned threads = 0;
  bool quiet = false;
};

// --order --engine --compiler --param --at --grid --tolerances --set --json --csv --plot
// --seed --threads --quiet; `with_tolerance` adds --tolerance.
void add_study_options(boost::program_options::options_description& opts, StudyFlags& flags,
                       bool with_tolerance);

// The "Model" flags alone: --order --engine --compiler --param.
boost::program_options::options_description model_options(StudyFlags& flags);
// --plane, --centre, --radius, --feed: a ballbar circle over the file's header keys.
boost::program_options::options_description ballbar_circle_options(BallbarFlags& circle);

// The machine's model (built-in, cached, compiled or numeric chain; logged to stderr unless
// quiet) with --param applied. Throws std::invalid_argument for bad flags.
std::shared_ptr<Model> open_model(const StudyFlags& flags, const Description& desc);

struct Study {
  std::shared_ptr<const Model> model;
  PoseSet poses;
  std::vector<InputDistribution> inputs;  // base units (mm, rad), Description::errors order
  std::vector<OutputTolerance> tolerances;
  unsigned threads = 1;
};

// Loads the machine and model (built-in, cached, compiled or numeric chain; logged to stderr
// unless quiet) and parses poses, distributions and tolerances. Throws std::invalid_argument
// for bad flags and InputError for bad files.
Study open_study(const StudyFlags& flags, bool need_tolerances);

// "X=0 Y=-1500 Z=600" and {"X": 0, "Y": -1500, "Z": 600} (axis units: mm, deg).
std::string pose_label(const PoseSet& poses, std::size_t i);
nlohmann::json pose_json(const PoseSet& poses, std::size_t i);

// A JSON number, or null for NaN and infinities (values not computed, or unbounded).
nlohmann::json json_number(double v);

// The model's identity for JSON output.
nlohmann::json model_json(const Model& model);
// The inputs with their distributions in each error's declared unit.
nlohmann::json inputs_json(const Model& model, const std::vector<InputDistribution>& inputs);

// Writes `text` to `path` atomically (temporary file, then rename).
void write_output(const std::string& path, const std::string& text);

// One CSV field: quoted when it contains a comma, quote or newline.
std::string csv_field(const std::string& s);
std::string csv_number(double v);

// Progress on stderr for runs longer than a second: "reliability: 12/75 poses, 3.1 s".
class Progress {
 public:
  Progress(std::string what, std::size_t total, bool quiet);
  void update(std::size_t done);
  ~Progress();

 private:
  std::string what_;
  std::size_t total_;
  bool quiet_, shown_ = false, tty_;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace weilgen::cli
