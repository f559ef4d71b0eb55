// LinuxCNC axis compensation tables (docs/controllers.md): `iso230-2 --comp-table` and
// `identify --comp-table --axis`. The sign convention is checked the way LinuxCNC applies a
// table: this file reads the COMP_FILE as usrmotLoadComp does (type 0: trim = nominal − value;
// type 1: the values are the trims), interpolates the trims linearly between nominals as
// control.c does (constant beyond the ends) and adds them to the motor command; a synthetic
// machine run with the table must then evaluate to ~0 under ISO 230-2.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "test_support.hpp"
#include "weilgen/analysis/axis_comp_table.hpp"
#include "weilgen/measure/comp_table.hpp"
#include "weilgen/report/comp_table_document.hpp"

using namespace weilgen;
namespace fs = std::filesystem;

namespace {

// A LinuxCNC joint's compensation as control.c applies it: trims per direction, interpolated.
struct LinuxCncComp {
  std::vector<double> nominal, fwd_trim, rev_trim;

  explicit LinuxCncComp(const std::string& path, int type) {
    std::ifstream in(path);
    for (std::string line; std::getline(in, line);) {
      double nom = 0, fwd = 0, rev = 0;
      if (std::sscanf(line.c_str(), "%lf %lf %lf", &nom, &fwd, &rev) != 3) break;  // as LinuxCNC
      nominal.push_back(nom);
      fwd_trim.push_back(type == 0 ? nom - fwd : fwd);
      rev_trim.push_back(type == 0 ? nom - rev : rev);
    }
  }
  double trim(double pos, int direction) const {
    const auto& t = direction > 0 ? fwd_trim : rev_trim;
    if (pos <= nominal.front()) return t.front();
    if (pos >= nominal.back()) return t.back();
    std::size_t i = 0;
    while (pos >= nominal[i + 1]) ++i;
    return t[i] + (t[i + 1] - t[i]) / (nominal[i + 1] - nominal[i]) * (pos - nominal[i]);
  }
};

// The synthetic axis: the actual position (mm) when the motor is commanded to m, approaching in
// `direction`: a scale error, a periodic pitch error and a reversal of 6 µm.
double actual_mm(double m, int direction) {
  return m + 0.002 + 12e-6 * m + 0.003 * std::sin(m / 70.0) + direction * 0.003;
}

// An ISO 230-2 CSV of the axis at targets 0, 50, ..., 500 mm, 4 cycles each way; `trim` gives the
// motor command's correction (none: 0).
std::string iso_csv(const std::function<double(double, int)>& trim) {
  std::ostringstream os;
  os << "# axis: X\nX,dir,cycle,dx_um\n";
  os.precision(17);
  for (int cycle = 1; cycle <= 4; ++cycle)
    for (int direction : {+1, -1})
      for (int k = 0; k <= 10; ++k) {
        const int i = direction > 0 ? k : 10 - k;
        const double target = 50.0 * i;
        const double motor = target + trim(target, direction);
        os << target << "," << direction << "," << cycle << ","
           << (actual_mm(motor, direction) - target) * 1e3 << "\n";
      }
  return os.str();
}

nlohmann::json iso_json(const std::string& csv, const fs::path& dir, const std::string& name,
                        const std::string& extra = "") {
  const std::string data = (dir / (name + ".csv")).string(),
                    json = (dir / (name + ".json")).string();
  write_file_atomically(data, csv);
  const test::Run r = test::run(test::cli("iso230-2 " + data + " --json " + json + " " + extra));
  INFO(r.out);
  REQUIRE(r.status == 0);
  return nlohmann::json::parse(test::read_text(json));
}

double figure(const nlohmann::json& j, const char* key) { return j.at(key).get<double>(); }

}  // namespace

TEST_CASE("iso230-2 --comp-table: the compensated synthetic run evaluates to ~0 (types 0 and 1)") {
  const fs::path dir = test::fresh_dir("comp_table_iso");
  for (int type : {0, 1}) {
    CAPTURE(type);
    const std::string table = (dir / ("x" + std::to_string(type) + ".comp")).string();
    const nlohmann::json before =
        iso_json(iso_csv([](double, int) { return 0.0; }), dir, "before",
                 "--comp-table " + table + " --comp-type " + std::to_string(type));
    CHECK(figure(before, "E_um") > 10);  // systematic: scale + pitch, tens of µm
    CHECK(figure(before, "B_um") == doctest::Approx(6).epsilon(1e-9));

    // The file: ascending nominals 0..500, one triplet per target, nothing else.
    const LinuxCncComp comp(table, type);
    REQUIRE(comp.nominal.size() == 11);
    CHECK(test::read_text(table).find('#') == std::string::npos);
    for (std::size_t i = 0; i < 11; ++i) {
      CHECK(comp.nominal[i] == 50.0 * static_cast<double>(i));
      // The trim is minus the mean deviation at the target: -(actual - commanded).
      CHECK(comp.fwd_trim[i] ==
            doctest::Approx(-(actual_mm(comp.nominal[i], 1) - comp.nominal[i])).epsilon(1e-12));
    }

    const nlohmann::json after = iso_json(
        iso_csv([&](double target, int direction) { return comp.trim(target, direction); }), dir,
        "after_" + std::to_string(type));
    // What is left is the error's slope times the correction: |f'| |x| < 5.5e-5 * 0.014 mm,
    // below 1e-3 um (the figures were tens of um).
    for (const char* key : {"E_um", "E_up_um", "E_down_um", "M_um", "B_um"}) {
      CAPTURE(key);
      CHECK(std::fabs(figure(after, key)) < 5e-3);
    }
    MESSAGE("type " << type << ": E " << figure(before, "E_um") << " -> " << figure(after, "E_um")
                    << " um, B " << figure(before, "B_um") << " -> " << figure(after, "B_um")
                    << " um, M " << figure(before, "M_um") << " -> " << figure(after, "M_um"));
  }
}

