// The documents of a sensitivity study: the text tables of `weilgen sensitivity`, its JSON and
// CSV (schemas in docs/sensitivity.md) and its bar charts.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "weilgen/analysis/sensitivity_study.hpp"
#include "weilgen/report/plot.hpp"

namespace weilgen {

// "local", "exact", "sobol" or "all"; "qmc" or "mc".
std::string sensitivity_method_name(const SensitivityOptions& options);
const char* sampling_name(Sampling sampling);
// "95 % Student t over 8 independent randomised replicates ...": how the intervals were made.
std::string sobol_interval_text(const SensitivityResult& result);

// Per output, the errors ranked: per pose for up to 3 poses, else the mean over the grid; `top`
// rows per table (0 = all).
std::string sensitivity_text(const Study& study, const SensitivityOptions& options,
                             const SensitivityResult& result, std::size_t top);
nlohmann::json sensitivity_json(const Study& study, const SensitivityOptions& options,
                                const SensitivityResult& result);
std::string sensitivity_csv(const Study& study, const SensitivityResult& result);
std::vector<Panel> sensitivity_panels(const Study& study, const SensitivityOptions& options,
                                      const SensitivityResult& result);

}  // namespace weilgen
