// 6D line measurements: Zhang & Chen 2021's Table 2 sign conversions, the eq. (1) straightness
// reference line, the CSV variant (# format: line6d) and its errors, and fit-pdge on the example
// file.
#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "weilgen/measure/line6d.hpp"
#include "weilgen/measure/pdge_fit.hpp"
#include "weilgen/report/plot.hpp"

using namespace weilgen;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<double> positions() {  // 0, 10, ..., 500 mm: symmetric about 250
  std::vector<double> x;
  for (int i = 0; i <= 50; ++i) x.push_back(10.0 * i);
  return x;
}

// A shape with no least-squares line of its own on positions(): even about 250 (so orthogonal
// to x - 250) with zero mean.
std::vector<double> bow(double amplitude) {
  const std::vector<double> x = positions();
  std::vector<double> y;
  double mean = 0;
  for (double v : x) {
    const double s = (v - 250) / 250;
    y.push_back(amplitude * (s * s + 0.3 * std::cos(2 * kPi * (v - 250) / 125)));
    mean += y.back() / static_cast<double>(x.size());
  }
  for (double& v : y) v -= mean;
  return y;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no exception)";
}

MeasurementTable table(const std::string& text) {
  return parse_measurements(text, "m.csv", line6d_read_options());
}

}  // namespace

TEST_CASE("pdge line6d: the default mappings follow Zhang & Chen 2021's Table 2") {
  const auto x = line6d_default_mapping("X");
  REQUIRE(x.size() == 6);
  // Table 2 (X axis): positioning d_x(x), straightness XX d_y(x), straightness YY d_z(x),
  // angle A (yaw, about Z) -ε_xz, angle B (pitch, about Y) -ε_xy, angle C (roll) ε_xx.
  const std::vector<std::pair<std::string, int>> expected = {
      {"E_XX", 1}, {"E_YX", 1}, {"E_ZX", 1}, {"E_CX", -1}, {"E_BX", -1}, {"E_AX", 1}};
  const std::vector<std::string> columns = {"lin_um",   "str_h_um",   "str_v_um",
                                            "yaw_urad", "pitch_urad", "roll_urad"};
  for (std::size_t i = 0; i < 6; ++i) {
    CHECK(laser_column(x[i].channel) == columns[i]);
    CHECK(x[i].iso == expected[i].first);
    CHECK(x[i].sign == expected[i].second);
    CHECK(x[i].why.rfind("Table 2", 0) == 0);
  }
  // The same rule for Y (H = X, V = Z) and Z (H = X, V = Y).
  const auto y = line6d_default_mapping("Y");
  CHECK(y[1].iso == "E_XY");
  CHECK(y[2].iso == "E_ZY");
  CHECK(y[3].iso == "E_CY");  // yaw about Z
  CHECK(y[4].iso == "E_AY");  // pitch about X
  CHECK(y[5].iso == "E_BY");  // roll about Y
  const auto z = line6d_default_mapping("Z");
  CHECK(z[1].iso == "E_XZ");
  CHECK(z[2].iso == "E_YZ");
  CHECK(z[3].iso == "E_BZ");
  CHECK(z[4].iso == "E_AZ");
  CHECK(z[5].iso == "E_CZ");
  CHECK(y[3].sign == -1);
  CHECK(z[4].sign == -1);
  CHECK(error_of([] { line6d_default_mapping("A"); }) ==
        "axis 'A': 6D line measurements are read for the linear axes X, Y and Z");
  CHECK(line6d_iso_errors("Y") ==
        std::vector<std::string>{"E_XY", "E_YY", "E_ZY", "E_AY", "E_BY", "E_CY"});
}

