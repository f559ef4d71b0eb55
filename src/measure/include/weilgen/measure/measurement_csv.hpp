// The measurement CSV reader (docs/data-format.md): a tidy table, one row per observation, a
// header row of column names, plain comma-separated numeric cells, `#` comment lines anywhere and
// `# key: value` lines before the header (header_keys). Every column name is classified by its
// role (coordinate, time, direction, cycle, temperature, covariate, deviation, ballbar angle,
// radial deviation); unknown names are an InputError, or warnings when allow_unknown is set —
// never silently dropped.
//
// Bad input throws InputError "file:line:column: message" naming the row's source line and the
// column, e.g.
//   data.csv:17:12: column 'dx_um': 'abc' is not a number
//   data.csv:9: 5 fields, the header has 6
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "weilgen/machine/description.hpp"

namespace weilgen {

enum class ColumnRole {
  Coordinate,   // an axis coordinate: X, Y, Z (mm), A, B, C (deg) ...
  Time,         // t_s (s)
  Direction,    // dir, dir_X (+1 / -1)
  Cycle,        // cycle (integer repetition or run id)
  Temperature,  // T_<name> (degC)
  Covariate,    // other numeric covariates: rpm, feed_mm_min, cov_<name>, or listed in `expected`
  Deviation,    // dx_um dy_um dz_um (um), da_urad db_urad dc_urad (urad)
  Angle,        // ballbar angle_deg (deg)
  Radial,       // ballbar dr_um (um)
  Unknown,
};

// "coordinate", "time", ... (for messages and docs).
const char* to_string(ColumnRole role);

struct ColumnInfo {
  std::string name;
  ColumnRole role = ColumnRole::Unknown;
  std::string unit;  // "mm", "deg", "s", "degC", "um", "urad", "1/min", "" when not known
  std::string axis;  // the axis a per-axis column refers to: "X" for dir_X; "" otherwise
                     // (also "" for dx_um: its component is in the name)
};

struct ReadOptions {
  // The machine's coordinate names (X, Y, Z, A, C ...). Empty: any single upper-case letter is a
  // coordinate (A, B, C in deg, the others in mm).
  std::vector<std::string> coordinates;
  // Extra column names the caller accepts (covariates such as a 6D variant's columns); they are
  // classified as Covariate unless they have another role.
  std::vector<std::string> expected;
  // false: unknown columns are an InputError listing them and the known roles; true: each unknown
  // column is reported in MeasurementTable::warnings and kept in `values` (role Unknown).
  bool allow_unknown = false;
  // The machine the data are read for (machine_read_options): a '# machine:' header naming
  // another machine is an InputError; a coordinate outside its joint's travel range (in the
  // joint's unit) is a warning naming the cell.
  std::string machine;
  struct Travel {
    std::string coordinate, unit;
    double min = 0, max = 0;
  };
  std::vector<Travel> travel;
};

// Plausibility limits of measured values (docs/data-format.md, "Checks on values"): a deviation
// above kImplausibleDeviation (µm or µrad: 10 mm, 10 mrad) is a warning, above
// kImpossibleDeviation (1 m, 1 rad: far outside any linear error model) an error; a coordinate
// above kImpossibleCoordinate (mm or deg) and a temperature below absolute zero are errors.
constexpr double kImplausibleDeviation = 1e4;
constexpr double kImpossibleDeviation = 1e6;
constexpr double kImpossibleCoordinate = 1e7;

// The options of a verb that knows the machine: its independent coordinates are the coordinate
// columns.
ReadOptions machine_read_options(const Description& desc, bool allow_unknown);

struct MeasurementTable {
  std::string file;                                   // path as given
  std::vector<std::string> columns;                   // header names, file order
  std::vector<ColumnInfo> info;                       // classification, same order as columns
  std::vector<int> lines;                             // 1-based source line of each row
  std::map<std::string, std::vector<double>> values;  // column -> values; empty cell = NaN
  std::map<std::string, std::string> header_keys;     // "# key: value" lines before the header
  std::map<std::string, int> header_key_lines;        // key -> its 1-based source line
  int header_line = 0;                                // 1-based line of the header row
  std::vector<std::string> warnings;  // "file:line: unknown column 'foo' ..." (allow_unknown)
  std::vector<std::vector<int>> cell_columns;  // per row, each cell's 1-based source column
  // Column -> the 1-based character column of its header cell (an imported file: the source
  // column it was read from); absent when unknown.
  std::map<std::string, int> header_columns;

  std::size_t rows() const { return lines.size(); }
  bool has(const std::string& column) const { return values.count(column) != 0; }
  // The column's values; throws InputError "file: missing column 'dx_um' (columns: X, dir, ...)"
  // when absent.
  const std::vector<double>& column(const std::string& name) const;
  // Where the cell of `row` in `column` is: file:line:column (the column 0 when unknown), for
  // messages about one cell, e.g. an empty one.
  SourceLoc cell(std::size_t row, const std::string& column) const;
  // Where the header cell of `column` is: file:header_line:column (the column 0 when unknown).
  SourceLoc header_cell(const std::string& column) const;
  // The classification of a column present in the table (throws like column()).
  const ColumnInfo& info_of(const std::string& name) const;
  // Names of the columns with this role, in file order.
  std::vector<std::string> columns_with(ColumnRole role) const;
  // The value of a header key, or `fallback` when absent.
  std::string header_key(const std::string& key, const std::string& fallback = "") const;
};

// Reads a file (InputError "path: cannot read file" when it cannot be opened).
MeasurementTable read_measurements(const std::string& path, const ReadOptions& options = {});
// The whole text of a data file; InputError "cannot read the data file: <why>" ("no such file",
// "is a directory", ...) when it cannot be read.
std::string read_data_file(const std::string& path);
// Parses text; `filename` is used in messages and stored in MeasurementTable::file.
MeasurementTable parse_measurements(const std::string& text, const std::string& filename,
                                    const ReadOptions& options = {});
// The role of one column name (role Unknown when it has none).
ColumnInfo classify_column(const std::string& name, const ReadOptions& options);

}  // namespace weilgen
