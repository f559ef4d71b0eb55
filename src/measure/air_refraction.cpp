#include "weilgen/measure/air_refraction.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "weilgen/base/format.hpp"

namespace weilgen {

namespace {

void check_range(double v, double lo, double hi, const std::string& what, const std::string& unit) {
  if (!(v >= lo && v <= hi))
    throw std::invalid_argument(what + " " + format_short(v) + " " + unit + " is outside [" +
                                format_short(lo) + ", " + format_short(hi) + "] " + unit);
}

}  // namespace

double saturation_vapour_pressure_Pa(double temperature_C) {
  check_range(temperature_C, kAirTemperatureMin_C, kAirTemperatureMax_C, "air temperature", "degC");
  // IAPWS-IF97, region 4: the coefficients n1 .. n10 and eq. 30 (T in K, p in MPa).
  const double n[10] = {0.11670521452767e4,  -0.72421316703206e6, -0.17073846940092e2,
                        0.12020824702470e5,  -0.32325550322333e7, 0.14915108613530e2,
                        -0.48232657361591e4, 0.40511340542057e6,  -0.23855557567849,
                        0.65017534844798e3};
  const double T = temperature_C + 273.15;
  const double theta = T + n[8] / (T - n[9]);
  const double A = theta * theta + n[0] * theta + n[1];
  const double B = n[2] * theta * theta + n[3] * theta + n[4];
  const double C = n[5] * theta * theta + n[6] * theta + n[7];
  const double p_MPa = std::pow(2 * C / (-B + std::sqrt(B * B - 4 * A * C)), 4);
  return p_MPa * 1e6;
}

double air_refractivity(const AirConditions& air, double wavelength_nm) {
  check_range(wavelength_nm, kWavelengthMin_nm, kWavelengthMax_nm, "laser wavelength", "nm");
  check_range(air.pressure_Pa, kAirPressureMin_Pa, kAirPressureMax_Pa, "air pressure", "Pa");
  check_range(air.humidity_pct, 0, 100, "air humidity", "%");
  const double t = air.temperature_C, p = air.pressure_Pa;
  const double f = air.humidity_pct / 100 * saturation_vapour_pressure_Pa(t);  // checks t
  const double s2 = std::pow(1000 / wavelength_nm, 2);                         // µm⁻²
  const double n_s = 1e-8 * (8342.54 + 2406147 / (130 - s2) + 15998 / (38.9 - s2));
  const double n_tp =
      p * n_s / 96095.43 * (1 + 1e-8 * (0.601 - 0.00972 * t) * p) / (1 + 0.0036610 * t);
  return n_tp - f * (3.7345 - 0.0401 * s2) * 1e-10;
}

}  // namespace weilgen
