// The documents of the PDGE fits of a file: the text of `weilgen fit-pdge` (a comparison like
// Zhang & Chen 2021's Table 4 per profile, optionally the CV curves), its JSON (docs/fit-pdge.md)
// and its CSV and charts (data and fits, residuals).
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
// One row per profile and basis: the chosen order and period, the Table 4 metrics and the CV
// error (e_max, RMSE, CV_RMSE in the row's `unit`, SSE in its square), or the failure.
std::string pdge_fit_csv(const PdgeFitStudyResult& result);
// Per profile: the data (mean per position) as points with the fitted curves (bases that span
// one space at one order, e.g. poly:3 = legendre:3 = chebyshev:3, drawn once), and residuals.
std::vector<Panel> pdge_fit_panels(const PdgeFitStudyResult& result);

}  // namespace weilgen
