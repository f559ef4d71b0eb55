#include "comp_table.hpp"

#include "weilgen/base/atomic_file.hpp"
#include "weilgen/report/comp_table_document.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

po::options_description comp_table_options(CompTableFlags& f, bool model_axis) {
  po::options_description o("LinuxCNC compensation table (docs/controllers.md)");
  CompTableOptions& t = f.options.table;
  o.add_options()("comp-table", po::value<std::string>(&f.path),
                  model_axis ? "write the identified model's deviation along --axis as a LinuxCNC "
                               "axis compensation file (COMP_FILE) to FILE"
                             : "write the mean deviations per direction as a LinuxCNC axis "
                               "compensation file (COMP_FILE) to FILE")(
      "comp-type", po::value<int>(&t.type)->default_value(t.type),
      "COMP_FILE_TYPE: 0 nominal, forward, reverse positions; 1 nominal and the trims")(
      "comp-units", po::value<std::string>(&t.linear_unit)->default_value(t.linear_unit),
      "machine units of a linear axis: mm or inch (a rotary axis: deg)");
  if (model_axis) {
    o.add_options()("axis", po::value<std::string>(&f.options.axis),
                    "the axis of the compensation table (a model coordinate)")(
        "comp-points", po::value<std::size_t>(&f.options.points)->default_value(f.options.points),
        "entries of the table, evenly spaced over the axis' range (2 to 256)")(
        "comp-at", po::value<std::string>(&f.options.at),
        "the other axes along the table, e.g. Y=-200,Z=-150 (axis units; default 0 where "
        "within range)");
  } else {
    o.add_options()("comp-source", po::value<std::string>(&t.source)->default_value(t.source),
                    "classical (the standard's mean deviations) or drift (the "
                    "drift-eliminated chart)");
  }
  return o;
}

void check_comp_table_flags(const CompTableFlags& f, const po::variables_map& vm, bool model_axis) {
  if (f.path.empty()) {
    // iso230-2 has an --axis of its own (the data's coordinate column).
    const std::vector<const char*> own =
        model_axis ? std::vector<const char*>{"axis", "comp-points", "comp-at"}
                   : std::vector<const char*>{"comp-source"};
    std::vector<const char*> flags = {"comp-type", "comp-units"};
    flags.insert(flags.end(), own.begin(), own.end());
    for (const char* flag : flags)
      if (vm.count(flag) && !vm[flag].defaulted())
        throw std::invalid_argument(std::string("--") + flag + " needs --comp-table FILE");
    return;
  }
  if (model_axis)
    f.options.validate();
  else
    f.options.table.validate();
}

std::string write_comp_table(const CompTableFlags& f, const CompTable& table) {
  write_file_atomically(f.path, linuxcnc_comp_file(table, f.options.table.type));
  return comp_table_text(table, f.options.table.type, f.path);
}

}  // namespace weilgen::cli
