// Study inputs: units and quantities, poses (--at, --grid), output tolerances (--tolerance),
// error distributions (machine file, tolerance files, --set) and the tolerance-file writer.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "test_support.hpp"
#include "weilgen/analysis/study_spec.hpp"
#include "weilgen/analysis/tolerance_file.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/machine/yaml_loader.hpp"

using namespace weilgen;
namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;

const Description& grinder() {
  static const Description d = load_machine_file(test::machine_path("gantry_grinder"));
  return d;
}

const Description& five_axis() {
  static const Description d = load_machine_file(test::machine_path("five_axis_ac"));
  return d;
}

// The message of the std::invalid_argument (or InputError) `f` throws.
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no error)";
}

void expect_words(const std::string& message, const std::vector<std::string>& words) {
  INFO("message: " << message);
  for (const std::string& w : words) {
    INFO("expected: " << w);
    CHECK(message.find(w) != std::string::npos);
  }
}

std::size_t index_of(const std::vector<std::string>& v, const std::string& s) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (v[i] == s) return i;
  }
  FAIL("no " << s);
  return 0;
}

std::size_t error_index(const Description& d, const std::string& name) {
  const int i = d.error_index(name);
  REQUIRE(i >= 0);
  return static_cast<std::size_t>(i);
}

std::string tmp_dir(const std::string& name) {
  const fs::path p = fs::path(WEILGEN_TEST_TMP) / "study_spec" / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

std::string write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// Equal to within a relative 1e-14 (unit conversions round).
bool close(double x, double y) {
  return x == y || std::abs(x - y) <= 1e-14 * std::max(std::abs(x), std::abs(y));
}

void check_same(const InputDistribution& a, const InputDistribution& b) {
  INFO(a.str() << " vs " << b.str());
  CHECK(a.kind() == b.kind());
  CHECK(close(a.a(), b.a()));
  CHECK(close(a.b(), b.b()));
  if (a.kind() != InputDistribution::Kind::Normal) {
    CHECK(close(a.lo(), b.lo()));
    CHECK(close(a.hi(), b.hi()));
  }
}

// Tolerance-file errors: "tol.yaml:line:col: ..." with every word.
void expect_file_error(const std::string& yaml, const std::string& where,
                       const std::vector<std::string>& words) {
  const std::string message = error_of([&] { read_tolerance_text(yaml, "tol.yaml", grinder()); });
  INFO("message: " << message);
  CHECK(message.rfind(where + ": ", 0) == 0);
  expect_words(message, words);
}

}  // namespace

// ---- Units and quantities ---------------------------------------------------------------------

TEST_CASE("study units: every unit") {
  struct Case {
    const char* unit;
    double to_base;
    bool angle;
  };
  const std::vector<Case> cases = {
      {"mm", 1, false},     {"um", 1e-3, false},      {"µm", 1e-3, false},
      {"μm", 1e-3, false},  {"nm", 1e-6, false},      {"m", 1e3, false},
      {"rad", 1, true},     {"mrad", 1e-3, true},     {"urad", 1e-6, true},
      {"µrad", 1e-6, true}, {"deg", kPi / 180, true}, {"arcsec", kPi / 648000, true},
      {"mm/m", 1e-3, true}, {"um/m", 1e-6, true},     {"µm/m", 1e-6, true},
      {"inch", 25.4, false}};
  for (const Case& c : cases) {
    INFO(c.unit);
    const UnitFactor u = parse_unit(c.unit);
    CHECK(u.to_base == c.to_base);
    CHECK(u.angle == c.angle);
  }
  for (const char* bad : {"", "MM", "in", "mm/", "um/mm", "µ", "u"}) {
    INFO(bad);
    expect_words(error_of([&] { parse_unit(bad); }),
                 {"unknown unit", "lengths: mm, um, µm, nm, m", "arcsec", "mm/m"});
  }
}

