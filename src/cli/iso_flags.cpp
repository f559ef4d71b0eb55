#include "iso_flags.hpp"

#include <optional>

#include "flags.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

po::options_description iso_options(IsoFlags& f) {
  po::options_description o(
      "Instrument files, normalisation to 20 degC, air, tolerances, report (docs/iso230-2.md)");
  o.add_options()("format", po::value<std::string>(&f.format)->default_value(f.format),
                  "the data file's layout: auto, tidy, carto (Renishaw XL-80/CARTO wide CSV) or "
                  "wide (docs/data-format.md, 'Instrument files')")(
      "normalise", po::value<std::string>(&f.normalise)->default_value(f.normalise),
      "corrections the instrument may already have applied: auto (never one the file says the "
      "instrument applied; docs/iso230-2.md, 'Instrument compensation state'), force (normalise "
      "to 20 degC with the coefficient given, and allow --air-compensation edlen, whatever the "
      "file says) or never (no correction by weilgen)")(
      "expansion", ranged(&f.expansion_ppm_per_K, NumberRange::closed(-100, 100)),
      "expansion coefficient of the machine's material, um/(m K) = ppm/K: normalise the "
      "deviations to 20 degC (default: header key expansion_ppm_per_K, else none)")(
      "material-temperature", po::value<std::string>(),
      "material temperature: degC, or columns whose mean is used (T_table,T_scale; default: "
      "columns T_material, T_material_<k>, or header key material_temperature_C)")(
      "air-compensation", po::value<std::string>(),
      "who compensated the air's refractive index: instrument, edlen (weilgen, modified Edlen "
      "equation of Birch & Downs from the air columns) or none (default: header key "
      "air_compensation, else unstated)")(
      "air-temperature", po::value<std::string>(),
      "air temperature: degC or a column (default: column T_air, header key air_temperature_C)")(
      "air-pressure", po::value<std::string>(),
      "air pressure: Pa (or '1013.2 hPa', mbar, kPa) or a column (default: column p_air_Pa, "
      "header key air_pressure_Pa)")(
      "air-humidity", po::value<std::string>(),
      "relative humidity: % or a column (default: column RH_air_pct, header key "
      "air_humidity_pct)")("wavelength", ranged(&f.wavelength_nm, NumberRange::closed(100, 20000)),
                           "the laser's vacuum wavelength, nm (default 632.991, HeNe)")(
      "air-index-assumed", ranged(&f.air_index_assumed, NumberRange::closed(0.9, 1.1)),
      "the refractive index the uncompensated readings assumed (default 1: vacuum wavelength)")(
      "datum", ranged(&f.datum_mm, NumberRange{}),
      "the target (mm) where the laser was zeroed (default: the lowest target)")(
      "tolerance", po::value<std::string>(&f.tolerance),
      "tolerances in the deviation unit: a band +-T ('10'), figure limits ('A=12,R=6,B=4') or "
      "both ('10,A=12'); verdicts in the text, JSON and report")(
      "report", po::value<std::string>(&f.report),
      "write the test report as one self-contained HTML file (charts inline)")(
      "iso-only",
      "only the figures ISO 230-2 defines: no Student-t set, no drift-eliminated evaluation")(
      "uncertainty", po::value<std::string>(&f.uncertainty),
      "the measurement uncertainty of E, M, A, B, R (ISO 230-9, GUM, k = 2) and ISO 14253-1 "
      "verdicts: auto (the instrument class from the air compensation), a class "
      "(laser-compensated, laser-edlen, laser-manual, scale) or a budget file (YAML; "
      "docs/iso230-2.md, 'Measurement uncertainty')");
  return o;
}

void apply_iso_flags(const IsoFlags& f, const po::variables_map& vm, Iso230_2StudyOptions& s,
                     ImportOptions& imp) {
  Iso230_2Flags w;
  w.format = f.format;
  w.normalise = f.normalise;
  w.iso_only = vm.count("iso-only") > 0;
  const auto number = [&](const char* flag, double value) {
    return vm.count(flag) ? std::optional<double>(value) : std::nullopt;
  };
  const auto text = [&](const char* flag) {
    return vm.count(flag) ? std::optional<std::string>(vm[flag].as<std::string>()) : std::nullopt;
  };
  w.expansion_ppm_per_K = number("expansion", f.expansion_ppm_per_K);
  w.wavelength_nm = number("wavelength", f.wavelength_nm);
  w.air_index_assumed = number("air-index-assumed", f.air_index_assumed);
  w.datum_mm = number("datum", f.datum_mm);
  w.material_temperature = text("material-temperature");
  w.air_compensation = text("air-compensation");
  w.air_temperature = text("air-temperature");
  w.air_pressure = text("air-pressure");
  w.air_humidity = text("air-humidity");
  w.uncertainty = text("uncertainty");
  w.tolerance = f.tolerance;
  w.report = f.report;
  w.apply(s, imp);
}

}  // namespace weilgen::cli
