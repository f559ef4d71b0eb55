#include "weilgen/measure/iso230_2_flags.hpp"

#include <filesystem>
#include <stdexcept>
#include <tuple>

#include "weilgen/base/text.hpp"
#include "weilgen/measure/iso230_2_uncertainty.hpp"
#include "weilgen/measure/normalisation.hpp"

namespace weilgen {

void Iso230_2Flags::apply(Iso230_2StudyOptions& s, ImportOptions& imp) const {
  if (lower(format) != "auto") imp.format = parse_instrument_format(format);
  NormalisationOptions& n = s.normalisation;
  n.mode = parse_normalise_mode(normalise);
  s.iso_only = iso_only;
  if (expansion_ppm_per_K) n.expansion_ppm_per_K = *expansion_ppm_per_K;
  if (wavelength_nm) n.wavelength_nm = *wavelength_nm;
  if (air_index_assumed) n.assumed_index = *air_index_assumed;
  if (datum_mm) n.datum_mm = *datum_mm;
  if (air_compensation) n.air = parse_air_compensation(*air_compensation, "--air-compensation");
  const std::tuple<const char*, const std::optional<std::string>*, EnvironmentSource*,
                   EnvironmentQuantity>
      sources[] = {
          {"--material-temperature", &material_temperature, &n.material_temperature,
           EnvironmentQuantity::MaterialTemperature},
          {"--air-temperature", &air_temperature, &n.air_temperature,
           EnvironmentQuantity::AirTemperature},
          {"--air-pressure", &air_pressure, &n.air_pressure, EnvironmentQuantity::AirPressure},
          {"--air-humidity", &air_humidity, &n.air_humidity, EnvironmentQuantity::AirHumidity}};
  for (const auto& [flag, text, source, quantity] : sources)
    if (*text) *source = parse_environment_source(**text, quantity, flag);
  n.validate();
  if (!tolerance.empty()) s.tolerance = parse_iso_tolerance(tolerance);
  if (uncertainty) s.uncertainty = uncertainty_budget_from_flag(*uncertainty);
  if (!report.empty()) {
    const std::string ext = lower(std::filesystem::path(report).extension().string());
    if (ext != ".html" && ext != ".htm")
      throw std::invalid_argument("--report " + report + ": the report is an .html file");
  }
}

}  // namespace weilgen