TEST_CASE("study units: quantities") {
  CHECK(parse_quantity("0.03mm", "mm", "t") == 0.03);
  CHECK(parse_quantity("30 um", "mm", "t") == doctest::Approx(0.03).epsilon(1e-15));
  CHECK(parse_quantity("30µm", "mm", "t") == doctest::Approx(0.03).epsilon(1e-15));
  CHECK(parse_quantity("2 nm", "mm", "t") == doctest::Approx(2e-6).epsilon(1e-15));
  CHECK(parse_quantity("1.5m", "mm", "t") == 1500);
  CHECK(parse_quantity("0.05/6", "mm", "t") == 0.05 / 6);
  CHECK(parse_quantity("0.05/6 mm", "um", "t") == 0.05 / 6);
  CHECK(parse_quantity("0.05/6", "um", "t") == doctest::Approx(0.05 / 6 * 1e-3).epsilon(1e-15));
  CHECK(parse_quantity("(1 + 2)*3um", "mm", "t") == doctest::Approx(9e-3).epsilon(1e-15));
  CHECK(parse_quantity("1e-3", "rad", "t") == 1e-3);
  CHECK(parse_quantity("2E3nm", "mm", "t") == doctest::Approx(2e-3).epsilon(1e-15));
  CHECK(parse_quantity("-5urad", "rad", "t") == doctest::Approx(-5e-6).epsilon(1e-15));
  CHECK(parse_quantity("90deg", "rad", "t") == doctest::Approx(kPi / 2).epsilon(1e-15));
  CHECK(parse_quantity("3600 arcsec", "rad", "t") == doctest::Approx(kPi / 180).epsilon(1e-15));
  CHECK(parse_quantity("20mm/m", "rad", "t") == doctest::Approx(0.02).epsilon(1e-15));
  CHECK(parse_quantity("7 um/m", "rad", "t") == doctest::Approx(7e-6).epsilon(1e-15));
  CHECK(parse_quantity("2*pi", "rad", "t") == doctest::Approx(2 * kPi).epsilon(1e-15));
  CHECK(parse_quantity("pi/2 rad", "deg", "t") == doctest::Approx(kPi / 2).epsilon(1e-15));
  CHECK(parse_quantity("pi", "rad", "t") == doctest::Approx(kPi).epsilon(1e-15));
  CHECK(parse_quantity("  4  ", "mm", "t") == 4);

  const Quantity q = parse_quantity_unit("30um", "mm", "t");
  CHECK(q.number == 30);
  CHECK(q.unit_given);
  CHECK(q.unit_name == "um");
  CHECK(q.in(parse_unit("um")) == 30);  // exact in its own unit
  const Quantity d = parse_quantity_unit("90", "deg", "t");
  CHECK_FALSE(d.unit_given);
  CHECK(d.unit_name == "deg");
  CHECK(d.in(parse_unit("deg")) == 90);

  // Bad text: one line, the context first, the text quoted.
  expect_words(error_of([] { parse_quantity("", "mm", "--tolerance: \"dx=\""); }),
               {"--tolerance: \"dx=\": empty value"});
  expect_words(error_of([] { parse_quantity("  ", "mm", "ctx"); }), {"ctx: empty value"});
  expect_words(error_of([] { parse_quantity("0.03xx", "mm", "ctx"); }),
               {"ctx: unknown unit \"xx\"", "in \"0.03xx\"", "lengths: mm"});
  expect_words(error_of([] { parse_quantity("5 furlongs", "mm", "ctx"); }),
               {"unknown unit \"furlongs\""});
  expect_words(error_of([] { parse_quantity("nan", "mm", "ctx"); }),
               {"ctx: \"nan\" is not a number (NaN)"});
  expect_words(error_of([] { parse_quantity("NaN mm", "mm", "ctx"); }), {"not a number (NaN)"});
  expect_words(error_of([] { parse_quantity("inf", "mm", "ctx"); }),
               {"ctx: \"inf\" is not a finite number"});
  expect_words(error_of([] { parse_quantity("-Infinity um", "mm", "ctx"); }),
               {"not a finite number"});
  expect_words(error_of([] { parse_quantity("1e999", "mm", "ctx"); }), {"ctx: \"1e999\""});
  expect_words(error_of([] { parse_quantity("1/0", "mm", "ctx"); }), {"not a finite number"});
  expect_words(error_of([] { parse_quantity("mm", "mm", "ctx"); }),
               {"ctx: \"mm\" has no number before the unit"});
  expect_words(error_of([] { parse_quantity("1+", "mm", "ctx"); }),
               {"ctx: \"1+\" is not a number or expression"});
  expect_words(error_of([] { parse_quantity("x*2", "mm", "ctx"); }), {"unknown name \"x\""});
  expect_words(error_of([] { parse_quantity("5", "", "ctx"); }), {"ctx: \"5\" needs a unit"});
  CHECK(parse_quantity("5um", "", "ctx") == doctest::Approx(5e-3).epsilon(1e-15));
}

// ---- Poses ------------------------------------------------------------------------------------

TEST_CASE("study poses: Wang & Yuan 2021's grid on the gantry grinder") {
  const Description& d = grinder();
  const PoseSet p = parse_poses(d, {}, {"X=0,Y=-1500:1500:5,Z=600:1400:5"});
  REQUIRE(p.axes == std::vector<std::string>{"X", "Z", "Y"});  // Description::axes() order
  CHECK(p.units == std::vector<std::string>{"mm", "mm", "mm"});
  REQUIRE(p.poses.size() == 25);
  CHECK(p.grid_size() == 25);
  // Written order X, Y, Z with X fixed: Y is the outer loop, Z (written last) the fastest.
  REQUIRE(p.grid_axes == std::vector<std::size_t>{2, 1});
  CHECK(p.grid_values[0] == std::vector<double>{-1500, -750, 0, 750, 1500});
  CHECK(p.grid_values[1] == std::vector<double>{600, 800, 1000, 1200, 1400});
  const std::vector<double> ys = {-1500, -750, 0, 750, 1500};
  const std::vector<double> zs = {600, 800, 1000, 1200, 1400};
  for (std::size_t iy = 0; iy < 5; ++iy) {
    for (std::size_t iz = 0; iz < 5; ++iz) {
      INFO("iy " << iy << " iz " << iz);
      CHECK(p.poses[iy * 5 + iz] == std::vector<double>{0, zs[iz], ys[iy]});
    }
  }
  CHECK(p.poses.front() == std::vector<double>{0, 600, -1500});
  CHECK(p.poses[1] == std::vector<double>{0, 800, -1500});
  CHECK(p.poses.back() == std::vector<double>{0, 1400, 1500});
}

