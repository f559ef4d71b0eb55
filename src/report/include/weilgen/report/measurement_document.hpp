// A measurement table as the tidy CSV of docs/data-format.md (what `weilgen import` prints), and
// the summary of an import: the format read, the rows, the mapping of the source columns.
#pragma once

#include <string>

#include "weilgen/measure/instrument_import.hpp"
#include "weilgen/measure/measurement_csv.hpp"

namespace weilgen {

// The header keys as "# key: value" lines (in source order; keys without a source line last),
// then `comment` lines (each written as "# <line>": keep them free of "key:" prefixes), the header
// row and one row per observation: numbers that read back as the same double (format_number),
// empty cells for NaN. parse_measurements of the text gives the table back.
std::string measurement_csv(const MeasurementTable& table,
                            const std::vector<std::string>& comments = {});

// "carto.csv: CARTO wide CSV, 22 rows -> 110 observations (axis X)" and the mapping lines.
std::string import_summary(const std::string& file, const ImportResult& result);
// The comment lines an imported file carries: where it came from and the mapping.
std::vector<std::string> import_comments(const std::string& file, const ImportResult& result);

}  // namespace weilgen