TEST_CASE("iso230-2 --comp-table: units, drift source, and bad flags refused before any output") {
  const fs::path dir = test::fresh_dir("comp_table_flags");
  const std::string data = (dir / "run.csv").string();
  write_file_atomically(data, iso_csv([](double, int) { return 0.0; }));
  const std::string original = test::read_text(data);
  const std::string inch = (dir / "inch.comp").string(), mm = (dir / "mm.comp").string();
  REQUIRE(test::run(test::cli("iso230-2 " + data + " --comp-table " + mm)).status == 0);
  REQUIRE(test::run(test::cli("iso230-2 " + data + " --comp-table " + inch + " --comp-units inch"))
              .status == 0);
  const LinuxCncComp a(mm, 0), b(inch, 0);
  REQUIRE(a.nominal.size() == b.nominal.size());
  for (std::size_t i = 0; i < a.nominal.size(); ++i) {
    CHECK(b.nominal[i] == doctest::Approx(a.nominal[i] / 25.4).epsilon(1e-14));
    CHECK(b.fwd_trim[i] == doctest::Approx(a.fwd_trim[i] / 25.4).epsilon(1e-9));
  }
  // The drift-eliminated chart without drift is the classical one up to the reference's offset.
  const std::string drift = (dir / "drift.comp").string();
  const test::Run d =
      test::run(test::cli("iso230-2 " + data + " --comp-table " + drift + " --comp-source drift"));
  INFO(d.out);
  CHECK(d.status == 0);
  CHECK(d.out.find("COMP_FILE = " + drift) != std::string::npos);

  const auto refused = [&](const std::string& flags, const std::string& message) {
    const std::string out = (dir / "refused.comp").string();
    const test::Run r = test::run(test::cli("iso230-2 " + data + " " + flags));
    INFO(flags, r.out);
    CHECK(r.status == 2);
    CHECK(r.out.find(message) != std::string::npos);
    CHECK(!fs::exists(out));
    CHECK(!fs::exists(dir / "refused.json"));
  };
  const std::string out = (dir / "refused.comp").string(), json = (dir / "refused.json").string();
  refused("--comp-table " + out + " --comp-type 2 --json " + json, "--comp-type 2");
  refused("--comp-table " + out + " --comp-units cm --json " + json, "--comp-units cm");
  refused("--comp-table " + out + " --comp-source best --json " + json, "--comp-source best");
  refused("--comp-table " + data + " --json " + json, "is the input");
  refused("--comp-table " + dir.string() + " --json " + json, "is a directory");
  refused("--comp-type 1 --json " + json, "--comp-type needs --comp-table");
  CHECK(test::read_text(data) == original);
}

TEST_CASE("comp table: LinuxCNC's limits and the writer's two types") {
  CompTable t;
  t.axis = "X";
  t.unit = "mm";
  t.nominal = {0, 100, 200};
  t.forward = {0.001, -0.002, 0.0035};
  t.reverse = {0.004, 0.0, -0.001};
  CHECK(linuxcnc_comp_file(t, 0) == "0 0.001 0.004\n100 99.998 100\n200 200.0035 199.999\n");
  CHECK(linuxcnc_comp_file(t, 1) == "0 -0.001 -0.004\n100 0.002 0\n200 -0.0035 0.001\n");
  CompTable unsorted = t;
  unsorted.nominal = {0, 200, 100};
  CHECK_THROWS_WITH_AS(unsorted.validate(), doctest::Contains("must increase"),
                       std::invalid_argument);
  CompTable big = t;
  big.nominal.resize(257);
  for (std::size_t i = 0; i < big.nominal.size(); ++i) big.nominal[i] = static_cast<double>(i);
  big.forward.assign(257, 0.0);
  big.reverse.assign(257, 0.0);
  CHECK_THROWS_WITH_AS(big.validate(), doctest::Contains("at most 256"), std::invalid_argument);
}