TEST_CASE("study poses: --at, units, defaults, grid then at") {
  const Description& d = grinder();
  const PoseSet a = parse_poses(d, {"X=0,Y=1500,Z=600", " Z = 1.2m , X=500 , Y=-1.5m "}, {});
  REQUIRE(a.poses.size() == 2);
  CHECK(a.poses[0] == std::vector<double>{0, 600, 1500});
  CHECK(a.poses[1] == std::vector<double>{500, 1200, -1500});
  CHECK(a.grid_axes.empty());
  CHECK(a.grid_size() == 0);
  // --at names every axis: a missing one is an error naming it (--grid still takes 0 for one).
  expect_words(
      error_of([&] { parse_poses(d, {"Z=700"}, {}); }),
      {"--at: \"Z=700\": axes X, Y are not given", "--at names every axis", "add e.g. X=0,Y=0"});
  expect_words(error_of([&] { parse_poses(d, {"X=1"}, {}); }),
               {"--at: \"X=1\": axes Z, Y are not given"});
  expect_words(error_of([&] { parse_poses(d, {}, {"X=0:1000:3"}); }),
               {"--grid: \"X=0:1000:3\": axis Z is not given"});
  // Grid poses first, then --at; a count of 1 is the start; a one-value axis is no grid axis.
  const PoseSet c = parse_poses(d, {"X=10,Z=700,Y=5"}, {"Z=600:1400:1,X=0:1000:3"});
  REQUIRE(c.poses.size() == 4);
  CHECK(c.grid_axes == std::vector<std::size_t>{0});
  CHECK(c.grid_values[0] == std::vector<double>{0, 500, 1000});
  CHECK(c.poses[0] == std::vector<double>{0, 600, 0});
  CHECK(c.poses[1] == std::vector<double>{500, 600, 0});
  CHECK(c.poses[2] == std::vector<double>{1000, 600, 0});
  CHECK(c.poses[3] == std::vector<double>{10, 700, 5});
  // Descending ranges and units in the grid.
  const PoseSet e = parse_poses(d, {}, {"Z=1.4m:600mm:3"});
  CHECK(e.grid_values[0] == std::vector<double>{1400, 1000, 600});
}

TEST_CASE("study poses: bad flags") {
  const Description& d = grinder();
  const auto err = [&](std::vector<std::string> at, std::vector<std::string> grid) {
    return error_of([&] { parse_poses(d, at, grid); });
  };
  expect_words(err({}, {}), {"no poses: give --grid and/or --at", "X [0, 1000] mm"});
  expect_words(err({}, {"X=0:1000:0,Z=600"}), {"--grid: \"X=0:1000:0,Z=600\": count must be >= 1"});
  expect_words(err({}, {"X=0:1000:-2,Z=600"}), {"count must be >= 1, got -2"});
  expect_words(err({}, {"X=0:1000:2.5,Z=600"}), {"count must be a whole number >= 1, got \"2.5\""});
  expect_words(err({}, {"X=0:1000,Z=600"}),
               {"--grid: \"X=0:1000,Z=600\": X=0:1000 is neither a value nor start:stop:count"});
  expect_words(err({}, {"X=0:1:2:3,Z=600"}), {"neither a value nor start:stop:count"});
  expect_words(err({}, {"Q=0:1:2,Z=600"}), {"--grid: \"Q=0:1:2,Z=600\": unknown axis \"Q\"",
                                            "machine gantry_grinder has axes X, Z, Y"});
  expect_words(err({"X=0,Z=600,X=5"}, {}), {"--at: \"X=0,Z=600,X=5\": axis X is given twice"});
  expect_words(err({}, {"Z=600,Z=700"}), {"axis Z is given twice"});
  expect_words(err({"X0,Z=600"}, {}),
               {"--at: \"X0,Z=600\": \"X0\" is not AXIS=value", "X=0,Y=1500,Z=600"});
  expect_words(err({"X=0,,Z=600"}, {}), {"empty item"});
  expect_words(err({""}, {}), {"--at: \"\": empty"});
  expect_words(err({"X=,Z=600"}, {}), {"--at: \"X=,Z=600\": empty value"});
  expect_words(err({"X=abc,Z=600"}, {}), {"unknown unit \"abc\""});
  expect_words(err({"X=1000.5,Z=600"}, {}),
               {"X = 1000.5 mm is outside the axis range [0, 1000] mm"});
  expect_words(err({"X=2m,Z=600"}, {}), {"X = 2000 mm is outside the axis range"});
  expect_words(err({}, {"Z=0:1400:3"}), {"Z = 0 mm is outside the axis range [600, 1400] mm"});
  expect_words(err({"X=5deg,Z=600"}, {}),
               {"axis X is a length in mm, but \"deg\" is an angle unit"});
  expect_words(err({"X=0:1:2,Z=600"}, {}), {"ranges (start:stop:count) go in --grid"});
  expect_words(err({}, {"X=0,Z=600", "X=1,Z=700"}), {"--grid: given 2 times"});
  expect_words(err({}, {"X=0:1000:10000,Y=-1500:1500:10000,Z=600"}), {"more than 10000000 poses"});
  // Endpoints within rounding of the range are accepted.
  CHECK(parse_poses(d, {"X=1000,Z=1400,Y=-1500"}, {}).poses[0] ==
        std::vector<double>{1000, 1400, -1500});
}

