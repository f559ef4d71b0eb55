// The documents of a tolerance allocation: the text of `weilgen allocate` (Wang & Yuan 2021's
// Tables 5-7 and the cost-aware optimum), its JSON and CSV (docs/reliability.md), and the
// tolerance file of the final spreads.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "weilgen/analysis/allocation_study.hpp"
#include "weilgen/report/plot.hpp"

namespace weilgen {

struct AllocationSettingsText {  // the flags as written, for the JSON settings
  std::string limit, method;
  std::uint64_t seed = 1;
};

std::string allocation_text(const Study& study, const AllocationStudyOptions& options,
                            const AllocationStudyResult& result);
nlohmann::json allocation_json(const Study& study, const AllocationStudyOptions& options,
                               const AllocationSettingsText& text,
                               const AllocationStudyResult& result);
std::string allocation_csv(const Study& study, const AllocationStudyResult& result);
// The allocation steps chart (allocate --plot): per toleranced output, min and mean R (%) over
// the steps with the targets; the chosen errors' spreads (% of their start) over the steps; with
// --cost-aware, every moving error's spread (% of its start) after the steps and at the optimum.
std::vector<Panel> allocation_panels(const Study& study, const AllocationStudyOptions& options,
                                     const AllocationStudyResult& result);
// The comment heading the saved tolerance file.
std::string allocation_tolerance_comment(const Study& study, const AllocationStudyResult& result);

}  // namespace weilgen
