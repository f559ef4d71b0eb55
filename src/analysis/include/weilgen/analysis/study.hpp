// What every study of a machine starts from: the machine's model (built-in, cached, compiled at
// run time or the numeric chain), the poses, the error distributions and the output tolerances,
// from the study inputs as written on a command line or passed by another front end
// (docs/study-inputs.md gives the grammar).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "weilgen/analysis/study_spec.hpp"
#include "weilgen/machine/description.hpp"
#include "weilgen/measure/ballbar.hpp"
#include "weilgen/model/model.hpp"
#include "weilgen/uq/distribution.hpp"

namespace weilgen {

// The study inputs in their written form (one string per --at, --grid, ... flag).
struct StudyRequest {
  std::string machine;              // a shipped machine's name or a machine file
  int order = 0;                    // algebra order; 0 = the machine file's
  std::string engine = "auto";      // auto | compiled | numeric
  std::string compiler;             // C++ compiler for run-time models; "none" disables them
  std::vector<std::string> params;  // NAME=VALUE machine parameters (mm, deg)
  std::vector<std::string> at, grid, tolerance, set, tolerance_files;
  unsigned threads = 0;  // 0 = every core
  // Messages about the model (which engine, compiling, warnings); empty = silent.
  std::function<void(const std::string&)> log;
};

struct Study {
  std::shared_ptr<const Model> model;
  PoseSet poses;
  std::vector<InputDistribution> inputs;  // base units (mm, rad), Description::errors order
  std::vector<OutputTolerance> tolerances;
  unsigned threads = 1;
};

// The machine's model with the request's parameters applied. Throws std::invalid_argument for a
// bad order, engine or parameter ("--param: ...").
std::shared_ptr<Model> open_model(const StudyRequest& request, const Description& desc);

// Loads the machine and its model and parses poses, distributions and (when needed) tolerances.
// Throws std::invalid_argument for bad inputs as written and InputError for bad files.
Study open_study(const StudyRequest& request, bool need_tolerances);
// The same for a model opened earlier (a front end that keeps models, such as the Python
// module): the request's machine, order, engine, compiler and params are not used.
Study open_study(const StudyRequest& request, std::shared_ptr<const Model> model,
                 bool need_tolerances);

// What the verbs that fit a model to measurements (identify, gap) share: the model, how files
// are read, the ballbar circle of a trace. Their requests (identify_request.hpp,
// gap_request.hpp) add their own flags.
struct MeasurementRequest {
  StudyRequest model;                            // machine, order, engine, compiler, params, log
  std::shared_ptr<const Model> opened;           // a model opened earlier, used instead of `model`
  bool allow_unknown = false;                    // --allow-unknown
  BallbarFlags circle;                           // --plane --centre --radius --feed
  std::function<void(const std::string&)> warn;  // the readers' warnings (may be empty)

  // std::invalid_argument "no machine given" without a machine or an opened model.
  void check_machine() const;
  // The opened model's description, or the machine file's (InputError).
  Description description() const;
  // The machine parameters the model will have (Description::parameters order, mm/deg): the
  // opened model's, or the file's defaults with --param applied (std::invalid_argument).
  std::vector<double> parameters(const Description& desc) const;
  // The opened model, or open_model(model, desc).
  std::shared_ptr<const Model> open(const Description& desc) const;
};

}  // namespace weilgen