TEST_CASE("study poses: degree axes of the five-axis machine") {
  const Description& d = five_axis();
  const PoseSet p = parse_poses(d, {"X=0,Y=0,Z=0,A=90,C=0.5rad", "X=0,Y=0,Z=0,A=-1.5708rad,C=-360"},
                                {"A=-90:90:3"});
  const std::size_t ia = index_of(p.axes, "A"), ic = index_of(p.axes, "C");
  CHECK(p.units[ia] == "deg");
  CHECK(p.units[ic] == "deg");
  CHECK(p.units[index_of(p.axes, "X")] == "mm");
  REQUIRE(p.poses.size() == 5);
  CHECK(p.grid_axes == std::vector<std::size_t>{ia});
  CHECK(p.poses[0][ia] == -90);
  CHECK(p.poses[1][ia] == 0);
  CHECK(p.poses[2][ia] == 90);
  CHECK(p.poses[0][ic] == 0);
  CHECK(p.poses[3][ia] == 90);  // no unit: the axis unit, exact
  CHECK(p.poses[3][ic] == doctest::Approx(0.5 * 180 / kPi).epsilon(1e-14));
  CHECK(p.poses[4][ia] == doctest::Approx(-1.5708 * 180 / kPi).epsilon(1e-14));
  CHECK(p.poses[4][ic] == -360);
  for (std::size_t k = 0; k < 5; ++k) {
    for (const char* axis : {"X", "Y", "Z"}) CHECK(p.poses[k][index_of(p.axes, axis)] == 0);
  }
  expect_words(error_of([&] { parse_poses(d, {"A=5mm"}, {}); }),
               {"--at: \"A=5mm\": axis A is an angle in deg, but \"mm\" is a length unit"});
  expect_words(error_of([&] { parse_poses(d, {"A=120"}, {}); }),
               {"A = 120 deg is outside the axis range [-110, 110] deg"});
  expect_words(error_of([&] { parse_poses(d, {"A=3rad"}, {}); }), {"outside the axis range"});
}

// ---- Outputs and tolerances -------------------------------------------------------------------

TEST_CASE("study outputs: names and units") {
  CHECK(all_outputs().size() == kNumOutputs);
  for (OutputId id : all_outputs()) CHECK(parse_output(output_name(id)) == id);
  CHECK(parse_output("DP") == OutputId::Dp);
  CHECK(std::string(output_unit(OutputId::Dx)) == "mm");
  CHECK(std::string(output_unit(OutputId::Dp)) == "mm");
  CHECK(std::string(output_unit(OutputId::Db)) == "rad");
  expect_words(error_of([] { parse_output("dq"); }),
               {"unknown output \"dq\" (expected dx, dy, dz, da, db, dc, dp)"});
}

TEST_CASE("study tolerances: --tolerance") {
  const std::vector<OutputTolerance> t = parse_tolerances(
      {"dx=0.03mm,dy=30um", "dz=0.02", "dp = 50 µm", "da=20urad,db=0.01mm/m", "dc=2arcsec"});
  REQUIRE(t.size() == 7);
  CHECK(t[0].output == OutputId::Dx);
  CHECK(t[0].value == 0.03);
  CHECK(t[0].text == "0.03mm");
  CHECK(t[1].output == OutputId::Dy);
  CHECK(t[1].value == doctest::Approx(0.03).epsilon(1e-15));
  CHECK(t[2].value == 0.02);  // default mm
  CHECK(t[3].output == OutputId::Dp);
  CHECK(t[3].value == doctest::Approx(0.05).epsilon(1e-15));
  CHECK(t[3].text == "50 µm");
  CHECK(t[4].value == doctest::Approx(20e-6).epsilon(1e-15));
  CHECK(t[5].value == doctest::Approx(1e-5).epsilon(1e-15));
  CHECK(t[6].value == doctest::Approx(2 * kPi / 648000).epsilon(1e-15));
  CHECK(parse_tolerances({"da=1e-5"})[0].value == 1e-5);  // default rad
  CHECK(parse_tolerances({}).empty());

  const auto err = [](const std::string& flag) {
    return error_of([&] { parse_tolerances({flag}); });
  };
  expect_words(err("dx=5urad"),
               {"--tolerance: \"dx=5urad\": dx is a position (mm) and needs a length unit, got "
                "\"urad\""});
  expect_words(err("da=5um"), {"da is an orientation (rad) and needs an angle unit, got \"um\""});
  expect_words(err("dx=0"), {"--tolerance: \"dx=0\": a tolerance must be > 0, got 0"});
  expect_words(err("dy=-1um"), {"a tolerance must be > 0, got -1um"});
  expect_words(err("dq=1"), {"--tolerance: \"dq=1\": unknown output \"dq\""});
  expect_words(err("dx"), {"\"dx\" is not OUTPUT=value"});
  expect_words(err("dx=1,,dy=2"), {"empty item"});
  expect_words(err(""), {"--tolerance: \"\": empty"});
  expect_words(err("dx=1mm,dx=2mm"), {"dx is given twice (1mm and 2mm)"});
  expect_words(err("dx=nan"), {"not a number (NaN)"});
  expect_words(err("dx=0.03xx"), {"unknown unit \"xx\""});
}

