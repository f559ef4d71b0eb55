// The documents of a reliability sweep: the text of `weilgen reliability` (tables like the
// Wang & Yuan 2021's Tables 2-4 for two grid axes), its JSON and CSV (docs/reliability.md) and its
// charts (a heat map over two grid axes, a line over one, small multiples over more, bars
// otherwise).
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "weilgen/analysis/reliability_sweep.hpp"
#include "weilgen/report/plot.hpp"

namespace weilgen {

// The flags as written, for the JSON settings.
struct ReliabilitySettingsText {
  std::string method, limit;
  std::size_t samples = 0;
  std::uint64_t seed = 1;
  double confidence = 0.95;
};

// `top` sensitive errors listed per output.
std::string reliability_text(const Study& study, const ReliabilitySettings& settings,
                             const std::vector<SweepCase>& cases, std::size_t top);
nlohmann::json reliability_json(const Study& study, const ReliabilitySettings& settings,
                                const ReliabilitySettingsText& text,
                                const std::vector<SweepCase>& cases);
std::string reliability_csv(const Study& study, const ReliabilitySettings& settings,
                            const std::vector<SweepCase>& cases);
// One panel per toleranced output: a heat map over two grid axes, a line over one, bars for
// poses given by --at. A grid of three or more varying axes gives small multiples: one heat map
// over its last two axes per value of the others (at most kMaxReliabilityPanels panels in all).
std::vector<Panel> reliability_panels(const Study& study, const std::vector<SweepCase>& cases);
constexpr std::size_t kMaxReliabilityPanels = 36;
// Throws std::invalid_argument ("--plot: ...") when reliability_panels would draw more than
// kMaxReliabilityPanels panels, naming the count and what to do (before the sweep runs).
void check_reliability_plot(const Study& study);

}  // namespace weilgen