TEST_CASE("pdge line6d: signs applied per channel") {
  const std::vector<double> x = {0, 100, 200};
  std::map<std::string, std::vector<double>> cols = {
      {"lin_um", {1, 2, 3}},      {"str_h_um", {4, 5, 6}},      {"str_v_um", {7, 8, 9}},
      {"yaw_urad", {10, 11, 12}}, {"pitch_urad", {13, 14, 15}}, {"roll_urad", {16, 17, 18}}};
  Line6dOptions raw;
  raw.remove_straightness_line = false;
  raw.angular = AngularReference::None;
  const Line6dData d = convert_line6d("X", x, cols, line6d_default_mapping("X"), raw);
  CHECK(d.spelling == "laser");
  REQUIRE(d.profiles.size() == 6);
  // Profiles in ISO order E_XX E_YX E_ZX E_AX E_BX E_CX.
  CHECK(d.profiles[0].error == "E_XX");
  CHECK(d.profiles[0].values == std::vector<double>{1, 2, 3});
  CHECK(d.profiles[1].values == std::vector<double>{4, 5, 6});
  CHECK(d.profiles[2].values == std::vector<double>{7, 8, 9});
  CHECK(d.profiles[3].error == "E_AX");  // roll, +
  CHECK(d.profiles[3].values == std::vector<double>{16, 17, 18});
  CHECK(d.profiles[4].error == "E_BX");  // pitch, -
  CHECK(d.profiles[4].values == std::vector<double>{-13, -14, -15});
  CHECK(d.profiles[5].error == "E_CX");  // yaw, -
  CHECK(d.profiles[5].values == std::vector<double>{-10, -11, -12});
  CHECK(d.profiles[5].unit == "urad");
  CHECK(d.profiles[1].kind == ProfileKind::Straightness);
  CHECK(d.profiles[4].kind == ProfileKind::Angular);
  CHECK(d.profiles[0].removed == "none");

  // ISO spelling: no sign change.
  const Line6dData iso =
      convert_line6d("X", x, {{"E_CX_urad", {1, 2, 3}}}, line6d_default_mapping("X"), raw);
  CHECK(iso.spelling == "iso");
  CHECK(iso.profiles.at(0).values == std::vector<double>{1, 2, 3});
  CHECK(iso.profiles.at(0).sign == 1);
}

TEST_CASE("pdge line6d: eq. (1) removes the straightness reference line exactly") {
  const std::vector<double> x = positions();
  const std::vector<double> shape = bow(2.0);
  // The beam's misalignment adds 3 + 0.025 x µm; the shape has no line of its own.
  std::vector<double> measured;
  for (std::size_t i = 0; i < x.size(); ++i) measured.push_back(shape[i] + 3 + 0.025 * x[i]);
  ReferenceLine line;
  const std::vector<double> back = remove_reference_line(x, measured, &line);
  CHECK(line.intercept == doctest::Approx(3).epsilon(1e-12));
  CHECK(line.slope == doctest::Approx(0.025).epsilon(1e-12));
  for (std::size_t i = 0; i < x.size(); ++i) CHECK(std::abs(back[i] - shape[i]) < 1e-12);
  // Idempotent: the result has no line left.
  const ReferenceLine again = least_squares_line(x, back);
  CHECK(std::abs(again.slope) < 1e-15);
  CHECK(std::abs(again.intercept) < 1e-12);
  // NaN rows are ignored and stay NaN.
  std::vector<double> gap = measured;
  gap[7] = NAN;
  const std::vector<double> back_gap = remove_reference_line(x, gap);
  CHECK(std::isnan(back_gap[7]));
  CHECK(error_of([] {
          least_squares_line({5, 5}, {1, 2});
        }) ==
        "reference line: a straightness profile needs values at two distinct positions at least");

  // Through the conversion, with the Table 2 sign: the vertical channel and yaw.
  std::vector<double> yaw;
  for (std::size_t i = 0; i < x.size(); ++i) yaw.push_back(-(shape[i] + 40));  // -E_CX + offset
  const Line6dData d = convert_line6d("X", x, {{"str_v_um", measured}, {"yaw_urad", yaw}},
                                      line6d_default_mapping("X"));
  const Line6dProfile* ezx = d.find("E_ZX");
  REQUIRE(ezx);
  CHECK(ezx->removed == "line");
  CHECK(ezx->reference.slope == doctest::Approx(0.025));
  for (std::size_t i = 0; i < x.size(); ++i) CHECK(std::abs(ezx->values[i] - shape[i]) < 1e-12);
  const Line6dProfile* ecx = d.find("E_CX");
  REQUIRE(ecx);
  CHECK(ecx->removed == "mean");
  CHECK(ecx->reference.intercept == doctest::Approx(40));
  for (std::size_t i = 0; i < x.size(); ++i) CHECK(std::abs(ecx->values[i] - shape[i]) < 1e-12);
  CHECK(d.find("E_XX") == nullptr);
}

