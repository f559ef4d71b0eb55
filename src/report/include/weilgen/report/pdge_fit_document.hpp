// The documents of the PDGE fits of a file: the text of `weilgen fit-pdge` (a comparison like
// the 6D seed's Table 4 per profile, optionally the CV curves), its JSON (docs/fit-pdge.md) and
// its charts (data and fits, residuals).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "weilgen/measure/pdge_fit_study.hpp"
#include "weilgen/report/plot.hpp"

namespace weilgen {

std::string pdge_fit_text(const PdgeFitStudyOptions& options, const PdgeFitStudyResult& result,
                          bool curves);
nlohmann::json pdge_fit_json(const PdgeFitStudyOptions& options, const PdgeFitStudyResult& result);
std::vector<Panel> pdge_fit_panels(const PdgeFitStudyResult& result);

}  // namespace weilgen
