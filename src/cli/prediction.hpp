// Predictions of `weilgen identify --predict`: the identified model's deviations at the poses of
// a measurement file, compared with the file's measured deviations where it has them.
#pragma once

#include <array>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "weilgen/analysis/identify.hpp"
#include "weilgen/measure/ballbar.hpp"
#include "weilgen/measure/measurement_csv.hpp"

namespace weilgen::cli {

struct Prediction {
  std::string file;
  std::vector<std::string> axes;                 // coordinate names
  std::vector<std::vector<double>> poses;        // per predicted row
  std::vector<int> lines;                        // source line per predicted row
  std::vector<std::array<double, 6>> predicted;  // µm / µrad
  std::vector<std::array<double, 6>> measured;   // NaN where not measured
  std::array<std::size_t, 6> compared{};         // measured cells per output
  std::array<double, 6> rms_measured{}, rms_difference{}, max_difference{};
};

// Every row of `table` with all coordinates present is predicted. InputError when the table
// lacks a coordinate column or has no complete pose.
Prediction predict_table(const Model& model, const ErrorParameterisation& param,
                         const std::vector<double>& theta, const MeasurementTable& table);

void print_prediction(std::ostream& os, const Prediction& p);
nlohmann::json prediction_json(const Prediction& p);
// A measurement CSV (docs/data-format.md) of the predicted deviations.
std::string prediction_csv(const Prediction& p, const Description& desc);

// A ballbar file: a table with angle_deg (and dr_um when measured) or only the circle's header
// keys; the circle from the header keys, overridden by `flags`.
bool is_ballbar_table(const MeasurementTable& table);

struct BallbarPrediction {
  std::string file;
  BallbarCircle circle;
  BallbarTrace predicted;  // 360 points, or at the measured angles
  BallbarEvaluation predicted_evaluation;
  std::vector<BallbarComparison> compared;  // one per measured trace (feed direction, cycle)
};

BallbarPrediction predict_ballbar_table(const Model& model, const ErrorParameterisation& param,
                                        const std::vector<double>& theta,
                                        const MeasurementTable& table, const BallbarFlags& flags);
void print_ballbar_prediction(std::ostream& os, const BallbarPrediction& p);
nlohmann::json ballbar_prediction_json(const BallbarPrediction& p);

}  // namespace weilgen::cli