TEST_CASE("pdge line6d: the CSV variant") {
  const MeasurementTable t = table(
      "# format: line6d\n"
      "# axis: Y\n"
      "# map: str_h_um=-E_XY\n"
      "Y,cycle,lin_um,str_h_um,pitch_urad\n"
      "0,1,0.5,1,10\n"
      "-100,1,1.5,3,12\n"
      "-200,1,2.5,2,11\n"
      "0,2,0.7,1.2,10.5\n"
      "-100,2,1.7,3.2,12.5\n"
      "-200,2,2.7,2.2,11.5\n");
  CHECK(is_line6d(t));
  const Line6dData d = line6d_from_table(t);
  CHECK(d.axis == "Y");
  CHECK(d.cycle == std::vector<int>{1, 1, 1, 2, 2, 2});
  REQUIRE(d.profiles.size() == 3);
  CHECK(d.profiles[0].error == "E_XY");  // the map override, sign -1
  CHECK(d.profiles[0].sign == -1);
  CHECK(d.profiles[0].removed == "line");
  CHECK(d.profiles[1].error == "E_YY");
  CHECK(d.profiles[1].values[1] == doctest::Approx(1.5));
  CHECK(d.profiles[2].error == "E_AY");  // pitch of Y is about X, sign -1
  CHECK(d.profiles[2].raw[0] == doctest::Approx(-10));
  CHECK(d.profiles[2].values[0] == doctest::Approx(-10 + 11.25));
}

TEST_CASE("pdge line6d: bad files name the problem") {
  CHECK(error_of([] { line6d_from_table(table("# format: line6d\nX,lin_um\n0,1\n")); }) ==
        "m.csv: line6d: the header key '# axis:' is missing (the measured axis, e.g. "
        "'# axis: X')");
  CHECK(error_of(
            [] { line6d_from_table(table("# format: line6d\n# axis: A\nA,roll_urad\n0,1\n")); }) ==
        "m.csv:2: line6d: axis 'A': 6D line measurements are read for the linear axes X, Y "
        "and Z");
  CHECK(error_of([] {
          line6d_from_table(table("# format: line6d\n# axis: X\nX,str_h_um,E_YX_um\n0,1,1\n"));
        }) == "m.csv: line6d: E_YX is given twice, as str_h_um (laser channel) and as E_YX_um");
  CHECK(
      error_of([] { line6d_from_table(table("# format: line6d\n# axis: X\nX,E_XY_um\n0,1\n")); }) ==
      "m.csv:3: line6d: column 'E_XY_um' is an error of axis Y but this file measures "
      "axis X ('# axis: X')");
  CHECK(error_of([] {
          line6d_from_table(table("# format: line6d\n# axis: X\nY,lin_um\n0,1\n"));
        }) == "m.csv:3: line6d: the axis column 'X' (the position along the axis, mm) is missing");
  CHECK(error_of([] {
          line6d_from_table(
              table("# format: line6d\n# axis: X\n# map: yaw_urad=E_XX\nX,lin_um\n0,1\n"));
        }) ==
        "m.csv:3: line6d: map item \"yaw_urad=E_XX\": channel 'yaw_urad' is an angle but "
        "E_XX is a translation");
  CHECK(error_of([] {
          line6d_from_table(
              table("# format: line6d\n# axis: X\n# map: roll_urad=E_CX\nX,lin_um\n0,1\n"));
        }) ==
        "m.csv:3: line6d: map \"roll_urad=E_CX\": two channels go to E_CX (each of the six "
        "errors takes one channel)");
  CHECK(error_of([] {
          line6d_from_table(table("# format: line6d\n# axis: X\nX,str_h_um\n5,1\n5,2\n"));
        }) ==
        "m.csv: line6d: E_YX (str_h_um): reference line: a straightness profile needs "
        "values at two distinct positions at least");
  CHECK(error_of([] {
          line6d_from_table(table("# format: line6d\n# axis: X\nX,cycle\n0,1\n"));
        }).find("line6d: no 6D column") != std::string::npos);
}

