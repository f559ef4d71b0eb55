// The analysis verbs end to end: `weilgen sensitivity`, `weilgen reliability` on the shipped
// grinder against independent closed forms; JSON schema; determinism; bad arguments; a machine
// that is not built in (compiled at run time).
#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "test_support.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/uq/distribution.hpp"

using namespace weilgen;
using nlohmann::json;
using test::cli;
using test::run;
using test::Run;

namespace {

json read_json(const std::string& path) {
  std::string text;
  REQUIRE(read_file(path, text));
  return json::parse(text);
}

// Table 1 of Wang & Yuan 2021 (standard deviations; mm and rad).
double grinder_sigma(const std::string& e) {
  static const std::map<std::string, double> s = {
      {"E_XX", 0.05 / 6},    {"E_YX", 0.05 / 6},    {"E_ZX", 0.05 / 6},     {"E_AX", 0.03 / 6000},
      {"E_BX", 0.06 / 6000}, {"E_CX", 0.05 / 6000}, {"E_XY", 0.04 / 6},     {"E_YY", 0.05 / 6},
      {"E_ZY", 0.04 / 6},    {"E_AY", 0.05 / 6000}, {"E_BY", 0.04 / 6000},  {"E_CY", 0.04 / 6000},
      {"E_XZ", 0.03 / 6},    {"E_YZ", 0.03 / 6},    {"E_ZZ", 0.05 / 6},     {"E_AZ", 0.03 / 6000},
      {"E_BZ", 0.04 / 6000}, {"E_CZ", 0.03 / 6000}, {"E_C0X", 0.03 / 3000}, {"E_B0Z", 0.03 / 3000},
      {"E_A0Z", 0.02 / 3000}};
  return s.at(e);
}

// dx of the grinder, independently from eqs. (17)-(18) with correction 1 (machine notes):
// dx = -E_XX - z E_BX + y E_CX + E_XZ - y E_CZ + E_XY + y E_C0X.
std::map<std::string, double> grinder_dx_coefficients(double y, double z) {
  return {{"E_XX", -1}, {"E_BX", -z}, {"E_CX", y}, {"E_XZ", 1},
          {"E_CZ", -y}, {"E_XY", 1},  {"E_C0X", y}};
}

}  // namespace

TEST_CASE("sensitivity CLI: coefficients, exact indices and QMC indices on the grinder") {
  const auto dir = test::fresh_dir("cli_sensitivity");
  const std::string out = (dir / "s.json").string();
  const Run r =
      run(cli("sensitivity gantry_grinder --at X=0,Y=750,Z=1000 --at X=500,Y=-1500,Z=600 "
              "--outputs dx,dy,dp --samples 4096 --bootstrap 100 --quiet --json " +
              out));
  REQUIRE(r.status == 0);
  CHECK(r.out.find("E_BX") != std::string::npos);
  const json j = read_json(out);
  CHECK(j["verb"] == "sensitivity");
  CHECK(j["model"]["engine"] == "built-in");
  CHECK(j["inputs"].size() == 21);
  CHECK(j["results"].size() == 2 * 3 * 21);
  std::size_t inside = 0, compared = 0;
  double sum_exact = 0;
  for (const auto& rec : j["results"]) {
    for (const char* key :
         {"pose", "output", "error", "coefficient", "S", "S_ci", "ST", "ST_ci", "S_exact"})
      REQUIRE(rec.contains(key));
    const double y = rec["pose"]["Y"], z = rec["pose"]["Z"];
    const std::string e = rec["error"], o = rec["output"];
    if (o == "dx") {
      const auto c = grinder_dx_coefficients(y, z);
      const double expect = c.count(e) ? c.at(e) : 0.0;
      CHECK(rec["coefficient"].get<double>() == doctest::Approx(expect).epsilon(1e-12));
      if (y == 750) sum_exact += rec["S_exact"].get<double>();
    }
    if (o == "dp") {
      CHECK(rec["coefficient"].is_null());
      CHECK(rec["S_exact"].is_null());
      continue;
    }
    // The exact index of the linear output against the QMC estimate and its interval.
    const double ex = rec["S_exact"], s = rec["S"], lo = rec["S_ci"][0], hi = rec["S_ci"][1];
    const double st = rec["ST"], tlo = rec["ST_ci"][0], thi = rec["ST_ci"][1];
    ++compared;
    if (lo <= ex && ex <= hi && tlo <= ex && ex <= thi) ++inside;
    CHECK(std::abs(s - ex) <= std::max(3 * (hi - lo) / 2, 1e-9));
    CHECK(std::abs(st - ex) <= std::max(3 * (thi - tlo) / 2, 1e-9));
  }
  CHECK(sum_exact == doctest::Approx(1.0).epsilon(1e-12));
  CHECK(static_cast<double>(inside) >= 0.85 * static_cast<double>(compared));
  // Exact index by hand at Y=750, Z=1000: S(E_BX) = (1000 sigma_BX)^2 / sum c^2 sigma^2.
  double v = 0;
  for (const auto& [e, c] : grinder_dx_coefficients(750, 1000))
    v += c * c * grinder_sigma(e) * grinder_sigma(e);
  for (const auto& rec : j["results"])
    if (rec["output"] == "dx" && rec["error"] == "E_BX" && rec["pose"]["Y"] == 750)
      CHECK(rec["S_exact"].get<double>() ==
            doctest::Approx(std::pow(1000 * grinder_sigma("E_BX"), 2) / v).epsilon(1e-12));
}

