// The documents of an identification: the text of `weilgen identify` (observations, rank,
// residuals per output, parameters with standard errors, the unidentifiable combinations) and
// its JSON (docs/identify.md).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "weilgen/analysis/identify.hpp"

namespace weilgen {

std::string identify_text(const Model& model, const ErrorParameterisation& param,
                          const IdentifyResult& result, const PointData& data);
// `files`: the --data files; the verb adds "predictions".
nlohmann::json identify_json(const Model& model, const ErrorParameterisation& param,
                             const IdentifyResult& result, const std::vector<std::string>& files);

}  // namespace weilgen