// ---- Error distributions ----------------------------------------------------------------------

TEST_CASE("study distributions: the machine file's, in base units") {
  const Description& d = grinder();
  const std::vector<InputDistribution> dist = error_distributions(d, {}, {});
  REQUIRE(dist.size() == 21);
  const InputDistribution& bx = dist[error_index(d, "E_BX")];
  CHECK(bx.kind() == InputDistribution::Kind::Normal);
  CHECK(bx.mean() == 0);
  CHECK(bx.stddev() == 0.06 / 6000);
  CHECK(dist[error_index(d, "E_XX")].stddev() == 0.05 / 6);
  CHECK(dist[error_index(d, "E_C0X")].stddev() == 0.03 / 3000);
  for (std::size_t i = 0; i < d.errors.size(); ++i) {
    INFO(d.errors[i].name);
    CHECK(dist[i].stddev() == d.errors[i].distribution.b * d.errors[i].to_base);
  }
  CHECK(error_to_base(d.errors[0]) == 1);
  // Five-axis: group defaults in um / urad become mm / rad.
  const Description& f = five_axis();
  const std::vector<InputDistribution> fd = error_distributions(f, {}, {});
  CHECK(fd[error_index(f, "E_XX")].stddev() == doctest::Approx(3e-3).epsilon(1e-15));
  CHECK(fd[error_index(f, "E_AA")].stddev() == doctest::Approx(5e-6).epsilon(1e-15));
  CHECK(fd[error_index(f, "E_XY")].stddev() == doctest::Approx(2e-3).epsilon(1e-15));
  CHECK(error_to_base(f.errors[error_index(f, "E_XX")]) == 1e-3);  // unit um
  // An error without a distribution (a hand-built description) needs an override.
  Description g = grinder();
  g.errors[error_index(g, "E_YX")].distribution = Distribution{};
  g.errors[error_index(g, "E_ZX")].distribution = Distribution{};
  expect_words(error_of([&] { error_distributions(g, {}, {}); }),
               {"E_YX, E_ZX have no distribution: give one in the machine file, a tolerance "
                "file or --set"});
  CHECK(error_distributions(g, {}, {"E_YX=sigma:1um", "E_ZX=sigma:1um"}).size() == 21);
}

TEST_CASE("study distributions: --set") {
  const Description& d = grinder();
  const std::vector<InputDistribution> s = error_distributions(
      d, {},
      {"E_XX=sigma:5um", "E_YX=normal:0.001,0.005mm", "E_ZX=uniform:-10,10um",
       "E_AX=truncnormal:0,5,-10,10urad", "E_BX=const:2urad", "δxz=sigma:3",
       "group:squareness=uniform:-1,1mm/m", "E_XY=normal:1um,0.002", "E_YY=sigma:0.05/6"});
  const auto at = [&](const char* n) { return s[error_index(d, n)]; };
  check_same(at("E_XX"), InputDistribution::normal(0, 0.005));
  check_same(at("E_YX"), InputDistribution::normal(0.001, 0.005));
  check_same(at("E_ZX"), InputDistribution::uniform(-0.01, 0.01));
  check_same(at("E_AX"), InputDistribution::truncated_normal(0, 5e-6, -1e-5, 1e-5));
  check_same(at("E_BX"), InputDistribution::normal(2e-6, 0));
  CHECK(at("E_BX").is_constant());
  check_same(at("E_XZ"), InputDistribution::normal(0, 3));  // alias; unit of E_XZ (mm)
  for (const char* sq : {"E_C0X", "E_B0Z", "E_A0Z"}) {
    check_same(at(sq), InputDistribution::uniform(-1e-3, 1e-3));
  }
  // The last number's unit applies to the numbers without one: 1um and 0.002 (mm).
  check_same(at("E_XY"), InputDistribution::normal(0.001, 0.002));
  check_same(at("E_YY"), InputDistribution::normal(0, 0.05 / 6));
  // Untouched errors keep the machine file's.
  check_same(at("E_CX"), InputDistribution::normal(0, 0.05 / 6000));
  // Later flags override earlier ones.
  const auto later = error_distributions(d, {}, {"group:positioning=sigma:1um", "E_XX=sigma:2um"});
  CHECK(later[error_index(d, "E_XX")].stddev() == doctest::Approx(2e-3).epsilon(1e-15));
  CHECK(later[error_index(d, "E_YY")].stddev() == doctest::Approx(1e-3).epsilon(1e-15));

  const auto err = [&](const std::string& flag) {
    return error_of([&] { error_distributions(d, {}, {flag}); });
  };
  expect_words(err("E_QQ=sigma:1um"),
               {"--set: \"E_QQ=sigma:1um\": unknown error \"E_QQ\" (machine gantry_grinder has "
                "E_XX, E_YX, E_ZX, E_AX"});
  expect_words(err("group:thermal=sigma:1um"),
               {"no errors in group \"thermal\"", "positioning, straightness, angular"});
  expect_words(err("E_XX=sigma:1urad"),
               {"--set: \"E_XX=sigma:1urad\": unit \"urad\" is an angle but error E_XX is a "
                "translation"});
  expect_words(err("E_AX=sigma:1um"), {"unit \"um\" is a length but error E_AX is a rotation"});
  expect_words(err("group:angular=sigma:1um"), {"is a length but error", "is a rotation"});
  expect_words(err("E_XX=sigma:0"), {"sigma must be > 0, got 0", "const:VALUE"});
  expect_words(err("E_XX=normal:0,-1um"), {"sigma must be > 0, got -1um"});
  expect_words(err("E_XX=uniform:1,-1um"), {"lo (1) must be less than hi (-1um)"});
  expect_words(err("E_XX=truncnormal:0,1,2,1um"), {"lo (2) must be less than hi (1um)"});
  expect_words(err("E_XX=truncnormal:100,1,0,1um"), {"invalid distribution"});
  expect_words(err("E_XX=normal:1um"), {"normal takes 2 numbers (mean,sigma), got 1"});
  expect_words(err("E_XX=truncnormal:0,1,2"), {"truncnormal takes 4 numbers"});
  expect_words(err("E_XX=sigma:1,2"), {"sigma takes 1 number (sigma), got 2"});
  expect_words(err("E_XX=gauss:1"),
               {"unknown distribution \"gauss\" (expected sigma, normal, uniform, truncnormal, "
                "const)"});
  expect_words(err("E_XX=5um"), {"expected KIND:VALUES"});
  expect_words(err("E_XX"), {"--set: \"E_XX\": expected NAME=KIND:VALUES"});
  expect_words(err("E_XX=sigma:"), {"empty value"});
  expect_words(err("E_XX=sigma:inf"), {"not a finite number"});
  expect_words(err("E_XX=sigma:1xx"), {"unknown unit \"xx\""});
}

