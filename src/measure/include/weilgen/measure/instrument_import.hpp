// Laser calibration exports read into the tidy measurement layout (docs/data-format.md, section
// "Instrument files"): the wide per-run CSV of a Renishaw XL-80 / CARTO linear test
// (`Target Position (mm)`, `Direction`, `Run 1 (um)` ..., environment columns and `Key,Value`
// lines before the table) and weilgen's generic wide form (`# format: wide`, per-cycle columns
// `dx_um@1`, `dx_um@2` ...). One row of a wide file is one target in one direction; each run
// becomes one tidy row (target, direction, cycle, deviation, environment), so every verb that
// reads measurements reads these files too. Tidy files pass through read_measurements.
//
// Bad input throws InputError "file:line:column: message" naming the cell or header name, e.g.
//   carto.csv:14:19: column 'Run 3 (um)': 'abc' is not a number
//   carto.csv:12:31: column 'Air Pressure (psi)': unit 'psi' (expected Pa, hPa, mbar, kPa, ...)
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "weilgen/measure/measurement_csv.hpp"

namespace weilgen {

enum class InstrumentFormat { Tidy, Carto, Wide };
const char* to_string(InstrumentFormat format);  // "tidy", "carto", "wide"
// "auto" is not a format: callers keep std::nullopt for it. Throws std::invalid_argument.
InstrumentFormat parse_instrument_format(const std::string& text);

struct ImportOptions {
  std::optional<InstrumentFormat> format;  // none: detect_instrument_format
  // The axis letter (X, Y, Z, A, B, C, U, V, W) when a CARTO file has no `Axis` line; when it
  // has one they must agree (std::invalid_argument otherwise).
  std::string axis;
  // For tidy and generic wide files as read_measurements; allow_unknown also lets CARTO files
  // skip columns weilgen does not know, each with a warning.
  ReadOptions read;
};

struct ImportResult {
  MeasurementTable table;  // tidy: one row per observation; lines are the source rows' lines
  InstrumentFormat format = InstrumentFormat::Tidy;
  // One line per source column of a wide file: "'Run 3 (um)' -> dx_um of cycle 3 (um, x 1)".
  std::vector<std::string> mapping;
  std::size_t source_rows = 0;  // data rows of the file
};

// Wide when a `# format: wide` header key comes before the header row; CARTO when a row's first
// cell is a target column (`Target Position (mm)`, `Target (deg)` ...) within the first 200
// lines; tidy otherwise.
InstrumentFormat detect_instrument_format(const std::string& text);

// `filename` names the file in messages and in ImportResult::table.file.
ImportResult parse_instrument_text(const std::string& text, const std::string& filename,
                                   const ImportOptions& options = {});
// Reads a file (InputError "path: cannot read file" when it cannot be opened).
ImportResult read_instrument_file(const std::string& path, const ImportOptions& options = {});

}  // namespace weilgen
