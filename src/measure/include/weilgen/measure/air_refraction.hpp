// The refractive index of air for laser interferometry: the modified Edlén equation of
// K. P. Birch and M. J. Downs, "An updated Edlén equation for the refractive index of air",
// Metrologia 30 (1993) 155–162, with their "Correction to the updated Edlén equation for the
// refractive index of air", Metrologia 31 (1994) 315–316; the saturation vapour pressure of
// water of IAPWS-IF97 (its eq. 30, the saturation-pressure equation of region 4), which turns a
// relative humidity into the partial pressure of water vapour. Formulas, validity and the hand
// computation: docs/iso230-2.md, "Air refraction".
#pragma once

namespace weilgen {

// The air a laser beam runs through.
struct AirConditions {
  double temperature_C = 20;    // °C
  double pressure_Pa = 101325;  // Pa
  double humidity_pct = 50;     // relative humidity, % (0..100)
};

// The range where weilgen evaluates the equation (the dispersion formula is fitted for
// 350..650 nm; IAPWS-IF97's saturation line starts at 0 °C).
inline constexpr double kAirTemperatureMin_C = 0, kAirTemperatureMax_C = 50;
inline constexpr double kAirPressureMin_Pa = 50e3, kAirPressureMax_Pa = 150e3;
inline constexpr double kWavelengthMin_nm = 350, kWavelengthMax_nm = 650;
// The vacuum wavelength of the helium-neon red line (632.816 nm in standard air). An instrument's
// certificate states its own; 0.01 nm more lowers n − 1 by 1.2e-10 (0.12 nm per metre).
inline constexpr double kHeNeWavelength_nm = 632.991;

// Saturation vapour pressure of water over liquid water, Pa, at `temperature_C` in
// [0, 50] °C (IAPWS-IF97 eq. 30). Throws std::invalid_argument outside.
double saturation_vapour_pressure_Pa(double temperature_C);

// n − 1 of moist air with 450 µmol/mol CO2 at the vacuum wavelength `wavelength_nm`:
//   σ² = (1000 / λ_nm)² µm⁻²
//   (n − 1)_s  = 1e-8 [8342.54 + 2406147 / (130 − σ²) + 15998 / (38.9 − σ²)]
//   (n − 1)_tp = p (n − 1)_s / 96095.43 · [1 + 1e-8 (0.601 − 0.00972 t) p] / (1 + 0.0036610 t)
//   n − 1      = (n − 1)_tp − f (3.7345 − 0.0401 σ²) 1e-10,  f = RH/100 · p_sv(t)  (Pa)
// Throws std::invalid_argument (naming the quantity) outside the ranges above or for a humidity
// outside [0, 100] %.
double air_refractivity(const AirConditions& air, double wavelength_nm = kHeNeWavelength_nm);

}  // namespace weilgen
