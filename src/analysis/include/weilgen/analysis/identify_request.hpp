// `weilgen identify` as written (docs/identify.md): the flags, and the whole run from them —
// machine, model, error parameterisation, data, identification and the --predict files — so
// that every front end (the CLI, the Python module) runs the same steps and gets the same
// documents from report/identify_document.hpp.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "weilgen/analysis/identify.hpp"
#include "weilgen/analysis/prediction.hpp"
#include "weilgen/analysis/study.hpp"
#include "weilgen/measure/ballbar.hpp"

namespace weilgen {

struct IdentifyRequest : MeasurementRequest {
  std::vector<std::string> data;     // --data: measurement CSV files
  std::vector<std::string> pdge;     // --pdge: poly:3, E_YY=fourier:3 ...
  std::vector<std::string> fixed;    // --fix: errors held at zero
  std::vector<std::string> predict;  // --predict: CSV or ballbar files
  std::string predict_out;           // --predict-out: only checked here (the CSV is the
                                     // front end's to write)
  double rank_tolerance = IdentifyOptions{}.rank_tolerance;  // --rank-tol

  IdentifyOptions options() const;  // --rank-tol, --fix
  // The flags alone, before any file is read (std::invalid_argument naming the flag).
  void validate() const;
};

// One --predict file: points or a ballbar trace.
struct FilePrediction {
  std::optional<Prediction> points;
  std::optional<BallbarPrediction> ballbar;
};

struct IdentifyRun {
  std::vector<std::string> files;  // the --data files
  std::shared_ptr<const Model> model;
  std::shared_ptr<const ErrorParameterisation> param;  // refers to model->description()
  PointData points;
  IdentifyResult result;
  std::vector<FilePrediction> predictions;  // in --predict order
};

// Validates the request, reads every file, identifies and predicts. std::invalid_argument for
// bad flags (also --predict-out naming a ballbar trace), InputError for bad files.
IdentifyRun run_identify(const IdentifyRequest& request);

}  // namespace weilgen
