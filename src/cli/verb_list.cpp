#include <filesystem>
#include <iostream>
#include <set>
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
  if (!args.empty()) return usage_error("list", "takes no arguments");
  std::set<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(shipped_machines_dir()))
    if (e.path().extension() == ".yaml") files.insert(e.path().string());
  for (const auto& f : files) {
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
