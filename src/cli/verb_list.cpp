#include <iostream>
#include <nlohmann/json.hpp>
#include <vector>

#include "verbs.hpp"
#include "weilgen/machine/yaml_loader.hpp"

namespace weilgen::cli {

int verb_list(const Args& args) {
  if (!args.empty() && (args[0] == "--help" || args[0] == "-h")) {
    std::cout << "weilgen list\n\nLists the shipped machines (" << shipped_machines_dir()
              << "): name, axes, errors, title.\n";
    return 0;
  }
  if (args.size() == 1 && args[0] == "--flags-json") {  // no flags (cli/flags.hpp, flags_json)
    std::cout << nlohmann::json{{"verb", "list"},
                                {"positional", nullptr},
                                {"positional_count", 0},
                                {"about", "Lists the shipped machines."},
                                {"flags", nlohmann::json::array()}}
                     .dump(1)
              << "\n";
    return 0;
  }
  if (!args.empty()) return usage_error("list", "takes no arguments");
  for (const auto& f : shipped_machine_files()) {
    const Description d = load_machine_file(f);
    // "XZY" for one-letter coordinates, "X, A12, Y231" otherwise.
    std::vector<std::string> names;
    bool letters = true;
    for (int b : d.axes()) {
      names.push_back(d.bodies[b].joint.coordinate);
      letters &= names.back().size() == 1;
    }
    std::string axes;
    for (const auto& n : names) axes += (axes.empty() || letters ? "" : ", ") + n;
    if (!d.linked_axes().empty())
      axes += " (+" + std::to_string(d.linked_axes().size()) + " linked)";
    std::cout << d.name << "  axes " << axes << ", " << d.errors.size() << " errors, order "
              << d.algebra.order << "  — " << d.title << "\n";
  }
  return 0;
}

}  // namespace weilgen::cli