TEST_CASE("study distributions: a sign -1 alias negates") {
  const std::string yaml = R"(weilgen: 1
name: signs
bodies:
  bed: {}
  x:
    parent: bed
    joint: {type: prismatic, axis: x, coordinate: X, range: [0, 100]}
    errors:
      E_XX: {aliases: [{name: dxx, sign: -1}], sigma: 1, unit: um}
      E_YX: {sigma: 1, unit: um}
tool: {body: x}
workpiece: {body: bed}
)";
  const Description d = load_machine_text(yaml, "signs.yaml");
  auto s = error_distributions(d, {}, {"dxx=normal:1,2um", "E_YX=uniform:1,3um"});
  check_same(s[0], InputDistribution::normal(-1e-3, 2e-3));
  s = error_distributions(d, {}, {"dxx=uniform:1,3um"});
  check_same(s[0], InputDistribution::uniform(-3e-3, -1e-3));
  s = error_distributions(d, {}, {"dxx=truncnormal:1,2,0,3um"});
  check_same(s[0], InputDistribution::truncated_normal(-1e-3, 2e-3, -3e-3, 0));
  s = error_distributions(d, {}, {"dxx=const:4um"});
  check_same(s[0], InputDistribution::normal(-4e-3, 0));
  const auto o = read_tolerance_text(
      "weilgen_tolerances: 1\nerrors:\n  dxx: {uniform: [1, 3], unit: um}\n", "t.yaml", d);
  check_same(*o[0], InputDistribution::uniform(-3e-3, -1e-3));
  CHECK_FALSE(o[1].has_value());
}

// ---- Tolerance files --------------------------------------------------------------------------

