// The documents of a gap diagnosis: the text and Markdown report of `weilgen gap` (verdict,
// baseline, where, which effect, how far it shrinks), its JSON (docs/gap.md) and its plots.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "weilgen/analysis/gap.hpp"
#include "weilgen/report/plot.hpp"

namespace weilgen {

std::string gap_text(const GapResult& result, const Model& model, const std::string& data,
                     bool markdown);
// The Markdown report with links to the plots written (relative to the report's directory).
std::string gap_markdown(const GapResult& result, const Model& model, const std::string& data,
                         const std::vector<std::string>& pngs, const std::string& report_path);
nlohmann::json gap_json(const GapResult& result, const Model& model, const std::string& data);
// The candidate effects in ranking order, one row each (held-out RMS in µm, shrink in %).
std::string gap_csv(const GapResult& result, const std::string& data);

// One plot file: `<stem>.png` with its title and panels.
struct GapPlot {
  std::string stem, title;
  std::vector<Panel> panels;
};
// The residual along time, the trace angle, where the named effects act and the significant
// regions, then the effect ranking.
std::vector<GapPlot> gap_plots(const GapData& data, const GapResult& result);
// Draws gap_plots into `dir` (created when missing) as <stem>.png; returns the paths written.
std::vector<std::string> write_gap_plots(const std::string& dir, const GapData& data,
                                         const GapResult& result);

}  // namespace weilgen
