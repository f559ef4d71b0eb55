// The pieces every JSON and CSV document shares: numbers (null for NaN and infinities), poses,
// the model's identity, the input distributions, CSV fields.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "weilgen/analysis/study_spec.hpp"
#include "weilgen/model/model.hpp"
#include "weilgen/uq/distribution.hpp"

namespace weilgen {

// Every verb's JSON document: `body` with "weilgen" (the version) and "verb" (the verb's name as
// typed on the command line: "sensitivity", "fit-pdge", ...) added. The one place of these keys.
nlohmann::json json_document(const std::string& verb, nlohmann::json body);

// A JSON number, or null for NaN and infinities (values not computed, or unbounded).
nlohmann::json json_number(double v);
nlohmann::json json_numbers(const std::vector<double>& v);

// "X=0 Y=-1500 Z=600" and {"X": 0, "Y": -1500, "Z": 600} (axis units: mm, deg).
std::string pose_label(const PoseSet& poses, std::size_t i);
nlohmann::json pose_json(const PoseSet& poses, std::size_t i);

// The model's identity: machine, source, order, key, engine, origin, axes.
nlohmann::json model_json(const Model& model);
// The inputs with their distributions in each error's declared unit.
nlohmann::json inputs_json(const Model& model, const std::vector<InputDistribution>& inputs);

// One CSV field: quoted when it contains a comma, quote or newline.
std::string csv_field(const std::string& s);
// A CSV number: format_number, empty for NaN and infinities.
std::string csv_number(double v);

}  // namespace weilgen
