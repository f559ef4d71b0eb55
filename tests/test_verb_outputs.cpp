// Issue 18 §3, every verb's outputs: the figures (allocate, identify, fit-pdge, reliability over
// three grid axes as small multiples), unit CSV headers against the JSON, --at naming every axis,
// --fix group:<group>, --predict-out refused before the work, the allocation verdict within its
// target tolerance, pareto() ordering, help defaults as written and "verb" in every JSON document.
#include <doctest/doctest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "test_support.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/report/plot.hpp"

using namespace weilgen;
using nlohmann::json;
using test::cli;
using test::run;
using test::Run;

namespace {

json read_json(const std::filesystem::path& path) {
  std::string text;
  REQUIRE(read_file(path.string(), text));
  return json::parse(text);
}

// A written SVG: the document element and each expected text.
void check_svg(const std::filesystem::path& path, const std::vector<std::string>& texts) {
  std::string svg;
  REQUIRE(read_file(path.string(), svg));
  CHECK(svg.find("<svg") != std::string::npos);
  CHECK(svg.find("</svg>") != std::string::npos);
  for (const std::string& t : texts) {
    CAPTURE(t);
    CHECK(svg.find(t) != std::string::npos);
  }
}

void check_document(const json& j, const std::string& verb) {
  CHECK(j.at("verb") == verb);
  CHECK(j.at("weilgen") == kVersion);
}

std::vector<std::string> csv_row(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream s(line);
  std::string c;
  while (std::getline(s, c, ',')) cells.push_back(c);
  return cells;
}

const std::string kData = std::string(WEILGEN_SOURCE_DIR) + "/examples/data/";

}  // namespace

TEST_CASE("outputs: allocate --plot draws the steps chart, and the verdict has a tolerance") {
  const auto dir = test::fresh_dir("outputs_allocate");
  const std::string base =
      "allocate gantry_grinder --grid X=0:1000:3,Y=0,Z=600 --tolerance dx=20um";
  REQUIRE(run(cli(base + " --quiet --plot " + (dir / "a.svg").string() + " --json " +
                  (dir / "a.json").string()))
              .status == 0);
  check_svg(dir / "a.svg", {"R(dx) over the steps", "spreads of the chosen errors", "min target"});
  const json a = read_json(dir / "a.json");
  check_document(a, "allocate");
  CHECK(a["settings"]["target_tolerance"] == 1e-9);
  // A minimum target 1e-12 above the start's minimum reliability: met, at the start, for every
  // --choose (without the tolerance the run would tighten spreads for a rounding difference).
  const double r0 = a["steps"][0]["outputs"][0]["min"].get<double>();
  REQUIRE(r0 > 0.5);
  std::ostringstream target;
  target.precision(17);
  target << r0 + 1e-12;
  for (const char* choose : {"1", "2", "4"}) {
    CAPTURE(choose);
    const auto out = dir / (std::string("c") + choose + ".json");
    const Run r = run(cli(base + " --quiet --mean 0.5 --min " + target.str() + " --choose " +
                          choose + " --json " + out.string()));
    REQUIRE(r.status == 0);
    const json j = read_json(out);
    CHECK(j["met"] == true);
    CHECK(j["steps"].size() == 1);
    CHECK(r.out.find("targets met") != std::string::npos);
  }
}

TEST_CASE("outputs: allocate --cost-aware gives one verdict whatever --choose") {
  // The case: the optimum's verdict depended on --choose (a 2e-12 miss counted).
  const auto dir = test::fresh_dir("outputs_cost_aware");
  double cost = NAN;
  for (const char* choose : {"1", "4"}) {
    CAPTURE(choose);
    const auto out = dir / (std::string("c") + choose + ".json");
    // With --choose 1 the step procedure cannot meet the targets (exit 1); the optimum can.
    const Run r =
        run(cli("allocate gantry_grinder --grid X=0:1000:3,Y=-1500:1500:3,Z=600:1400:3 "
                "--tolerance dx=30um,dy=30um --cost-aware --quiet --choose " +
                std::string(choose) + " --json " + out.string()));
    CHECK(r.status == (std::string(choose) == "1" ? 1 : 0));
    REQUIRE(std::filesystem::exists(out));
    const json ca = read_json(out)["cost_aware"];
    CHECK(ca["met"] == true);
    if (std::isnan(cost)) cost = ca["cost"].get<double>();
    CHECK(ca["cost"].get<double>() == doctest::Approx(cost).epsilon(1e-6));
  }
}

