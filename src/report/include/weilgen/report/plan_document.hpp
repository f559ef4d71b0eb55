// The documents of `weilgen plan` (docs/planning.md): the report on stdout, the JSON, the
// measurement templates and the figure.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "weilgen/analysis/plan.hpp"
#include "weilgen/base/output_paths.hpp"
#include "weilgen/report/plot.hpp"

namespace weilgen {

// The template files of a run for `--out PATH` (none when PATH is empty): PATH itself when the
// plan has one set-up, else one file per set-up, PATH's stem + "_" + the set-up's tag + its
// extension (poses_X.csv, poses_XY_12.csv, poses_rtest2.csv). (path, CSV text) in set-up order;
// each is a measurement file identify reads once its empty output cells are filled.
// std::invalid_argument (naming --out) when one of them is one of `inputs` or another.
std::vector<std::pair<std::string, std::string>> plan_files(
    const PlanRun& run, const std::string& out, const std::vector<PathArg>& inputs = {});

std::string plan_text(const PlanRun& run, const std::vector<std::string>& files = {});
// "verb": "plan"; `files`: the templates written.
nlohmann::json plan_json(const PlanRun& run, const std::vector<std::string>& files = {});
// The poses in the workspace, the prediction SD map, the comparison.
std::vector<Panel> plan_panels(const PlanRun& run);

}  // namespace weilgen
