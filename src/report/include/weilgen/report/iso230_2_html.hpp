// The ISO 230-2 test report as one self-contained HTML file (`weilgen iso230-2 --report F.html`),
// in the manner of a laser software's ISO 230-2 report: the test's identification (machine,
// axis, date, operator from the file's header keys), the environment with the normalisation and
// compensation statements, the figures per direction and bidirectional, the deviation chart
// with x̄ ± 2s and the tolerance lines beside the drift-eliminated evaluation, the per-target
// table, the drift per cycle, the tolerance verdicts and a signature block. Charts are inline SVG
// (report/svg_chart.hpp); the file loads nothing else. Every figure shown is the JSON's number
// rounded to 3 decimals and carries data-set / data-key attributes naming it (docs/iso230-2.md,
// "The HTML report").
#pragma once

#include <string>

#include "weilgen/measure/iso230_2_study.hpp"

namespace weilgen {

// `data`: the file name as given; `source_format`: "tidy", "carto" or "wide".
std::string iso230_2_html(const std::string& data, const Iso230_2StudyResult& result,
                          const std::string& source_format = "tidy");

}  // namespace weilgen
