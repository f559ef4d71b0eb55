// The documents of predictions from identified parameters: the text of `weilgen identify
// --predict`, the JSON entries, and the CSV of predicted deviations (docs/identify.md).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "weilgen/analysis/prediction.hpp"

namespace weilgen {

std::string prediction_text(const Prediction& p);
nlohmann::json prediction_json(const Prediction& p);
// A measurement CSV (docs/data-format.md) of the predicted deviations.
std::string prediction_csv(const Prediction& p, const Description& desc);

std::string ballbar_prediction_text(const BallbarPrediction& p);
nlohmann::json ballbar_prediction_json(const BallbarPrediction& p);

}  // namespace weilgen
