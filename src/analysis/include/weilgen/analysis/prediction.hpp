// Predictions of `weilgen identify --predict`: the identified model's deviations at the poses of
// a measurement file, compared with the file's measured deviations where it has them.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "weilgen/analysis/identify.hpp"
#include "weilgen/measure/ballbar.hpp"
#include "weilgen/measure/measurement_csv.hpp"

namespace weilgen {

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

}  // namespace weilgen
