// What the analysis verbs share: the common flags (model, poses, distributions, tolerances,
// outputs) and progress reporting. Flag grammar: docs/study-inputs.md.
#pragma once

#include <boost/program_options.hpp>
#include <chrono>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "flags.hpp"
#include "weilgen/analysis/reliability_sweep.hpp"
#include "weilgen/analysis/study.hpp"
#include "weilgen/analysis/study_spec.hpp"
#include "weilgen/measure/ballbar.hpp"
#include "weilgen/model/model.hpp"
#include "weilgen/report/json_common.hpp"
#include "weilgen/uq/distribution.hpp"

namespace weilgen::cli {

// The study flags: the model, pose and distribution flags bind straight into `request` (as
// verb_gap binds GapRequest); the rest say where to write and how to run.
struct StudyFlags {
  StudyRequest request;  // --order --engine --compiler --param --at --grid --tolerance(s) --set
                         // --threads, and the machine (positional)
  std::string json, csv, plot;
  std::uint64_t seed = 1;
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

// The files the study flags read (the machine file, --tolerances) and write (--json, --csv,
// --plot), for check_output_paths (flags.hpp).
std::vector<PathArg> study_inputs(const StudyFlags& flags);
std::vector<PathArg> study_outputs(const StudyFlags& flags);

// The flags as a study request (model messages to stderr unless --quiet).
StudyRequest study_request(const StudyFlags& flags);
// analysis/study.hpp's open_model and open_study over the flags.
std::shared_ptr<Model> open_model(const StudyFlags& flags, const Description& desc);
Study open_study(const StudyFlags& flags, bool need_tolerances);
// After parsing, what `identify` and `gap` share: the machine (the positional argument), the
// model flags, --allow-unknown, and the readers' warnings on stderr.
void fill_measurement_request(const boost::program_options::variables_map& vm, StudyFlags& flags,
                              MeasurementRequest& request);

// The reliability flags shared by `reliability` and `allocate`: --limit --method --samples
// --confidence --sensitivities (ReliabilityFlags: analysis/reliability_sweep.hpp).
void add_reliability_options(boost::program_options::options_description& opts,
                             ReliabilityFlags& flags);

// Writes `text` to `path` atomically (temporary file, then rename).
void write_output(const std::string& path, const std::string& text);

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