TEST_CASE("pdge line6d: the example file and fit-pdge on it") {
  const std::string path = std::string(WEILGEN_SOURCE_DIR) + "/examples/data/line6d_x.csv";
  const Line6dData d = read_line6d(path);
  CHECK(d.axis == "X");
  CHECK(d.spelling == "laser");
  CHECK(d.position.size() == 255);
  CHECK(d.cycle.size() == 255);
  REQUIRE(d.profiles.size() == 6);
  // The generator's beam misalignment (2.0 + 0.030 x µm horizontally) comes back as the line,
  // within what the bow and the noise leave in it.
  const Line6dProfile* eyx = d.find("E_YX");
  REQUIRE(eyx);
  CHECK(eyx->reference.slope == doctest::Approx(0.030).epsilon(0.02));
  // Yaw was written as -E_CX + 25 with E_CX = 5 s + ...: after conversion E_CX rises with x.
  const Line6dProfile* ecx = d.find("E_CX");
  REQUIRE(ecx);
  CHECK(ecx->sign == -1);
  CHECK(ecx->values[50] - ecx->values[0] > 8);

  // Zhang & Chen 2021's finding on its wave-shaped positioning error: a Fourier series fits it
  // better than a polynomial with about as many coefficients (here by held-out error too).
  const Line6dProfile* exx = d.find("E_XX");
  REQUIRE(exx);
  const PdgeFitResult f3 =
      PdgeFit().run(d.position, exx->values, d.cycle, parse_basis("fourier:3"), 0, 500);
  const PdgeFitResult p7 =
      PdgeFit().run(d.position, exx->values, d.cycle, parse_basis("poly:7"), 0, 500);
  CHECK(f3.fit.metrics.e_max < p7.fit.metrics.e_max);
  CHECK(f3.fit.metrics.rmse < p7.fit.metrics.rmse);
  CHECK(f3.cv.rmse < p7.cv.rmse);

  // The CLI: Table 4 on stdout, JSON.
  const auto dir = test::fresh_dir("fit_pdge_cli");
  const std::string json_path = (dir / "fit.json").string();
  const test::Run r =
      test::run(test::cli("fit-pdge " + path + " --column E_XX,E_BX --json " + json_path));
  REQUIRE(r.status == 0);
  CHECK(r.out.find("E_XX (um, 255 values; from lin_um x +1, removed none)") != std::string::npos);
  CHECK(r.out.find("fourier:auto") != std::string::npos);
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  CHECK(j["verb"] == "fit-pdge");
  CHECK(j["format"] == "line6d");
  REQUIRE(j["profiles"].size() == 2);
  CHECK(j["profiles"][1]["name"] == "E_BX");
  CHECK(j["profiles"][1]["conversion"]["sign"] == -1);
  CHECK(j["profiles"][0]["fits"].size() == 4);
  CHECK(j["profiles"][0]["fits"][0]["cv_curve"].size() == 11);
  CHECK(j["profiles"][0]["fits"][0]["power_coefficients"].size() ==
        j["profiles"][0]["fits"][0]["order"].get<std::size_t>() + 1);
  CHECK(j["profiles"][0]["fits"][1]["period_mm"] == 500.0);
  CHECK(j["profiles"][0]["fits"][1]["metrics"]["cv_rmse"].get<double>() <
        j["profiles"][0]["fits"][0]["metrics"]["cv_rmse"].get<double>());  // Fourier wins
  if (gnuplot_available()) {
    const std::string png = (dir / "fit.png").string();
    const test::Run p = test::run(test::cli("fit-pdge " + path + " --column E_YX --plot " + png));
    CHECK(p.status == 0);
    std::ifstream f(png, std::ios::binary);
    char magic[4] = {};
    f.read(magic, 4);
    CHECK(std::string(magic + 1, 3) == "PNG");
  }

  const test::Run bad = test::run(test::cli("fit-pdge " + path + " --basis spline:3"));
  CHECK(bad.status == 2);
  CHECK(bad.out.find("--basis: basis \"spline:3\": unknown kind \"spline\"") != std::string::npos);
  const test::Run high = test::run(test::cli("fit-pdge " + path + " --basis poly:60"));
  CHECK(high.status == 1);
  CHECK(high.out.find("poly:60 has 61 coefficients but the data has 51 distinct positions") !=
        std::string::npos);
}
