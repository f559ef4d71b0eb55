// The documents of `weilgen ballbar` (docs/ballbar.md, "weilgen ballbar"): the text for stdout,
// the JSON, the polar plot (SVG: both directions magnified about the nominal circle, each run's
// minimum zone, the ISO 230-4 figures and the diagnosis annotated) and the self-contained HTML
// report that holds it.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "weilgen/analysis/ballbar_request.hpp"

namespace weilgen {

std::string ballbar_text(const BallbarStudy& study);
nlohmann::json ballbar_json(const BallbarStudy& study);
// A standalone <svg> (with its xmlns), deterministic text.
std::string ballbar_polar_svg(const BallbarStudy& study);
// One HTML file, nothing loaded from elsewhere: identification, the ISO 230-4 table per run and
// H, the polar plot, the ranked diagnosis, the model terms (with a machine), approval lines.
std::string ballbar_html(const BallbarStudy& study);

// "ccw 1", "cw" (the cycle when the file numbers its runs).
std::string ballbar_run_label(int feed, int cycle);
// A p-value for print: 2 significant digits, "< 1e-16" below what a double resolves.
std::string p_text(double p);

}  // namespace weilgen
