// The flags of `iso230-2` beyond the evaluation's own: the instrument file format, the
// normalisation to 20 °C and air compensation (weilgen/measure/normalisation.hpp), tolerances and
// the HTML report (docs/iso230-2.md).
#pragma once

#include <boost/program_options.hpp>
#include <string>

#include "weilgen/measure/instrument_import.hpp"
#include "weilgen/measure/iso230_2_flags.hpp"
#include "weilgen/measure/iso230_2_study.hpp"

namespace weilgen::cli {

struct IsoFlags {
  std::string format = "auto";     // --format
  std::string normalise = "auto";  // --normalise
  std::string uncertainty;         // --uncertainty
  std::string report;              // --report FILE.html
  std::string tolerance;           // --tolerance
  double expansion_ppm_per_K = 0, wavelength_nm = 0, air_index_assumed = 0, datum_mm = 0;
};

// --format, --normalise, --expansion, --material-temperature, --air-compensation,
// --air-temperature,
// --air-pressure, --air-humidity, --wavelength, --air-index-assumed, --datum, --tolerance,
// --report, --iso-only, --uncertainty.
boost::program_options::options_description iso_options(IsoFlags& flags);

// The flags into the study's options and the import's through Iso230_2Flags::apply (the same
// steps as the Python module's).
void apply_iso_flags(const IsoFlags& flags, const boost::program_options::variables_map& vm,
                     Iso230_2StudyOptions& study, ImportOptions& import);

}  // namespace weilgen::cli
