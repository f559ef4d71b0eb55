#include "weilgen/report/comp_table_document.hpp"

#include <algorithm>
#include <sstream>

#include "weilgen/base/constants.hpp"
#include "weilgen/base/format.hpp"

namespace weilgen {

std::string linuxcnc_comp_file(const CompTable& table, int type) {
  table.validate();
  std::string s;
  for (std::size_t i = 0; i < table.nominal.size(); ++i) {
    const double p = table.nominal[i];
    const double f = type == 0 ? p + table.forward[i] : -table.forward[i];
    const double r = type == 0 ? p + table.reverse[i] : -table.reverse[i];
    s += format_number(p) + " " + format_number(f) + " " + format_number(r) + "\n";
  }
  return s;
}

std::string comp_table_text(const CompTable& table, int type, const std::string& path) {
  const bool angle = table.unit == "deg";
  // Deviations in µm (µrad for an angle: deg -> µrad), the scale of the data.
  const double to_micro = angle ? kPi / 180.0 * 1e6 : (table.unit == "inch" ? 25.4e3 : 1e3);
  const auto range = [&](const std::vector<double>& v) {
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    return format_fixed(*lo * to_micro, 3) + " .. " + format_fixed(*hi * to_micro, 3);
  };
  std::ostringstream os;
  os << "wrote " << path << ": LinuxCNC compensation table (COMP_FILE_TYPE = " << type
     << ") of axis " << table.axis << ", " << table.nominal.size() << " entries "
     << format_number(table.nominal.front()) << " .. " << format_number(table.nominal.back()) << " "
     << table.unit << "; deviation (actual - commanded) forward " << range(table.forward)
     << ", reverse " << range(table.reverse) << (angle ? " urad" : " um") << "\n"
     << "  in the INI file's "
     << (table.joint >= 0 ? "[JOINT_" + std::to_string(table.joint) + "]" : "[JOINT_n]")
     << " section of the axis: COMP_FILE = " << path << " and COMP_FILE_TYPE = " << type
     << " (docs/controllers.md)\n";
  return os.str();
}

}  // namespace weilgen
