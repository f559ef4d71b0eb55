// Normalisation of laser positioning deviations to the reference temperature 20 °C (ISO 1;
// ISO 230-2:2014 asks for the nominal differential expansion to be corrected or stated) and the
// correction of readings for the refractive index of air when the instrument did not apply it
// (weilgen/measure/air_refraction.hpp). Both are optional; the result says what was done, from
// which values, and how large the corrections were. Formulas and sign conventions:
// docs/iso230-2.md, "Normalisation to 20 °C and air refraction".
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "weilgen/measure/air_refraction.hpp"
#include "weilgen/measure/iso230_2.hpp"
#include "weilgen/measure/measurement_csv.hpp"

namespace weilgen {

// Who compensated the laser readings for the refractive index of air.
enum class AirCompensation {
  Unstated,    // the file does not say: nothing is corrected, and the output says so
  Instrument,  // the instrument did (its weather station or typed-in values): nothing to do
  Edlen,       // weilgen corrects the readings from the air's temperature, pressure, humidity
  None,        // nobody did and nobody will: the output warns that the readings are raw
};
const char* to_string(AirCompensation mode);  // "unstated", "instrument", "edlen", "none"
// "instrument", "edlen", "none" (case-insensitive); std::invalid_argument otherwise.
AirCompensation parse_air_compensation(const std::string& text, const std::string& what);

enum class EnvironmentQuantity { MaterialTemperature, AirTemperature, AirPressure, AirHumidity };

// One quantity of the environment: a constant, or the mean of some columns of each row.
struct EnvironmentSource {
  std::optional<double> value;       // in the quantity's unit: °C, Pa, %
  std::vector<std::string> columns;  // columns of the table (T_<name>, p_air_Pa, RH_air_pct)
  std::string origin;                // "--air-pressure", "header key air_pressure_Pa", ...
  bool given() const { return value.has_value() || !columns.empty(); }
};

// "21.3" (°C or %), "1013.25 hPa" (a pressure: Pa, hPa, mbar, kPa; Pa when no unit is written),
// or column names "T_table,T_scale". Throws std::invalid_argument "<origin>: why".
EnvironmentSource parse_environment_source(const std::string& text, EnvironmentQuantity quantity,
                                           const std::string& origin);

struct NormalisationOptions {
  double reference_temperature_C = 20;  // ISO 1
  // α of the machine's material (its scale or the part the material sensors sit on), µm/(m·K)
  // = ppm/K; none: no expansion correction.
  std::optional<double> expansion_ppm_per_K;
  EnvironmentSource material_temperature;  // none: the columns T_material, T_material_<k>
  AirCompensation air = AirCompensation::Unstated;
  EnvironmentSource air_temperature, air_pressure, air_humidity;  // none: T_air, p_air_Pa,
                                                                  // RH_air_pct
  std::optional<double> wavelength_nm;  // vacuum wavelength; none: kHeNeWavelength_nm
  std::optional<double> assumed_index;  // the index the readings assumed; none: 1 (vacuum)
  std::optional<double> datum_mm;       // where the laser was zeroed; none: the lowest target
  // The constants within their ranges (std::invalid_argument naming the origin): expansion
  // [-10, 100] ppm/K, temperatures and pressure as air_refraction.hpp, humidity [0, 100] %,
  // material temperature [-50, 100] °C, wavelength [350, 650] nm, assumed index [1, 1.001].
  void validate() const;
};

// Fills what `options` leaves unset from the table's header keys: expansion_ppm_per_K,
// material_temperature_C, air_compensation, air_temperature_C, air_pressure_Pa,
// air_humidity_pct, laser_wavelength_nm, air_index_assumed, datum_mm (a flag wins over a key).
// A bad value is an InputError "file:line: header key 'expansion_ppm_per_K': ...".
NormalisationOptions normalisation_with_header_keys(NormalisationOptions options,
                                                    const MeasurementTable& table);

struct ValueRange {
  double min = std::numeric_limits<double>::quiet_NaN();
  double mean = std::numeric_limits<double>::quiet_NaN();
  double max = std::numeric_limits<double>::quiet_NaN();
  std::size_t count = 0;
  void add(double v);  // NaN ignored
  bool empty() const { return count == 0; }
};

struct NormalisationResult {
  double reference_temperature_C = 20;
  double datum_mm = 0;
  // Expansion to 20 °C: δ_T = −α (T_m − 20) L, L the displacement from the datum.
  bool material_applied = false;
  double expansion_ppm_per_K = std::numeric_limits<double>::quiet_NaN();
  std::string material_source;  // "" when no material temperature is known
  ValueRange material_temperature_C, material_correction_um;
  // Air: δ_air = L_read (n0/n − 1), the reading L_read = (P − P0) + x counted with index n0.
  AirCompensation air = AirCompensation::Unstated;
  bool air_applied = false;
  double wavelength_nm = kHeNeWavelength_nm, assumed_index = 1;
  std::string air_temperature_source, air_pressure_source, air_humidity_source;
  ValueRange air_temperature_C, air_pressure_Pa, air_humidity_pct, air_refractivity,
      air_correction_um;
  // Per observation (the order of the observations): δ_air + δ_T, µm, added to x.
  std::vector<double> correction_um;
  bool applied() const { return material_applied || air_applied; }
};

// Corrects the deviations of `observations` (read from `table` by iso_observations) in place and
// says what it did. The environment is read for every observation's row; the temperatures and
// air values are reported even when nothing is corrected. Throws InputError (file:line, the
// column) for a needed value missing or outside its range in a measured row, or a correction
// asked for without its inputs; std::invalid_argument for a correction of an angular axis
// (`deviation_unit` not "um").
NormalisationResult normalise_observations(const MeasurementTable& table,
                                           std::vector<IsoObservation>& observations,
                                           const NormalisationOptions& options,
                                           const std::string& deviation_unit);

}  // namespace weilgen
