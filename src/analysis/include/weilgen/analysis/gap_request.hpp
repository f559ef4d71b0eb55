// `weilgen gap` as written (docs/gap.md): the flags, and the whole run from them — machine,
// model, data, hold-out scheme and diagnosis — so that every front end (the CLI, the Python
// module) runs the same steps and gets the same documents from report/gap_document.hpp.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "weilgen/analysis/gap.hpp"
#include "weilgen/analysis/study.hpp"
#include "weilgen/measure/ballbar.hpp"

namespace weilgen {

struct GapRequest : MeasurementRequest {
  std::string data;                         // --data: the measurement CSV
  std::string holdout = "auto";             // --holdout
  std::vector<std::string> effects;         // --effects: names, each may be a comma-separated list
  std::vector<std::string> pdge;            // --pdge
  std::vector<std::string> at;              // --at: coordinates the data do not list
  double alpha = GapOptions{}.alpha;        // --alpha
  unsigned threads = GapOptions{}.threads;  // --threads

  // The diagnosis options from the flags (without the --at coordinates, which need the machine).
  GapOptions options() const;
  // The flags alone, before any file is read (std::invalid_argument naming the flag).
  void validate() const;
};

struct GapRun {
  std::shared_ptr<const Model> model;
  GapData data;
  GapResult result;
};

// Validates the request, reads the machine and the data, and diagnoses. std::invalid_argument
// for bad flags, InputError for bad files.
GapRun run_gap(const GapRequest& request);

}  // namespace weilgen
