// The documents of an ISO 230-2 evaluation: the text of `weilgen iso230-2` (per-target table,
// axis figures classical / Student-t / drift-eliminated, Stejskal et al. 2017's tables), its JSON
// (docs/iso230-2.md) and its deviation charts.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "weilgen/measure/iso230_2_study.hpp"
#include "weilgen/report/plot.hpp"

namespace weilgen {

// `data`: the file name as given, for the heading and the JSON; `source_format`: how it was read
// ("tidy", "carto", "wide"; weilgen/measure/instrument_import.hpp).
std::string iso230_2_text(const std::string& data, const Iso230_2StudyResult& result);
nlohmann::json iso230_2_json(const std::string& data, const Iso230_2StudyResult& result,
                             const std::string& source_format = "tidy");

// What the normalisation to 20 °C and the air compensation did, one sentence per line (ASCII
// units: um, degC); the text, the JSON and the HTML report state it in these words.
std::vector<std::string> iso230_2_normalisation_statement(const Iso230_2StudyResult& result);
// The tolerance verdicts, one line each, and the overall verdict ("" without tolerances).
std::vector<std::string> iso230_2_tolerance_statement(const Iso230_2StudyResult& result);
// The uncertainty of the figures (empty without a budget): a table of E, M, A, B, R (and the
// figures the tolerances limit) with u, U and the Monte Carlo's u and interval, then each of E,
// M, A, B, R's budget (every contribution's distribution, u(x), sensitivity, |c| u and share of
// u²) and the budget's notes.
std::vector<std::string> iso230_2_uncertainty_text(const Iso230_2StudyResult& result);
// The figures whose budgets the documents show: E, M, A, B, R.
const std::vector<std::string>& iso230_2_budget_figures();
// Whether the run meets ISO 230-2's test conditions: one line, or a heading and one "- check:
// why" line per condition not met.
std::vector<std::string> iso230_2_conformance_statement(const Iso230_2StudyResult& result);
// The per-target table as CSV, one row per target: target_mm, the classical k = 2 columns
// (mean_up_um ... R_i_um, mean_bi_um, the band lower_up_um = x̄↑ − 2s↑ ... upper_down_um) and,
// with a drift-eliminated evaluation, chart_up_um, s_star_up_um, chart_down_um, s_star_down_um
// (µrad columns for a rotary axis). The axis figures are in the JSON.
std::string iso230_2_csv(const Iso230_2StudyResult& result);
std::vector<Panel> iso230_2_panels(const Iso230_2StudyResult& result);

}  // namespace weilgen