TEST_CASE("sensitivity CLI: replicate intervals by default, the bootstrap on request, in JSON") {
  const auto dir = test::fresh_dir("cli_sensitivity_intervals");
  const std::string out = (dir / "s.json").string();
  const std::string common =
      "sensitivity gantry_grinder --at X=0,Y=1500,Z=600 --outputs dx --method all --samples 4096 "
      "--quiet --json " +
      out;
  const Run r = run(cli(common));
  REQUIRE(r.status == 0);
  CHECK(r.out.find("Sobol' intervals: 95 % Student t over 4 independent randomised replicates") !=
        std::string::npos);
  json j = read_json(out);
  CHECK(j["settings"]["intervals"] == "replicates");
  CHECK(j["settings"]["replicates"] == 4);
  CHECK(j["settings"]["bootstrap"] == 0);
  CHECK(j["settings"]["evaluations"] == 4096 * 23);
  // The grinder is linear at order 1: the replicate intervals are narrow and hold S_exact
  // for nearly every acting error (95 % each; 14 intervals).
  int inside = 0, acting = 0;
  for (const auto& rec : j["results"]) {
    const double ex = rec["S_exact"];
    if (ex == 0) {
      CHECK(rec["S"] == 0.0);
      CHECK(rec["S_ci"][1] == 0.0);
      continue;
    }
    acting += 2;
    inside += rec["S_ci"][0] <= ex && ex <= rec["S_ci"][1];
    inside += rec["ST_ci"][0] <= ex && ex <= rec["ST_ci"][1];
    CHECK(rec["S_ci"][1].get<double>() - rec["S_ci"][0].get<double>() < 0.05);
  }
  CHECK(acting == 14);
  CHECK(inside >= 11);
  REQUIRE(run(cli(common + " --replicates 4")).status == 0);
  CHECK(read_json(out)["settings"]["replicates"] == 4);
  REQUIRE(run(cli(common + " --bootstrap 50")).status == 0);
  j = read_json(out);
  CHECK(j["settings"]["intervals"] == "bootstrap");
  CHECK(j["settings"]["bootstrap"] == 50);
  CHECK(j["settings"]["replicates"] == 1);
  const Run none = run(cli(common + " --bootstrap 0"));
  REQUIRE(none.status == 0);
  CHECK(none.out.find("Sobol' intervals: none") != std::string::npos);
  j = read_json(out);
  for (const auto& rec : j["results"]) CHECK(rec["S_ci"][0].is_null());
  // Without Sobol' indices there is no interval method.
  REQUIRE(run(cli("sensitivity gantry_grinder --at X=0,Y=1500,Z=600 --method exact --quiet "
                  "--json " +
                  out))
              .status == 0);
  CHECK(read_json(out)["settings"]["intervals"].is_null());
}

TEST_CASE("sensitivity CLI: at order 1 the linear form gives the model's Sobol' indices") {
  // dx alone is evaluated as its linear form (offset + coefficients · errors); with dp beside it
  // (not linear) every output comes from the model's batch evaluation. The same design and seed:
  // the same indices to rounding.
  const auto dir = test::fresh_dir("cli_sensitivity_linear");
  const std::string a = (dir / "a.json").string(), b = (dir / "b.json").string();
  const std::string common =
      "sensitivity five_axis_ac --at X=100,Y=50,Z=-100,A=30,C=45 --method sobol --samples 2048 "
      "--quiet --json ";
  REQUIRE(run(cli(common + a + " --outputs dx,db")).status == 0);
  REQUIRE(run(cli(common + b + " --outputs dx,db,dp")).status == 0);
  const json ja = read_json(a), jb = read_json(b);
  std::map<std::string, double> model;
  for (const auto& rec : jb["results"])
    if (rec["output"] != "dp")
      model[rec["output"].get<std::string>() + "/" + rec["error"].get<std::string>()] = rec["S"];
  std::size_t compared = 0;
  for (const auto& rec : ja["results"]) {
    const std::string key =
        rec["output"].get<std::string>() + "/" + rec["error"].get<std::string>();
    CAPTURE(key);
    REQUIRE(model.count(key) == 1);
    CHECK(rec["S"].get<double>() == doctest::Approx(model[key]).epsilon(1e-12).scale(1));
    ++compared;
  }
  CHECK(compared == 2 * 43);
}

