// The LinuxCNC axis compensation file (a joint's COMP_FILE, COMP_FILE_TYPE 0 or 1) of a
// compensation table (measure/comp_table.hpp), and its summary for stdout. docs/controllers.md.
#pragma once

#include <string>

#include "weilgen/measure/comp_table.hpp"

namespace weilgen {

// One line per entry, "nominal forward reverse", machine units, ascending, numbers that read back
// as the same doubles; type 0: the actual positions nominal + deviation, type 1: the trims
// −deviation that LinuxCNC adds to the motor command. Nothing else: LinuxCNC stops reading the
// file at the first line that is not three numbers, so the file carries no comment.
std::string linuxcnc_comp_file(const CompTable& table, int type);

// "wrote F: LinuxCNC COMP_FILE_TYPE 0 of axis X, 11 entries 0 .. 500 mm, deviation forward
// -1.2 .. 3.4 um, reverse ..." and the INI lines to use it.
std::string comp_table_text(const CompTable& table, int type, const std::string& path);

}  // namespace weilgen
