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

// Whether weilgen applies a correction the instrument may already have applied (--normalise):
//   Auto   never a correction the file says the instrument applied; a correction the file says
//          it did not apply (or weilgen's own tidy keys ask for) when its inputs are there;
//   Force  every correction whose inputs are there, whatever the file says;
//   Never  none.
// The full rule per correction: docs/iso230-2.md, "Instrument compensation state".
enum class NormaliseMode { Auto, Force, Never };
const char* to_string(NormaliseMode mode);  // "auto", "force", "never"
// "auto", "force", "never" (case-insensitive); std::invalid_argument naming --normalise.
NormaliseMode parse_normalise_mode(const std::string& text);

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
  NormaliseMode mode = NormaliseMode::Auto;
  double reference_temperature_C = 20;  // ISO 1
  // α of the machine's material (its scale or the part the material sensors sit on), µm/(m·K)
  // = ppm/K; none: no expansion correction.
  std::optional<double> expansion_ppm_per_K;
  // Where α came from: "--expansion" (also when empty and α is set: a caller's value), or
  // "header key expansion_ppm_per_K" (normalisation_with_header_keys).
  std::string expansion_origin;
  // What the file says the instrument did about the material's expansion (header key
  // material_compensation, which the CARTO import writes from 'Material Compensation,On|Off'):
  // "instrument" (applied), "none" (not applied), "unstated" (a laser export without such a
  // line), or "" (no key: a tidy file of weilgen's, whose expansion key asks for the correction).
  std::string material_compensation;
  int material_compensation_line = 0;      // its header key's line (0: written by the import)
  EnvironmentSource material_temperature;  // none: the columns T_material, T_material_<k>
  AirCompensation air = AirCompensation::Unstated;
  // Where `air` came from: "--air-compensation" (also when empty and `air` is set) or "header
  // key air_compensation" (the file's statement about the instrument).
  std::string air_origin;
  AirCompensation air_in_file = AirCompensation::Unstated;  // the header key air_compensation
  int air_in_file_line = 0;
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
  NormaliseMode mode = NormaliseMode::Auto;
  double reference_temperature_C = 20;
  double datum_mm = 0;
  // The instrument's state as the file gives it ("instrument", "none", "unstated", "") and why
  // weilgen applied each correction or not (one sentence each, ASCII units).
  std::string material_compensation;
  std::string material_decision, air_decision;
  std::string expansion_origin;  // "" without α
  // Sensors that disagree with their siblings (a °F column read as °C ...), with file:line:column.
  std::vector<std::string> warnings;
  // Expansion to 20 °C: δ_T = −α (T_m − 20) L, L the displacement from the datum.
  bool material_applied = false;
  double expansion_ppm_per_K = std::numeric_limits<double>::quiet_NaN();
  std::string material_source;  // "" when no material temperature is known
  ValueRange material_temperature_C, material_correction_um;
  // Air: δ_air = L_read (n0/n − 1), the reading L_read = (P − P0) + x counted with index n0.
  AirCompensation air = AirCompensation::Unstated;          // Edlen when weilgen corrected the air
  AirCompensation air_in_file = AirCompensation::Unstated;  // what the file says
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
// says what it did. Throws std::invalid_argument naming the flags when a flag asks for a
// correction the mode or the file's state forbids (--expansion with --normalise never, or with a
// file whose instrument already compensated the material; --air-compensation edlen likewise). The
// environment is read for every observation's row; the temperatures and air values are reported
// even when nothing is corrected. Throws InputError (file:line, the column) for a needed value
// missing or outside its range in a measured row, or a correction asked for without its inputs;
// std::invalid_argument for a correction of an angular axis
// (`deviation_unit` not "um").
NormalisationResult normalise_observations(const MeasurementTable& table,
                                           std::vector<IsoObservation>& observations,
                                           const NormalisationOptions& options,
                                           const std::string& deviation_unit);

}  // namespace weilgen