TEST_CASE("sensitivity CLI: the same seed gives the same numbers with 1 or 2 threads") {
  const auto dir = test::fresh_dir("cli_sensitivity_seed");
  const std::string a = (dir / "a.csv").string(), b = (dir / "b.csv").string();
  const std::string common =
      "sensitivity vmc_3axis --grid X=0:400:2,Y=-100,Z=-200 --samples 1024 --quiet ";
  REQUIRE(run(cli(common + "--seed 7 --threads 1 --csv " + a)).status == 0);
  REQUIRE(run(cli(common + "--seed 7 --threads 2 --csv " + b)).status == 0);
  std::string ta, tb;
  REQUIRE(read_file(a, ta));
  REQUIRE(read_file(b, tb));
  CHECK(ta == tb);
  CHECK(ta.rfind("Y_mm,X_mm,Z_mm,output,output_unit", 0) == 0);
  REQUIRE(run(cli(common + "--seed 8 --csv " + b)).status == 0);
  REQUIRE(read_file(b, tb));
  CHECK(ta != tb);
}

TEST_CASE("reliability CLI: exact one-sided reliability of the grinder equals the closed form") {
  const auto dir = test::fresh_dir("cli_reliability");
  const std::string out = (dir / "r.json").string();
  REQUIRE(run(cli("reliability gantry_grinder --grid X=0,Y=-1500:1500:5,Z=600:1400:5 "
                  "--tolerance dx=0.03mm --limit one-sided --quiet --json " +
                  out))
              .status == 0);
  const json j = read_json(out);
  REQUIRE(j["results"].size() == 25);
  double min = 1, mean = 0;
  for (const auto& rec : j["results"]) {
    const double y = rec["pose"]["Y"], z = rec["pose"]["Z"];
    double v = 0;
    for (const auto& [e, c] : grinder_dx_coefficients(y, z))
      v += c * c * grinder_sigma(e) * grinder_sigma(e);
    const double s = std::sqrt(v);
    const double expect = normal_cdf(0.03 / s);
    CHECK(rec["method"] == "exact");
    CHECK(rec["limit"] == "one-sided");
    CHECK(rec["reliability"].get<double>() == doctest::Approx(expect).epsilon(1e-12));
    // dR/dsigma_BX = phi(t/s) * (-t/s^2) * c^2 sigma / s.
    const double c = -z, sg = grinder_sigma("E_BX");
    CHECK(rec["dR_dsigma"]["E_BX"].get<double>() ==
          doctest::Approx(normal_pdf(0.03 / s) * (-0.03 / (s * s)) * c * c * sg / s).epsilon(1e-9));
    CHECK(rec["dR_dmu"]["E_BX"].get<double>() ==
          doctest::Approx(-normal_pdf(0.03 / s) * c / s).epsilon(1e-9));
    min = std::min(min, expect);
    mean += expect / 25;
  }
  const json& sum = j["summary"][0];
  CHECK(sum["min"].get<double>() == doctest::Approx(min).epsilon(1e-12));
  CHECK(sum["mean"].get<double>() == doctest::Approx(mean).epsilon(1e-12));
  CHECK(std::abs(sum["argmin"]["Y"].get<double>()) == 1500);
  CHECK(sum["argmin"]["Z"].get<double>() == 1400);
}

TEST_CASE("reliability CLI: every method agrees on a linear two-sided limit") {
  const auto dir = test::fresh_dir("cli_reliability_methods");
  std::map<std::string, json> res;
  for (const char* m : {"exact", "form", "is", "mc"}) {
    const std::string out = (dir / (std::string(m) + ".json")).string();
    REQUIRE(run(cli(std::string("reliability gantry_grinder --at X=250,Y=750,Z=1200 --tolerance "
                                "dy=25um --samples 200000 --quiet --method ") +
                    m + " --json " + out))
                .status == 0);
    res[m] = read_json(out)["results"][0];
  }
  const double exact = res["exact"]["reliability"];
  CHECK(res["form"]["reliability"].get<double>() == doctest::Approx(exact).epsilon(1e-9));
  CHECK(res["is"]["reliability"].get<double>() == doctest::Approx(exact).epsilon(1e-9));
  CHECK(res["mc"]["ci"][0].get<double>() <= exact);
  CHECK(res["mc"]["ci"][1].get<double>() >= exact);
  CHECK(res["mc"]["cov"].get<double>() > 0);
}

