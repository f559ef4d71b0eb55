// base/units' temperature and pressure units (the one table the instrument import and the
// ISO 230-2 environment flags share): each unit against its defining value, spellings, and the
// message of an unknown unit.
#include <doctest/doctest.h>

#include <stdexcept>
#include <string>

#include "weilgen/base/units.hpp"

using namespace weilgen;

namespace {

std::string unit_error(AffineUnit (*parse)(const std::string&), const std::string& unit) {
  try {
    parse(unit);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("units: temperatures to degC by their defining points") {
  // Water freezes at 0 degC = 32 degF = 273.15 K and boils at 100 degC = 212 degF = 373.15 K.
  for (const char* c : {"degC", "C", "c",
                        "\xC2\xB0"
                        "C",
                        "\xC2\xBA"
                        "C",
                        "deg C", "DEG_C"}) {
    const AffineUnit u = parse_temperature_unit(c);
    CHECK(u.to_base(20.5) == 20.5);
  }
  for (const char* f : {"degF", "F",
                        "\xC2\xB0"
                        "F"}) {
    const AffineUnit u = parse_temperature_unit(f);
    CHECK(u.to_base(32) == doctest::Approx(0).epsilon(1e-15));
    CHECK(u.to_base(212) == doctest::Approx(100).epsilon(1e-15));
    CHECK(u.to_base(68) == doctest::Approx(20).epsilon(1e-15));
  }
  const AffineUnit k = parse_temperature_unit("K");
  CHECK(k.to_base(273.15) == 0);
  CHECK(k.to_base(293.15) == doctest::Approx(20).epsilon(1e-15));
  CHECK(unit_error(parse_temperature_unit, "Rankine") ==
        "unit 'Rankine' (expected degC, degF or K)");
  CHECK(unit_error(parse_temperature_unit, "") == "unit '' (expected degC, degF or K)");
}

TEST_CASE("units: pressures to Pa by their definitions") {
  CHECK(parse_pressure_unit("Pa").to_base(101325) == 101325);
  CHECK(parse_pressure_unit("hPa").to_base(1013.25) == doctest::Approx(101325).epsilon(1e-15));
  CHECK(parse_pressure_unit("mbar").to_base(1013.25) == doctest::Approx(101325).epsilon(1e-15));
  CHECK(parse_pressure_unit("kPa").to_base(101.325) == doctest::Approx(101325).epsilon(1e-15));
  // The conventional mmHg is 1 mm of mercury at 13595.1 kg/m^3 under g_n = 9.80665 m/s^2 (within
  // 1.5e-7 of the torr, 101325/760 Pa); the inHg is 25.4 of them.
  CHECK(parse_pressure_unit("mmHg").to_base(1) ==
        doctest::Approx(13595.1 * 9.80665 * 1e-3).epsilon(1e-12));
  CHECK(parse_pressure_unit("mmHg").to_base(760) == doctest::Approx(101325).epsilon(2e-7));
  CHECK(parse_pressure_unit("inHg").to_base(1) ==
        doctest::Approx(25.4 * 13595.1 * 9.80665 * 1e-3).epsilon(1e-8));
  CHECK(parse_pressure_unit(" MMHG ").factor == parse_pressure_unit("mmHg").factor);
  CHECK(parse_pressure_unit("mmHg").offset == 0);
  CHECK(unit_error(parse_pressure_unit, "psi") ==
        "unit 'psi' (expected Pa, hPa, mbar, kPa, mmHg or inHg)");
  CHECK(unit_error(parse_pressure_unit, "") ==
        "unit '' (expected Pa, hPa, mbar, kPa, mmHg or inHg)");
}