TEST_CASE("tolerance files: overrides") {
  const Description& d = grinder();
  const std::string yaml = R"(# a study's tolerances
weilgen_tolerances: 1
machine: gantry_grinder
groups:
  straightness: {sigma: 2, unit: um}
  squareness: {uniform: [-0.01, 0.01], unit: mm/m}
errors:
  E_XX: {sigma: 0.005, unit: mm}
  εyx: {normal: [0, 1], unit: urad}
  E_YX: {truncnormal: [0, 0.05/6, -0.01, 0.01]}
  E_CX: {const: 3, unit: urad}
  E_AX: {uniform: [-1, 1], unit: arcsec}
)";
  const ToleranceOverrides o = read_tolerance_text(yaml, "tol.yaml", d);
  REQUIRE(o.size() == 21);
  const auto at = [&](const char* n) -> const std::optional<InputDistribution>& {
    return o[error_index(d, n)];
  };
  check_same(*at("E_XX"), InputDistribution::normal(0, 0.005));
  check_same(*at("E_BX"), InputDistribution::normal(0, 1e-6));  // alias εyx
  // No unit: the error's declared unit (mm); errors entries override the group (straightness).
  check_same(*at("E_YX"), InputDistribution::truncated_normal(0, 0.05 / 6, -0.01, 0.01));
  check_same(*at("E_CX"), InputDistribution::normal(3e-6, 0));
  check_same(*at("E_AX"), InputDistribution::uniform(-kPi / 648000, kPi / 648000));
  for (const char* n : {"E_ZX", "E_XZ", "E_YZ", "E_XY", "E_ZY"}) {
    INFO(n);
    check_same(*at(n), InputDistribution::normal(0, 2e-3));
  }
  for (const char* n : {"E_C0X", "E_B0Z", "E_A0Z"}) {
    check_same(*at(n), InputDistribution::uniform(-1e-5, 1e-5));
  }
  CHECK_FALSE(at("E_ZZ").has_value());
  CHECK_FALSE(at("E_CY").has_value());

  // Through error_distributions: files in order, then --set.
  const std::string dir = tmp_dir("overrides");
  const std::string f1 = write_text(dir + "/a.yaml", yaml);
  const std::string f2 =
      write_text(dir + "/b.yaml", "weilgen_tolerances: 1\nerrors: {E_XX: {sigma: 7, unit: um}}\n");
  const auto s = error_distributions(d, {f1, f2}, {"E_BX=sigma:4urad"});
  check_same(s[error_index(d, "E_XX")], InputDistribution::normal(0, 7e-3));
  check_same(s[error_index(d, "E_BX")], InputDistribution::normal(0, 4e-6));
  check_same(s[error_index(d, "E_ZX")], InputDistribution::normal(0, 2e-3));
  check_same(s[error_index(d, "E_ZZ")], InputDistribution::normal(0, 0.05 / 6));
  expect_words(error_of([&] { error_distributions(d, {dir + "/missing.yaml"}, {}); }),
               {dir + "/missing.yaml: cannot read the tolerance file"});
  // An empty errors/groups section is allowed.
  const auto empty = read_tolerance_text("weilgen_tolerances: 1\nerrors:\n", "t.yaml", d);
  for (const auto& e : empty) CHECK_FALSE(e.has_value());
}