TEST_CASE("analysis CLI: bad arguments give one clear line, exit 2 and leave outputs untouched") {
  const auto dir = test::fresh_dir("cli_bad_args");
  const std::string out = (dir / "keep.json").string();
  { std::ofstream(out) << "previous"; }
  struct Case {
    std::string args, message;
  };
  const std::vector<Case> cases = {
      {"sensitivity gantry_grinder --at X=0,Y=0,Z=600 --set E_QQ=sigma:1um", "unknown error"},
      {"sensitivity gantry_grinder --grid X=0:1000:0,Y=0,Z=600", "count must be >= 1"},
      {"sensitivity gantry_grinder", "pose"},
      {"sensitivity gantry_grinder --at X=0,Y=0,Z=600 --samples 1",
       "--samples: '1' is out of range"},
      {"sensitivity gantry_grinder --at X=0,Y=0,Z=600 --outputs dq", "dq"},
      {"sensitivity gantry_grinder --at X=0,Y=0,Z=600 --replicates 1",
       "--replicates: '1' is out of range (allowed: a whole number from 2 to 1024)"},
      {"sensitivity gantry_grinder --at X=0,Y=0,Z=600 --replicates -2",
       "--replicates: '-2' is out of range"},
      {"sensitivity gantry_grinder --at X=0,Y=0,Z=600 --replicates 4 --bootstrap 10",
       "give one of them"},
      {"sensitivity gantry_grinder --at X=0,Y=0,Z=600 --bootstrap -1",
       "--bootstrap: '-1' is out of range"},
      {"sensitivity gantry_grinder --at X=0,Y=0,Z=600 --samples 1001",
       "--samples 1001 must be a multiple of --replicates 4"},
      {"sensitivity gantry_grinder --at X=0,Y=0,Z=600 --seed 0", "--seed 0"},
      {"reliability gantry_grinder --at X=0,Y=0,Z=600 --tolerance dx=0mm", "dx"},
      {"reliability gantry_grinder --at X=0,Y=0,Z=600 --tolerance dx=-1um", "dx"},
      {"reliability gantry_grinder --at X=0,Y=0,Z=600", "--tolerance"},
      {"reliability gantry_grinder --at X=0,Y=0,Z=600 --tolerance dx=1um --limit radial", "radial"},
      {"reliability gantry_grinder --at X=0,Y=0,Z=600 --tolerance dx=1um --method magic", "magic"},
      {"reliability gantry_grinder --at W=3 --tolerance dx=1um", "W"},
  };
  for (const auto& c : cases) {
    CAPTURE(c.args);
    const Run r = run(cli(c.args + " --quiet --json " + out));
    CHECK(r.status == 2);
    CHECK(r.out.find(c.message) != std::string::npos);
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
    std::string text;
    REQUIRE(read_file(out, text));
    CHECK(text == "previous");
  }
}

TEST_CASE("analysis CLI: a machine that is not built in is compiled at run time and cached") {
  const auto dir = test::fresh_dir("cli_runtime_compile");
  std::string text;
  REQUIRE(read_file(test::machine_path("two_axis"), text));
  const std::string machine = (dir / "two_axis_long_tool.yaml").string();
  { std::ofstream(machine) << text << "\n# a user's copy\n"; }
  const std::string env = "WEILGEN_CACHE_DIR=" + (dir / "cache").string() + " ";
  const std::string args =
      "sensitivity " + machine + " --at Y=100,A=30 --method local --param tool_length=250 --json ";
  const Run first = run(env + cli(args + (dir / "c.json").string()));
  REQUIRE(first.status == 0);
  CHECK(first.out.find("compiling model two_axis") != std::string::npos);
  const Run second = run(env + cli(args + (dir / "c2.json").string()));
  REQUIRE(second.status == 0);
  CHECK(second.out.find("compiling") == std::string::npos);
  const Run numeric = run(cli(args + (dir / "n.json").string() + " --engine numeric"));
  REQUIRE(numeric.status == 0);
  const json c = read_json((dir / "c.json").string()), n = read_json((dir / "n.json").string());
  CHECK(c["model"]["engine"] == "compiled");
  CHECK(n["model"]["engine"] == "numeric chain");
  REQUIRE(c["results"].size() == n["results"].size());
  for (std::size_t i = 0; i < c["results"].size(); ++i) {
    if (c["results"][i]["output"] == "dp") continue;  // no local coefficient for the norm
    const double a = c["results"][i]["coefficient"], b = n["results"][i]["coefficient"];
    CHECK(a == doctest::Approx(b).epsilon(1e-8).scale(1.0));
  }
  // The tool length enters: dx per E_BY is tool_length cos(A) (two_axis closed form).
  for (const auto& rec : c["results"])
    if (rec["output"] == "dx" && rec["error"] == "E_BY")
      CHECK(rec["coefficient"].get<double>() ==
            doctest::Approx(250 * std::cos(30 * M_PI / 180)).epsilon(1e-12));
}