TEST_CASE("identify --comp-table --axis: a positioning error alone is the table (linear, rotary)") {
  // VMC: only E_XX's basis coefficients non-zero; the table along X is E_XX(X) itself (ISO 230-1
  // E_XX is the axis' positioning deviation), in mm, with the other axes anywhere.
  for (const auto& [machine, axis, error, at] :
       {std::tuple<std::string, std::string, std::string, std::string>{"vmc_3axis", "X", "E_XX",
                                                                       "Y=-120,Z=-60"},
        {"five_axis_ac", "C", "E_CC", "X=40,Z=-100,Y=30,A=20"}}) {
    const std::string& machine_name = machine;  // clang < 16 cannot capture a structured binding
    CAPTURE(machine_name);
    const std::shared_ptr<Model> model = test::builtin_model(machine);
    const Description& d = model->description();
    const ErrorParameterisation param(d, PdgeBasisChoice{});
    std::vector<double> theta(param.size(), 0.0);
    const int e = d.error_index(error);
    for (std::size_t p = 0; p < param.size(); ++p)
      if (param.parameters()[p].error == e) theta[p] = 3.0 + 2.0 * static_cast<double>(p % 3);
    AxisCompTableOptions o;
    o.axis = axis;
    o.points = 9;
    o.at = at;
    const CompTable t = axis_comp_table(*model, param, theta, o);
    REQUIRE(t.nominal.size() == 9);
    const bool rotary = axis == "C";
    CHECK(t.unit == (rotary ? "deg" : "mm"));
    const auto axes = d.axes();
    std::size_t k = 0;
    while (d.bodies[static_cast<std::size_t>(axes[k])].joint.coordinate != axis) ++k;
    const PoseSet line = parse_poses(
        d, {},
        {axis + "=" + std::to_string(d.bodies[static_cast<std::size_t>(axes[k])].joint.min) + ":" +
         std::to_string(d.bodies[static_cast<std::size_t>(axes[k])].joint.max) + ":9," + at});
    // Both axes carry the workpiece: LinuxCNC's joint is minus the model's axis, the entries
    // run the other way, and the deviation changes sign with the coordinate.
    CHECK(t.joint == (rotary ? 4 : 0));
    double largest = 0;
    for (std::size_t i = 0; i < 9; ++i) {
      std::vector<double> errors(d.errors.size());
      param.errors_at(line.poses[i].data(), theta.data(), errors.data());
      const double want = -errors[static_cast<std::size_t>(e)] * (rotary ? 180.0 / M_PI : 1.0);
      CHECK(t.nominal[8 - i] == doctest::Approx(-line.poses[i][k]));
      CHECK(t.forward[8 - i] == doctest::Approx(want).epsilon(1e-7).scale(1e-12));
      CHECK(t.reverse[8 - i] == t.forward[8 - i]);
      largest = std::max(largest, std::fabs(want));
    }
    CHECK(largest > 0);
  }
}

TEST_CASE("identify --comp-table --axis on the VMC's measured points, and bad axis flags refused") {
  const fs::path dir = test::fresh_dir("comp_table_identify");
  const std::string data = std::string(WEILGEN_SOURCE_DIR) + "/examples/data/vmc_3axis_points.csv";
  const std::string table = (dir / "x.comp").string();
  test::Run r = test::run(test::cli("identify vmc_3axis --data " + data + " --quiet --comp-table " +
                                    table + " --axis X --comp-points 11 --comp-at Y=-200,Z=-150"));
  INFO(r.out);
  REQUIRE(r.status == 0);
  CHECK(r.out.find("COMP_FILE_TYPE = 0") != std::string::npos);
  const LinuxCncComp comp(table, 0);
  REQUIRE(comp.nominal.size() == 11);
  CHECK(comp.nominal.front() == -500.0);  // joint 0 = -X: X carries the workpiece
  CHECK(comp.nominal.back() == 0.0);
  CHECK(r.out.find("[JOINT_0]") != std::string::npos);
  double largest = 0;
  for (double v : comp.fwd_trim) largest = std::max(largest, std::fabs(v));
  CHECK(largest > 1e-4);  // µm-scale corrections
  CHECK(largest < 0.1);
  CHECK(comp.fwd_trim == comp.rev_trim);

  const auto refused = [&](const std::string& flags, const std::string& message) {
    const std::string out = (dir / "refused.comp").string();
    const test::Run x =
        test::run(test::cli("identify vmc_3axis --data " + data + " --quiet " + flags));
    INFO(flags, x.out);
    CHECK(x.status == 2);
    CHECK(x.out.find(message) != std::string::npos);
    CHECK(!fs::exists(out));
  };
  const std::string out = (dir / "refused.comp").string();
  refused("--comp-table " + out, "--comp-table needs --axis");
  refused("--comp-table " + out + " --axis Q", "--axis Q");
  refused("--comp-table " + out + " --axis X --comp-points 300", "--comp-points 300");
  refused("--comp-table " + out + " --axis X --comp-at Y=5", "--comp-at");
  refused("--comp-table " + out + " --axis X --comp-at X=5", "--comp-at");
  refused("--axis X", "--axis needs --comp-table");
  refused("--comp-table " + data + " --axis X", "is the input");
}