TEST_CASE("tolerance files: bad input names file:line:column") {
  expect_file_error("[1, 2]\n", "tol.yaml:1:1", {"a tolerance file is a YAML mapping"});
  expect_file_error("machine: gantry_grinder\n", "tol.yaml:1:1",
                    {"missing required key 'weilgen_tolerances'"});
  expect_file_error("weilgen_tolerances: 2\n", "tol.yaml:1:21",
                    {"weilgen_tolerances: unsupported format version '2'"});
  expect_file_error("weilgen_tolerances: 1\nmachine: vmc_3axis\n", "tol.yaml:2:10",
                    {"machine: this file is for machine 'vmc_3axis', not 'gantry_grinder'"});
  expect_file_error("weilgen_tolerances: 1\nerror:\n  E_XX: {sigma: 1}\n", "tol.yaml:2:1",
                    {"unknown key 'error' (allowed: weilgen_tolerances, machine, groups, errors)"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: {sigma: 1}\n  E_QQ: {sigma: 1}\n",
                    "tol.yaml:4:3",
                    {"errors: unknown error 'E_QQ' (machine gantry_grinder has E_XX, E_YX"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: {sigma: 1}\n  δxx: {sigma: 2}\n",
                    "tol.yaml:4:3", {"error E_XX is given twice: as 'E_XX' (line 3) and as 'δxx'"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: {sigma: 1}\n  E_XX: {sigma: 2}\n",
                    "tol.yaml:4:3", {"duplicate key 'E_XX' (first at line 3)"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: {sigma: 1, mean: 0}\n",
                    "tol.yaml:3:20",
                    {"errors.E_XX: unknown key 'mean' (allowed: sigma, normal, uniform, "
                     "truncnormal, const, unit)"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: {unit: um}\n", "tol.yaml:3:9",
                    {"errors.E_XX: give a distribution (sigma, normal, uniform, truncnormal or "
                     "const)"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: 5\n", "tol.yaml:3:9",
                    {"errors.E_XX: expected a distribution such as {sigma: 2, unit: um}"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX:\n", "tol.yaml:3:3",
                    {"errors.E_XX: expected a distribution"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: {sigma: -1}\n", "tol.yaml:3:17",
                    {"errors.E_XX.sigma: sigma must be positive, got -1"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: {sigma: 1, normal: [0, 1]}\n",
                    "tol.yaml:3:20", {"give one distribution, not both 'sigma' and 'normal'"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: {const: 1, sigma: 1}\n",
                    "tol.yaml:3:20", {"give one distribution, not both 'const' and 'sigma'"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: {uniform: [1, -1]}\n", "tol.yaml:3:19",
                    {"errors.E_XX.uniform: lo (1) must be less than hi (-1)"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: {normal: [0, 1, 2]}\n",
                    "tol.yaml:3:18", {"errors.E_XX.normal: expected [mean, sigma]"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: {sigma: 1, unit: furlong}\n",
                    "tol.yaml:3:26", {"errors.E_XX.unit: unknown unit \"furlong\""});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: {sigma: 1, unit: urad}\n",
                    "tol.yaml:3:26",
                    {"errors.E_XX.unit: unit 'urad' is an angle but error 'E_XX' is a "
                     "translation"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: {const: abc}\n", "tol.yaml:3:17",
                    {"errors.E_XX.const: expected a number, got 'abc'"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: {sigma: nan}\n", "tol.yaml:3:17",
                    {"NaN is not a valid value"});
  expect_file_error("weilgen_tolerances: 1\nerrors:\n  E_XX: {truncnormal: [100, 1, 0, 1]}\n",
                    "tol.yaml:3:9", {"errors.E_XX: invalid distribution"});
  expect_file_error("weilgen_tolerances: 1\ngroups:\n  bogus: {sigma: 1}\n", "tol.yaml:3:3",
                    {"groups: unknown group 'bogus' (groups of machine gantry_grinder with "
                     "errors: positioning, straightness, angular, squareness)"});
  expect_file_error("weilgen_tolerances: 1\ngroups:\n  thermal: {sigma: 1}\n", "tol.yaml:3:3",
                    {"group 'thermal' has no errors in machine gantry_grinder"});
  expect_file_error("weilgen_tolerances: 1\ngroups:\n  angular: {sigma: 1, unit: um}\n",
                    "tol.yaml:3:29", {"unit 'um' is a length but error 'E_AX' is a rotation"});
  expect_file_error("weilgen_tolerances: 1\nerrors: [E_XX]\n", "tol.yaml:2:9",
                    {"errors: expected a mapping from error name to distribution"});
  expect_file_error("weilgen_tolerances: 1\nerrors: {E_XX: {sigma: 1}\n", "tol.yaml:3:1",
                    {"YAML syntax error"});
}

TEST_CASE("tolerance files: write, read back, shipped examples") {
  const Description& d = grinder();
  std::vector<InputDistribution> dist = error_distributions(d, {}, {});
  dist[error_index(d, "E_YX")] = InputDistribution::normal(0.0012, 0.004);
  dist[error_index(d, "E_ZX")] = InputDistribution::uniform(-0.01, 0.02);
  dist[error_index(d, "E_AX")] = InputDistribution::truncated_normal(1e-6, 3e-6, -5e-6, 7e-6);
  dist[error_index(d, "E_CX")] = InputDistribution::normal(2e-6, 0);
  dist[error_index(d, "E_XY")] = InputDistribution::normal(0, 0.05 / 6 * 0.37);
  const std::string dir = tmp_dir("roundtrip");
  const std::string path = dir + "/allocated.yaml";
  write_tolerance_file(path, d, dist, "allocated by a test\n\nsecond line");
  std::string text;
  REQUIRE(read_file(path, text));
  CHECK(text.rfind("# allocated by a test\n#\n# second line\nweilgen_tolerances: 1\n"
                   "machine: gantry_grinder\n",
                   0) == 0);
  CHECK(text.find("  E_XX: {sigma: 0.00833333333333333") != std::string::npos);
  CHECK(text.find("E_YX: {normal: [0.0012, 0.004], unit: mm}") != std::string::npos);
  CHECK(text.find("E_ZX: {uniform: [-0.01, 0.02], unit: mm}") != std::string::npos);
  CHECK(text.find("E_AX: {truncnormal: [1e-06, 3e-06, -5e-06, 7e-06], unit: rad}") !=
        std::string::npos);
  CHECK(text.find("E_CX: {const: 2e-06, unit: rad}") != std::string::npos);
  CHECK(text.find("# positioning, δxx") != std::string::npos);
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file() ? 1 : 0;
  CHECK(files == 1);  // no temporary left

  const ToleranceOverrides back = read_tolerance_file(path, d);
  for (std::size_t i = 0; i < dist.size(); ++i) {
    INFO(d.errors[i].name);
    REQUIRE(back[i].has_value());
    check_same(*back[i], dist[i]);
  }
  const auto via = error_distributions(d, {path}, {});
  for (std::size_t i = 0; i < dist.size(); ++i) check_same(via[i], dist[i]);

  // Unit conversion both ways (five-axis: um and urad errors).
  const Description& f = five_axis();
  std::vector<InputDistribution> fd = error_distributions(f, {}, {});
  fd[0] = InputDistribution::normal(0, 1.234567890123e-3);
  const std::string fpath = dir + "/five.yaml";
  write_tolerance_file(fpath, f, fd, "");
  const ToleranceOverrides fb = read_tolerance_file(fpath, f);
  for (std::size_t i = 0; i < fd.size(); ++i) check_same(*fb[i], fd[i]);

  expect_words(error_of([&] { tolerance_file_text(d, {}, ""); }),
               {"0 distributions given for 21 errors"});

  // The shipped examples load and restate Table 1.
  const std::string table1 =
      std::string(WEILGEN_SOURCE_DIR) + "/machines/tolerances/gantry_grinder_table1.yaml";
  const auto t1 = error_distributions(d, {table1}, {});
  const auto machine = error_distributions(d, {}, {});
  for (std::size_t i = 0; i < t1.size(); ++i) {
    INFO(d.errors[i].name);
    check_same(t1[i], machine[i]);
  }
  const auto tight = error_distributions(
      d, {std::string(WEILGEN_SOURCE_DIR) + "/machines/tolerances/gantry_grinder_tight.yaml"}, {});
  for (std::size_t i = 0; i < t1.size(); ++i) {
    INFO(d.errors[i].name);
    CHECK(tight[i].stddev() <= machine[i].stddev());
  }
}