TEST_CASE("analysis CLI: --plot draws PNG and SVG through gnuplot") {
  const auto dir = test::fresh_dir("cli_plot");
  const std::string png = (dir / "s.png").string(), svg = (dir / "r.svg").string();
  REQUIRE(run(cli("sensitivity gantry_grinder --at X=0,Y=750,Z=1000 --outputs dx,dy --samples "
                  "1024 --quiet --plot " +
                  png))
              .status == 0);
  REQUIRE(run(cli("reliability gantry_grinder --grid X=0,Y=-1500:1500:5,Z=600:1400:5 "
                  "--tolerance dx=0.03mm --quiet --plot " +
                  svg))
              .status == 0);
  std::string p, s;
  REQUIRE(read_file(png, p));
  REQUIRE(read_file(svg, s));
  CHECK(p.substr(0, 8) == std::string("\x89PNG\r\n\x1a\n", 8));
  CHECK(s.find("<svg") != std::string::npos);
}

TEST_CASE(
    "allocate CLI: Wang & Yuan 2021's x-direction procedure, and its saved tolerances read back") {
  const auto dir = test::fresh_dir("cli_allocate");
  const std::string json_path = (dir / "a.json").string(), tol = (dir / "tol.yaml").string();
  const std::string grid =
      "--grid X=0,Y=-1500:1500:5,Z=600:1400:5 --tolerance dx=0.03mm "
      "--limit one-sided ";
  const Run r = run(cli("allocate gantry_grinder " + grid +
                        "--step 0.005/6mm --step 0.005/6000rad --step E_C0X=0.005/3000rad "
                        "--rank raw --cost-aware --quiet --json " +
                        json_path + " --save-tolerances " + tol));
  REQUIRE(r.status == 0);
  const json j = read_json(json_path);
  // The raw (per-unit) ranking picks exactly Wang & Yuan 2021's errors: eps_yx, eps_zx, eps_zz,
  // S_xy.
  std::set<std::string> chosen;
  for (const auto& e : j["chosen"]) chosen.insert(e.get<std::string>());
  CHECK(chosen == std::set<std::string>{"E_BX", "E_CX", "E_CZ", "E_C0X"});
  REQUIRE(j["steps"].size() == 5);  // start + 4 steps
  const json& last = j["steps"][4];
  CHECK(last["stddev"]["E_BX"].get<double>() == doctest::Approx(0.04 / 6000).epsilon(1e-12));
  CHECK(last["stddev"]["E_C0X"].get<double>() == doctest::Approx(0.01 / 3000).epsilon(1e-12));
  CHECK(last["stddev"]["E_XX"].get<double>() == doctest::Approx(0.05 / 6).epsilon(1e-12));
  CHECK(last["outputs"][0]["min"].get<double>() >= 0.95);
  CHECK(last["outputs"][0]["mean"].get<double>() >= 0.97);
  CHECK(j["steps"][3]["outputs"][0]["min"].get<double>() < 0.95);  // 3 steps were not enough
  CHECK(j["cost_aware"]["met"] == true);
  CHECK(j["cost_aware"]["cost"].get<double>() < j["cost_aware"]["cost_step"].get<double>());
  // The saved tolerances reproduce the final step's reliability.
  const std::string rj = (dir / "r.json").string();
  REQUIRE(run(cli("reliability gantry_grinder " + grid + "--tolerances " + tol +
                  " --quiet --json " + rj))
              .status == 0);
  const json rel = read_json(rj);
  CHECK(rel["summary"][0]["min"].get<double>() ==
        doctest::Approx(last["outputs"][0]["min"].get<double>()).epsilon(1e-9));
}
