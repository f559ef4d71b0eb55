// The flags of `iso230-2` beyond the evaluation's own, in their written form, for both front ends
// (the CLI's cli/iso_flags.cpp and the Python module's weilgen.iso230_2): the instrument file's
// format, the normalisation to 20 °C and air compensation (normalisation.hpp), tolerances and the
// HTML report (docs/iso230-2.md).
#pragma once

#include <optional>
#include <string>

#include "weilgen/measure/instrument_import.hpp"
#include "weilgen/measure/iso230_2_study.hpp"

namespace weilgen {

struct Iso230_2Flags {
  std::string format = "auto";                      // --format
  std::string normalise = "auto";                   // --normalise: auto, force or never
  bool iso_only = false;                            // --iso-only
  std::optional<std::string> uncertainty;           // --uncertainty: auto, a class or a budget file
  std::optional<double> expansion_ppm_per_K;        // --expansion, ppm/K
  std::optional<std::string> material_temperature;  // --material-temperature: degC or columns
  std::optional<std::string> air_compensation;      // --air-compensation
  std::optional<std::string> air_temperature;       // --air-temperature: degC or a column
  std::optional<std::string> air_pressure;          // --air-pressure: Pa (or hPa ...) or a column
  std::optional<std::string> air_humidity;          // --air-humidity: % or a column
  std::optional<double> wavelength_nm;              // --wavelength, nm
  std::optional<double> air_index_assumed;          // --air-index-assumed
  std::optional<double> datum_mm;                   // --datum, mm
  std::string tolerance;                            // --tolerance; empty: none
  std::string report;                               // --report FILE.html; empty: none

  // Into the study's options and the import's (std::invalid_argument naming the flag); checks
  // that --report is an .html file (the front end checks it with its other outputs before any
  // work).
  void apply(Iso230_2StudyOptions& study, ImportOptions& import) const;
};

}  // namespace weilgen