TEST_CASE("outputs: identify --plot, --csv equals the JSON, --fix group:, --predict-out first") {
  const auto dir = test::fresh_dir("outputs_identify");
  const std::string base = "identify vmc_3axis --data " + kData + "vmc_3axis_points.csv --quiet";
  REQUIRE(run(cli(base + " --plot " + (dir / "i.svg").string() + " --csv " +
                  (dir / "i.csv").string() + " --json " + (dir / "i.json").string()))
              .status == 0);
  check_svg(dir / "i.svg", {"(not identifiable)", "E_AX[u]"});
  const json j = read_json(dir / "i.json");
  check_document(j, "identify");
  // The CSV's parameter rows carry the JSON's values, in order, with their unit.
  std::string csv;
  REQUIRE(read_file((dir / "i.csv").string(), csv));
  std::stringstream lines(csv);
  std::string line;
  std::getline(lines, line);
  CHECK(line.rfind("# weilgen identify vmc_3axis", 0) == 0);
  std::getline(lines, line);
  CHECK(line == "parameter,error,basis,term,value,standard_error,unit,identifiable,fixed");
  std::size_t k = 0;
  for (const json& p : j["parameters"]) {
    if (!std::getline(lines, line)) break;
    const auto cells = csv_row(line);
    REQUIRE(cells.size() >= 7);
    CHECK(cells[0] == p["label"].get<std::string>());
    CHECK(std::stod(cells[4]) == doctest::Approx(p["value"].get<double>()).epsilon(1e-15));
    CHECK(cells[6] == p["unit"].get<std::string>());
    ++k;
  }
  CHECK(k == j["parameters"].size());

  // --fix group:straightness holds the same errors as naming them one by one.
  REQUIRE(run(cli(base + " --fix group:straightness --json " + (dir / "g.json").string())).status ==
          0);
  const json g = read_json(dir / "g.json");
  std::set<std::string> fixed, all;
  for (const json& p : g["parameters"]) {
    all.insert(p["error"].get<std::string>());
    if (p["fixed"] == true) fixed.insert(p["error"].get<std::string>());
  }
  std::set<std::string> straightness;  // E_<D><K>, D a linear direction other than the axis K
  for (const std::string& e : all)
    if (e.size() == 4 && std::string("XYZ").find(e[2]) != std::string::npos &&
        std::string("XYZ").find(e[3]) != std::string::npos && e[2] != e[3])
      straightness.insert(e);
  REQUIRE(!straightness.empty());
  CHECK(fixed == straightness);
  std::string by_name;
  for (const std::string& e : fixed) by_name += " --fix " + e;
  REQUIRE(run(cli(base + by_name + " --json " + (dir / "n.json").string())).status == 0);
  CHECK(read_json(dir / "n.json")["parameters"] == g["parameters"]);

  // --predict-out on a ballbar trace: refused before the work, nothing written.
  const Run r = run(cli(base + " --predict " + kData + "vmc_3axis_ballbar.csv --predict-out " +
                        (dir / "p.csv").string() + " --json " + (dir / "p.json").string()));
  CHECK(r.status == 2);
  CHECK(r.out.find("--predict-out") != std::string::npos);
  CHECK(r.out.find("ballbar") != std::string::npos);
  CHECK(!std::filesystem::exists(dir / "p.csv"));
  CHECK(!std::filesystem::exists(dir / "p.json"));
}

TEST_CASE("outputs: fit-pdge --plot draws data points and merges identical curves") {
  const auto dir = test::fresh_dir("outputs_fit");
  REQUIRE(run(cli("fit-pdge " + kData + "line6d_x.csv --column E_XX,E_BX --plot " +
                  (dir / "f.svg").string() + " --csv " + (dir / "f.csv").string() + " --json " +
                  (dir / "f.json").string()))
              .status == 0);
  check_svg(dir / "f.svg", {"E_XX: data and fits", "E_BX: residuals", "data (mean per position)",
                            "poly:10 = legendre:10 = chebyshev:10"});
  check_document(read_json(dir / "f.json"), "fit-pdge");
  std::string csv;
  REQUIRE(read_file((dir / "f.csv").string(), csv));
  CHECK(csv.find("profile,column,unit,basis,kind,order") != std::string::npos);
}

