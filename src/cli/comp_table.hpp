// The compensation-table flags of `iso230-2` and `identify` (docs/controllers.md): --comp-table
// FILE, --comp-type 0|1, --comp-units mm|inch, and for iso230-2 --comp-source classical|drift, for
// identify --axis, --comp-points, --comp-at.
#pragma once

#include <boost/program_options.hpp>
#include <string>
#include <vector>

#include "weilgen/analysis/axis_comp_table.hpp"

namespace weilgen::cli {

struct CompTableFlags {
  std::string path;              // --comp-table; empty: no table
  AxisCompTableOptions options;  // .table: type, units, source; the rest: identify's axis line
};

// iso230-2 (`model_axis` false): --comp-table --comp-type --comp-units --comp-source;
// identify (`model_axis` true): --comp-table --comp-type --comp-units --axis --comp-points
// --comp-at.
boost::program_options::options_description comp_table_options(CompTableFlags& flags,
                                                               bool model_axis);

// Before any work: the options valid (std::invalid_argument naming the flag); the verb checks the
// file with its other outputs (check_output_paths). Nothing when --comp-table is not given; with
// `model_axis`, --axis / --comp-points / --comp-at without --comp-table are refused.
void check_comp_table_flags(const CompTableFlags& flags,
                            const boost::program_options::variables_map& vm, bool model_axis);

// Writes the COMP_FILE atomically; returns the summary for stdout.
std::string write_comp_table(const CompTableFlags& flags, const CompTable& table);

}  // namespace weilgen::cli
