// The documents of an identification: the text of `weilgen identify` (observations, rank,
// residuals per output, parameters with standard errors, the unidentifiable combinations) and
// its JSON, CSV and chart (docs/identify.md).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "weilgen/analysis/identify.hpp"
#include "weilgen/analysis/identify_request.hpp"
#include "weilgen/report/plot.hpp"

namespace weilgen {

std::string identify_text(const Model& model, const ErrorParameterisation& param,
                          const IdentifyResult& result, const PointData& data);
// `files`: the --data files; without "predictions" (identify_json(run) adds them).
// Unidentifiable combinations as JSON: a list of `text` and `terms` [`parameter`, `coefficient`].
nlohmann::json null_combinations_json(const ErrorParameterisation& param,
                                      const std::vector<NullCombination>& combinations);

nlohmann::json identify_json(const Model& model, const ErrorParameterisation& param,
                             const IdentifyResult& result, const std::vector<std::string>& files);

// The document of a whole run (`weilgen identify --json`): identify_json of the run with
// "predictions", one entry per --predict file (prediction_document.hpp).
nlohmann::json identify_json(const IdentifyRun& run);
// The text of a whole run: identify_text, then each prediction's text.
std::string identify_text(const IdentifyRun& run);
// One row per parameter: label, error, basis, term, value and standard error in `unit`,
// identifiable, fixed.
std::string identify_csv(const Model& model, const ErrorParameterisation& param,
                         const IdentifyResult& result);
// The RMS residual per output before and after (µm, µrad), and per unit the identified
// parameters with their 95 % intervals (value ± 1.96 standard errors).
std::vector<Panel> identify_panels(const ErrorParameterisation& param,
                                   const IdentifyResult& result);

}  // namespace weilgen