TEST_CASE("outputs: reliability over three grid axes, small multiples and unit CSV columns") {
  const auto dir = test::fresh_dir("outputs_reliability");
  REQUIRE(run(cli("reliability gantry_grinder --grid X=0:1000:2,Y=-1500:1500:2,Z=600:1400:2 "
                  "--tolerance dx=30um --quiet --plot " +
                  (dir / "r.svg").string() + " --csv " + (dir / "r.csv").string() + " --json " +
                  (dir / "r.json").string()))
              .status == 0);
  check_svg(dir / "r.svg", {"X=0", "X=1000", "Y (mm)", "Z (mm)"});
  const json j = read_json(dir / "r.json");
  check_document(j, "reliability");
  CHECK(j["derivative_units"].is_object());
  std::string csv;
  REQUIRE(read_file((dir / "r.csv").string(), csv));
  std::stringstream lines(csv);
  std::string head, row;
  std::getline(lines, head);
  std::getline(lines, row);
  const auto h = csv_row(head), c = csv_row(row);
  REQUIRE(h.size() == c.size());
  CHECK(h[0] == "X_mm");
  std::size_t col = h.size();
  for (std::size_t i = 0; i < h.size(); ++i)
    if (h[i] == "dR_dsigma_E_BX_per_rad") col = i;
  REQUIRE(col < h.size());
  const double json_value = j["results"][0]["dR_dsigma"]["E_BX"].get<double>();
  CHECK(json_value != 0);
  CHECK(std::stod(c[col]) == doctest::Approx(json_value).epsilon(1e-15));

  // 40 heat maps (40 values of X) are more than one figure holds: refused before the sweep,
  // naming the count and the way out, and nothing written.
  const Run refused =
      run(cli("reliability gantry_grinder --grid X=0:1000:40,Y=-1500:1500:2,"
              "Z=600:1400:2 --tolerance dx=30um --quiet --plot " +
              (dir / "r40.svg").string()));
  CHECK(refused.status == 2);
  CHECK(refused.out.find("gives 40 heat maps") != std::string::npos);
  CHECK(refused.out.find("--csv") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir / "r40.svg"));
}

TEST_CASE("outputs: --at names every axis, help shows 0.95, sensitivity names its verb") {
  const Run r = run(cli("sensitivity gantry_grinder --at Z=700 --quiet"));
  CHECK(r.status == 2);
  CHECK(r.out.find("--at") != std::string::npos);
  CHECK(r.out.find("axes X, Y are not given") != std::string::npos);
  const Run h = run(cli("sensitivity --help"));
  CHECK(h.out.find("--confidence arg (=0.95)") != std::string::npos);
  const auto dir = test::fresh_dir("outputs_sensitivity");
  REQUIRE(run(cli("sensitivity gantry_grinder --at X=0,Y=0,Z=600 --method local --quiet --json " +
                  (dir / "s.json").string()))
              .status == 0);
  check_document(read_json(dir / "s.json"), "sensitivity");
}

TEST_CASE("outputs: pareto() sorts descending, drops categories without effect") {
  BarChart c;
  c.categories = {"a", "b", "c", "d", "e"};
  c.series = {{"S", {0.1, 0.0, 0.5, NAN, 0.3}, {}, {}}};
  pareto(c);
  CHECK(c.categories == std::vector<std::string>{"c", "e", "a"});
  REQUIRE(c.series[0].value.size() == 3);
  CHECK(c.series[0].value[0] == 0.5);
  CHECK(c.series[0].value[2] == 0.1);
  BarChart z;  // every category without effect: kept
  z.categories = {"a", "b"};
  z.series = {{"S", {0.0, 0.0}, {}, {}}};
  pareto(z);
  CHECK(z.categories.size() == 2);
}
