// Air refraction (weilgen/measure/air_refraction.hpp) and the normalisation of ISO 230-2
// deviations to 20 °C (weilgen/measure/normalisation.hpp, docs/iso230-2.md): the saturation
// pressure against IAPWS-IF97's own verification value, the modified Edlén equation of Birch &
// Downs against a hand computation and against an independent equation (Ciddor 1996), the
// corrections of single observations against hand-computed values, header keys and flags, and
// the errors.
#include <doctest/doctest.h>

#include <cmath>

#include "test_support.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/measure/air_refraction.hpp"
#include "weilgen/measure/iso230_2_study.hpp"
#include "weilgen/measure/normalisation.hpp"

using namespace weilgen;

namespace {

// Ciddor, "Refractive index of air: new equations for the visible and near infrared", Appl. Opt.
// 35 (1996) 1566, eqs. (1)-(5), (12), with the BIPM-1981/91 compressibility and the enhancement
// factor of its appendix; 450 µmol/mol CO2. A different construction from Edlén's (densities of
// dry air and water vapour from the CIPM equation of state), written here independently of the
// library. The saturation pressure is the library's (checked against IF97 below).
double ciddor_refractivity(double t_C, double p_Pa, double rh_pct, double lambda_um) {
  const double T = t_C + 273.15, s2 = 1 / (lambda_um * lambda_um);
  const double n_as = 1e-8 * (5792105 / (238.0185 - s2) + 167917 / (57.362 - s2));
  const double n_ws =
      1.022e-8 * (295.235 + 2.6422 * s2 - 0.032380 * s2 * s2 + 0.004028 * s2 * s2 * s2);
  const double Ma = 1e-3 * (28.9635 + 12.011e-6 * (450 - 400)), Mw = 0.018015, R = 8.314510;
  const double f = 1.00062 + 3.14e-8 * p_Pa + 5.6e-7 * t_C * t_C;
  const double xw = f * rh_pct / 100 * saturation_vapour_pressure_Pa(t_C) / p_Pa;
  auto Z = [](double p, double TK, double x) {
    const double t = TK - 273.15;
    return 1 -
           (p / TK) * (1.58123e-6 - 2.9331e-8 * t + 1.1043e-10 * t * t +
                       (5.707e-6 - 2.051e-8 * t) * x + (1.9898e-4 - 2.376e-6 * t) * x * x) +
           (p / TK) * (p / TK) * (1.83e-11 - 0.765e-8 * x * x);
  };
  const double rho_axs = 101325 * Ma / (Z(101325, 288.15, 0) * R * 288.15);
  const double rho_ws = 1333 * Mw / (Z(1333, 293.15, 1) * R * 293.15);
  const double Zm = Z(p_Pa, T, xw);
  const double rho_a = p_Pa * Ma * (1 - xw) / (Zm * R * T);
  const double rho_w = p_Pa * Mw * xw / (Zm * R * T);
  return rho_a / rho_axs * n_as + rho_w / rho_ws * n_ws;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("air: IAPWS-IF97 saturation pressure against the standard's verification value") {
  // IF97, Table 35: T = 300 K -> p_s = 0.353658941e-2 MPa.
  CHECK(saturation_vapour_pressure_Pa(26.85) == doctest::Approx(3536.58941).epsilon(1e-9));
  // 20 degC: 2339.2 Pa (the steam tables' 2.3392 kPa).
  CHECK(saturation_vapour_pressure_Pa(20) == doctest::Approx(2339.21).epsilon(1e-5));
  CHECK_THROWS_AS(saturation_vapour_pressure_Pa(-5), std::invalid_argument);
  CHECK_THROWS_AS(saturation_vapour_pressure_Pa(60), std::invalid_argument);
}

TEST_CASE("air: the modified Edlen equation at 20 degC, 101325 Pa, 50 %RH, by hand") {
  // Inputs: t = 20 degC, p = 101325 Pa, RH = 50 %, lambda = 632.991 nm (vacuum).
  // sigma^2 = (1 / 0.632991 um)^2                                      = 2.4957721 um^-2
  // (n-1)_s = 1e-8 [8342.54 + 2406147/(130 - 2.4957721) + 15998/(38.9 - 2.4957721)]
  //         = 1e-8 [8342.54 + 18870.9196 + 439.4578]                   = 2.7653110e-4
  // (n-1)_tp = 101325 (n-1)_s / 96095.43 * (1 + 1e-8 (0.601 - 0.1944) 101325) / (1.07322)
  //          = 2.9158555e-4 * 1.00041199 / 1.07322                     = 2.7179908e-4
  // f = 0.5 * p_sv(20 degC) = 0.5 * 2339.2148 Pa                       = 1169.6074 Pa
  // water term = f (3.7345 - 0.0401 sigma^2) 1e-10 = 1169.6074 * 3.6344 * 1e-10 = 4.250844e-7
  // n - 1 = 2.7179908e-4 - 4.250844e-7                                  = 2.7137400e-4
  const AirConditions air{20, 101325, 50};
  CHECK(air_refractivity(air, 632.991) == doctest::Approx(2.71374e-4).epsilon(2e-6));
  // Dry air: the (n-1)_tp line alone.
  CHECK(air_refractivity({20, 101325, 0}, 632.991) == doctest::Approx(2.7179908e-4).epsilon(1e-7));
  // The humidity term alone.
  CHECK(air_refractivity({20, 101325, 0}, 632.991) - air_refractivity(air, 632.991) ==
        doctest::Approx(4.250844e-7).epsilon(1e-5));
  // Sensitivities a laser user knows: ~ -0.93 ppm/K, +2.7 ppm/kPa, -0.0085 ppm/%RH at 20 degC.
  const double n0 = air_refractivity(air, 632.991);
  CHECK((air_refractivity({21, 101325, 50}, 632.991) - n0) * 1e6 ==
        doctest::Approx(-0.93).epsilon(0.03));
  CHECK((air_refractivity({20, 102325, 50}, 632.991) - n0) * 1e6 ==
        doctest::Approx(2.68).epsilon(0.03));
  CHECK((air_refractivity({20, 101325, 60}, 632.991) - n0) * 1e6 ==
        doctest::Approx(-0.085).epsilon(0.05));  // 10 %RH more
}

TEST_CASE("air: Birch & Downs agrees with Ciddor 1996 within 3e-8 over workshop air") {
  double worst = 0;
  for (double t : {15.0, 18.0, 20.0, 22.0, 25.0, 28.0})
    for (double p : {95e3, 98e3, 101325.0, 103e3, 105e3})
      for (double rh : {0.0, 20.0, 40.0, 50.0, 60.0, 70.0})
        worst = std::max(worst, std::abs(air_refractivity({t, p, rh}, 632.991) -
                                         ciddor_refractivity(t, p, rh, 0.632991)));
  MESSAGE("max |Edlen - Ciddor| = " << worst);
  CHECK(worst < 3e-8);  // measured 2.6e-8 (28 degC, 70 %RH); the humidity term is 4e-7
  CHECK(ciddor_refractivity(20, 101325, 50, 0.632991) == doctest::Approx(2.71373e-4).epsilon(1e-5));
}

TEST_CASE("air: values outside the equation's range are refused with the quantity named") {
  CHECK(error_of([] {
          air_refractivity({20, 1013.25, 50});
        }).find("air pressure") != std::string::npos);
  CHECK(error_of([] {
          air_refractivity({20, 101325, 120});
        }).find("air humidity") != std::string::npos);
  CHECK(error_of([] {
          air_refractivity({20, 101325, 50}, 1064);
        }).find("wavelength") != std::string::npos);
}

TEST_CASE("normalisation: one observation corrected by hand (expansion, then air)") {
  // X = 500 mm, x = 10 um, datum 0: the laser read L = 500.010 mm.
  // Air (instrument counted vacuum wavelengths, n0 = 1; air 20 degC, 101325 Pa, 50 %RH):
  //   n - 1 = 2.71373998e-4; delta_air = L (n0/n - 1) = -500.010 * 2.71373998e-4 / 1.000271374 mm
  //   = -135.6529 um.
  // Expansion (alpha = 11.5 um/(m K), T = 21.5 degC) on the true travel L + delta_air:
  //   delta_T = -11.5 * 1.5 * (500.010 - 0.1356529) * 1e-3 = -8.622832 um.
  // x' = 10 - 135.6529 - 8.622832 = -134.275733 um.
  const std::string text =
      "# axis: X\n# air_compensation: edlen\n# expansion_ppm_per_K: 11.5\n"
      "X,dir,cycle,dx_um,T_material,T_air,p_air_Pa,RH_air_pct\n"
      "500,1,1,10,21.5,20,101325,50\n";
  const MeasurementTable t = parse_measurements(text, "one.csv");
  std::vector<IsoObservation> obs = iso_observations(t, iso_columns(t));
  NormalisationOptions o = normalisation_with_header_keys({}, t);
  o.datum_mm = 0;
  const NormalisationResult r = normalise_observations(t, obs, o, "um");
  CHECK(r.air_applied);
  CHECK(r.material_applied);
  CHECK(r.air_correction_um.mean == doctest::Approx(-135.6529002).epsilon(1e-9));
  CHECK(r.material_correction_um.mean == doctest::Approx(-8.6228325).epsilon(1e-8));
  CHECK(obs[0].deviation == doctest::Approx(-134.2757327).epsilon(1e-9));
  CHECK(r.air_refractivity.mean == doctest::Approx(2.71374e-4).epsilon(2e-6));
  CHECK(r.material_source == "column T_material");
}

TEST_CASE("normalisation: a thermal slope on the deviations is removed exactly") {
  // The laser reads L = (P + profile) / (1 - alpha (T - 20)) with T changing per cycle, i.e.
  // x = L - P; the correction -alpha (T - 20) L leaves exactly the profile.
  std::string text = "# axis: X\n# expansion_ppm_per_K: 11.7\nX,dir,cycle,dx_um,T_material\n";
  std::vector<double> profile;
  for (int j = 1; j <= 4; ++j)
    for (int d : {1, -1})
      for (int i = 0; i <= 5; ++i) {
        const double P = 200.0 * i, T = 21 + 0.1 * j;
        const double base = 2 * std::sin(P / 300) + 0.5 * d;
        const double x = ((P + base * 1e-3) / (1 - 11.7e-6 * (T - 20)) - P) * 1e3;
        text += std::to_string(P) + "," + std::to_string(d) + "," + std::to_string(j) + "," +
                format_number(x) + "," + format_number(T) + "\n";
        profile.push_back(base);
      }
  const MeasurementTable t = parse_measurements(text, "slope.csv");
  std::vector<IsoObservation> obs = iso_observations(t, iso_columns(t));
  const NormalisationResult r =
      normalise_observations(t, obs, normalisation_with_header_keys({}, t), "um");
  for (std::size_t k = 0; k < obs.size(); ++k)
    CHECK(obs[k].deviation == doctest::Approx(profile[k]).epsilon(1e-6));
  CHECK(r.material_temperature_C.min == doctest::Approx(21.1));
  CHECK(r.material_temperature_C.max == doctest::Approx(21.4));
  CHECK(r.air == AirCompensation::Unstated);
  CHECK_FALSE(r.air_applied);
  // Through the study: E shrinks to the profile's, the same as a file without the slope.
  Iso230_2StudyOptions so;
  const Iso230_2StudyResult normalised = Iso230_2Study(so).run(t);
  Iso230_2StudyOptions off;
  off.normalisation.expansion_ppm_per_K = 0;  // a flag wins over the header key
  const Iso230_2StudyResult raw = Iso230_2Study(off).run(t);
  // The thermal part, 11.7 um/(m K) * (1.1 .. 1.4) K * 1000 mm = 12.9 .. 16.4 um, goes away.
  CHECK(raw.classical.figures.E > normalised.classical.figures.E + 10);
  CHECK(normalised.classical.figures.B == doctest::Approx(1.0).epsilon(1e-6));
}

TEST_CASE("normalisation: constants and columns from flags, header keys and defaults") {
  const std::string text =
      "# axis: X\n# material_temperature_C: 22\n# air_pressure_Pa: 1000 hPa\n"
      "# air_temperature_C: T_room\n# air_humidity_pct: 40\n# air_compensation: edlen\n"
      "X,dir,cycle,dx_um,T_room,T_table,T_scale\n"
      "0,1,1,0,19,21,23\n0,-1,1,0,19,21,23\n100,1,1,0,21,21,23\n100,-1,1,0,21,21,23\n";
  const MeasurementTable t = parse_measurements(text, "keys.csv");
  std::vector<IsoObservation> obs = iso_observations(t, iso_columns(t));
  NormalisationOptions o;
  o.expansion_ppm_per_K = 10;
  o.material_temperature = parse_environment_source(
      "T_table,T_scale", EnvironmentQuantity::MaterialTemperature, "--material-temperature");
  const NormalisationResult r =
      normalise_observations(t, obs, normalisation_with_header_keys(o, t), "um");
  // The flag's columns (mean 22 degC) win over the key's 22: the same here, by design of the
  // data; the source names the flag.
  CHECK(r.material_source == "mean of columns T_table, T_scale (--material-temperature)");
  CHECK(r.material_temperature_C.mean == doctest::Approx(22));
  CHECK(r.air_pressure_Pa.mean == doctest::Approx(100000));
  CHECK(r.air_pressure_source == "header key air_pressure_Pa");
  CHECK(r.air_temperature_C.min == doctest::Approx(19));
  CHECK(r.air_temperature_C.max == doctest::Approx(21));
  CHECK(r.datum_mm == 0);
  // At the datum nothing is corrected; at 100 mm: material -10 * 2 * L * 1e-3, L ~ 0.1 m.
  CHECK(obs[0].deviation == 0);
  const double n1 = air_refractivity({21, 100000, 40});
  const double air = 100 * (-n1 / (1 + n1)) * 1e3;
  CHECK(obs[2].deviation ==
        doctest::Approx(air - 10 * 2 * (100 + air * 1e-3) * 1e-3).epsilon(1e-12));

  // Parsing of constants.
  CHECK(*parse_environment_source("1013.25 hPa", EnvironmentQuantity::AirPressure, "--air-pressure")
             .value == doctest::Approx(101325));
  CHECK(*parse_environment_source("101.325kPa", EnvironmentQuantity::AirPressure, "x").value ==
        doctest::Approx(101325));
  CHECK(*parse_environment_source("20.5 degC", EnvironmentQuantity::AirTemperature, "x").value ==
        doctest::Approx(20.5));
  // The same units as the instrument import (base/units): degF, K, mmHg, inHg.
  CHECK(*parse_environment_source("68 degF", EnvironmentQuantity::AirTemperature, "x").value ==
        doctest::Approx(20).epsilon(1e-15));
  CHECK(
      *parse_environment_source("293.15 K", EnvironmentQuantity::MaterialTemperature, "x").value ==
      doctest::Approx(20).epsilon(1e-15));
  CHECK(*parse_environment_source("760 mmHg", EnvironmentQuantity::AirPressure, "x").value ==
        doctest::Approx(101325).epsilon(2e-7));
  CHECK(*parse_environment_source("1013 mbar", EnvironmentQuantity::AirPressure, "x").value ==
        doctest::Approx(101300));
  CHECK(error_of([] {
          parse_environment_source("20 degR", EnvironmentQuantity::AirTemperature,
                                   "--air-temperature");
        }) == "--air-temperature: unit 'degR' (expected degC, degF or K)");
  CHECK(error_of([] {
          parse_environment_source("40 ppm", EnvironmentQuantity::AirHumidity, "--air-humidity");
        }) == "--air-humidity: unit 'ppm' (expected % or none)");
  CHECK(error_of([] {
          parse_environment_source("1013", EnvironmentQuantity::AirPressure, "--air-pressure");
        }) == "--air-pressure: 1013 Pa is outside [50000, 150000] Pa");
  CHECK(error_of([] {
          parse_environment_source("12 psi", EnvironmentQuantity::AirPressure, "--air-pressure");
        }).find("unit 'psi'") != std::string::npos);
  CHECK(parse_air_compensation("EDLEN", "x") == AirCompensation::Edlen);
  CHECK_THROWS_AS(parse_air_compensation("yes", "--air-compensation"), std::invalid_argument);
}

TEST_CASE("normalisation: missing or bad inputs name the file, line and column or flag") {
  auto run_text = [](const std::string& text, NormalisationOptions o = {}) {
    return error_of([&] {
      const MeasurementTable t = parse_measurements(text, "bad.csv");
      std::vector<IsoObservation> obs = iso_observations(t, iso_columns(t));
      normalise_observations(t, obs, normalisation_with_header_keys(o, t), "um");
    });
  };
  CHECK(run_text("# axis: X\n# expansion_ppm_per_K: 11.5\nX,dir,cycle,dx_um\n0,1,1,0\n") ==
        "bad.csv:3: an expansion coefficient is given but no material temperature: add a column "
        "T_material (T_material_<k>), --material-temperature or the header key "
        "material_temperature_C");
  CHECK(run_text("# axis: X\n# expansion_ppm_per_K: abc\nX,dir,cycle,dx_um\n0,1,1,0\n") ==
        "bad.csv:2: header key expansion_ppm_per_K: 'abc' is not a number");
  CHECK(run_text("# axis: X\n# expansion_ppm_per_K: 500\nX,dir,cycle,dx_um\n0,1,1,0\n") ==
        "bad.csv:2: header key expansion_ppm_per_K: 500 ppm/K is outside [-10, 100] ppm/K");
  CHECK(
      run_text("# air_compensation: edlen\nX,dir,cycle,dx_um,T_air,RH_air_pct\n0,1,1,0,20,50\n") ==
      "bad.csv:2: air compensation 'edlen' needs the air pressure: a column p_air_Pa, "
      "--air-pressure or header key air_pressure_Pa");
  CHECK(run_text("# air_compensation: edlen\nX,dir,cycle,dx_um,T_air,p_air_Pa,RH_air_pct\n"
                 "0,1,1,0,20,101325,50\n10,1,1,0,20,1013,50\n") ==
        "bad.csv:4: column 'p_air_Pa': air pressure 1013 Pa is outside [50000, 150000] Pa");
  CHECK(run_text("# air_compensation: edlen\nX,dir,cycle,dx_um,T_air,p_air_Pa,RH_air_pct\n"
                 "0,1,1,0,,101325,50\n") ==
        "bad.csv:3: column 'T_air': empty, but the air temperature is needed for this measured "
        "row");
  CHECK(run_text("# air_compensation: maybe\nX,dir,cycle,dx_um\n0,1,1,0\n")
            .rfind("bad.csv:1: header key air_compensation: 'maybe'", 0) == 0);
  NormalisationOptions o;
  o.material_temperature.columns = {"T_missing"};
  o.material_temperature.origin = "--material-temperature";
  o.expansion_ppm_per_K = 11;
  CHECK(run_text("X,dir,cycle,dx_um\n0,1,1,0\n", o) ==
        "bad.csv:1: column 'T_missing' (--material-temperature) is not in the file (columns: X, "
        "dir, cycle, dx_um)");
  // A rotary axis: the corrections are for lengths.
  NormalisationOptions rot;
  rot.expansion_ppm_per_K = 11;
  rot.material_temperature.value = 21;
  CHECK(error_of([&] {
          const MeasurementTable t = parse_measurements("C,dir,cycle,dc_urad\n0,1,1,0\n", "r.csv");
          std::vector<IsoObservation> obs = iso_observations(t, iso_columns(t));
          normalise_observations(t, obs, rot, "urad");
        }).find("apply to a linear axis") != std::string::npos);
  // Options out of range.
  NormalisationOptions w;
  w.wavelength_nm = 1064;
  CHECK(error_of([&] { w.validate(); }) == "--wavelength: 1064 nm is outside [350, 650] nm");
}
