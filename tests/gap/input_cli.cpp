// Gap diagnosis, bad input: angles in radians, covariates with gaps, held-out splits, bad data
// with a message, and the CLI's JSON schema, report and bad flags.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "gap/fixtures.hpp"
#include "weilgen/base/constants.hpp"

using namespace weilgen;
using namespace weilgen::gap_test;

namespace {

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}

MeasurementTable read_for(const std::string& machine, const std::string& csv) {
  return parse_measurements(
      csv, "r.csv", machine_read_options(test::builtin_model(machine)->description(), false));
}

}  // namespace

TEST_CASE("gap input: a rotary column in radians is refused when it reads as whole degrees") {
  // C at 0, 30, ..., 330 deg written in radians (6 decimals), five_axis_ac's C in deg over ±360.
  std::vector<std::string> rad;
  for (int k = 0; k < 12; ++k) {
    std::ostringstream v;
    v.precision(6);
    v << std::fixed << k * 30 * kPi / 180;
    rad.push_back(v.str());
  }
  // The largest value (5.759587 rad = 330 deg) is on line 13 (the first A block), column 15.
  CHECK(error_of([&] { read_for("five_axis_ac", five_axis_rows(rad)); }) ==
        "r.csv:13:15: column 'C' looks like radians: every value lies within ±2π (0 .. 5.75959) "
        "while C is in deg over [-360, 360] deg, and read as radians they are whole degrees "
        "(5.75959 rad = 330 deg); write it in degrees (times 180/π)");
  // The reader is the one home: identify and gap read the data through it (CLI: hostile_cli).
  // The same values in degrees are read without a word.
  std::vector<std::string> deg;
  for (int k = 0; k < 12; ++k) deg.push_back(std::to_string(30 * k));
  const MeasurementTable ok = read_for("five_axis_ac", five_axis_rows(deg));
  CHECK(ok.warnings.empty());
}

TEST_CASE("gap input: a short sweep within ±2π deg is a warning, not an error") {
  // 0, 0.5, ..., 5.5 deg: possible in degrees (a short sweep) and in radians (0 .. 315 deg);
  // read as radians they are not whole degrees, so the range alone speaks: a located warning.
  std::vector<std::string> c;
  for (int k = 0; k < 12; ++k) c.push_back(std::to_string(0.5 * k));
  const MeasurementTable t = read_for("five_axis_ac", five_axis_rows(c));
  REQUIRE(t.warnings.size() == 1);
  CHECK(t.warnings[0] ==
        "r.csv:13:15: warning: column 'C' looks like radians: every value lies within ±2π (0 .. "
        "5.5) while C is in deg over [-360, 360] deg, so as degrees the data turn C by only 5.5 "
        "deg; if they are radians, write them in degrees");
  // Whole numbers as written (0, 1, ..., 5 deg) are never an error, whatever they read as.
  c.clear();
  for (int k = 0; k < 12; ++k) c.push_back(std::to_string(k % 6));
  CHECK(read_for("five_axis_ac", five_axis_rows(c)).warnings.size() == 1);
  // A value beyond what radians within the travel allow (A = 2.5 rad = 143 deg > 110 deg): no
  // word about radians.
  std::string a = "X,Y,Z,A,C,dx_um\n";
  for (int k = 0; k < 12; ++k) a += "10,0,-100," + std::to_string(0.25 * k) + ",0,1\n";
  CHECK(read_for("five_axis_ac", a).warnings.empty());
  // Fewer than 3 distinct values, or a machine axis in radians: no check.
  std::string two = "X,Y,Z,A,C,dx_um\n";
  for (int k = 0; k < 12; ++k)
    two += "10,0,-100,0," + std::string(k % 2 ? "1.570796" : "0") + ",1\n";
  CHECK(read_for("five_axis_ac", two).warnings.empty());
}

TEST_CASE("gap input: a ballbar angle in radians is refused") {
  std::string s = "# plane: XY\n# radius: 150 mm\nangle_deg,dr_um\n";
  for (int k = 0; k < 36; ++k)
    s += std::to_string(k * 10 * kPi / 180) + "," + std::to_string(0.1 * k) + "\n";
  const std::string e = error_of([&] { parse_measurements(s, "b.csv"); });
  CHECK(e.rfind("b.csv:39:1: column 'angle_deg' looks like radians", 0) == 0);
  CHECK(e.find("(6.10865 rad = 350 deg)") != std::string::npos);
}

TEST_CASE("gap input: a covariate with gaps names the file, the first empty cell and every row") {
  const Description& desc = test::builtin_model("vmc_3axis")->description();
  auto gap_error = [&](const std::string& csv) {
    return error_of([&] { gap_data(parse_measurements(csv, "b.csv"), desc); });
  };
  auto rows = [](const std::string& column, const std::vector<int>& empty, int n) {
    std::string s = "X,Y,Z," + column + ",dx_um\n";
    for (int i = 0; i < n; ++i) {
      const bool gap = std::find(empty.begin(), empty.end(), i) != empty.end();
      s += std::to_string(i * 10) + ",0,0," + (gap ? "" : std::to_string(100 + 7 * i)) + ",1\n";
    }
    return s;
  };
  CHECK(gap_error(rows("rpm", {3}, 12)) ==
        "b.csv:5:8: column 'rpm' is empty in 1 row where a deviation is measured (line 5): the "
        "diagnosis needs it in every row; fill or drop those rows");
  // Beyond ten rows, the count of the others.
  std::vector<int> many;
  for (int i = 2; i < 16; ++i) many.push_back(i);
  CHECK(gap_error(rows("T_table", many, 30)) ==
        "b.csv:4:8: column 'T_table' is empty in 14 rows where a deviation is measured (lines 4, "
        "5, 6, 7, 8, 9, 10, 11, 12, 13 and 4 more): the diagnosis needs it in every row; fill or "
        "drop those rows");
  CHECK(gap_error(rows("t_s", {0, 11}, 12)) ==
        "b.csv:2:7: column 't_s' is empty in 2 rows where a deviation is measured (lines 2, 13): "
        "the diagnosis needs it in every row; fill or drop those rows");
  // A cycle or a direction with gaps too (neither needs to vary).
  CHECK(gap_error(rows("cycle", {5}, 12)) ==
        "b.csv:7:8: column 'cycle' is empty in 1 row where a deviation is measured (line 7): the "
        "diagnosis needs it in every row; fill or drop those rows");
  std::string dir = "X,Y,Z,dir_X,dx_um\n";
  for (int i = 0; i < 12; ++i)
    dir += std::to_string(i * 10) + ",0,0," + (i == 8 ? "" : "1") + ",1\n";
  CHECK(gap_error(dir) ==
        "b.csv:10:8: column 'dir_X' is empty in 1 row where a deviation is measured (line 10): "
        "the diagnosis needs it in every row; fill or drop those rows");
  // A row that measures nothing may leave the covariate empty.
  std::string unmeasured = rows("rpm", {}, 12) + "5,0,0,,\n";
  CHECK_NOTHROW(gap_data(parse_measurements(unmeasured, "b.csv"), desc));
}

TEST_CASE("gap: held-out splits never share an observation and cover every one once") {
  const MeasurementTable t = parse_measurements(synth(7, none), "g.csv");
  const GapData d = gap_data(t, vmc()->description());
  for (const char* scheme : {"cycle:4", "time:5", "space:X:3"}) {
    const std::vector<Split> splits = make_splits(d, *parse_holdout(scheme), 20);
    std::vector<int> held(d.points.observations.size(), 0);
    for (const Split& s : splits) {
      std::vector<bool> in_train(held.size(), false);
      for (std::size_t i : s.train) in_train[i] = true;
      for (std::size_t i : s.test) {
        CHECK_FALSE(in_train[i]);
        ++held[i];
      }
      CHECK(s.train.size() + s.test.size() == held.size());
    }
    for (int h : held) CHECK(h == 1);
  }
  // Cycle folds keep a cycle together.
  const std::vector<Split> by_cycle = make_splits(d, *parse_holdout("cycle:4"), 20);
  for (const Split& s : by_cycle) {
    std::set<double> cycles;
    for (std::size_t i : s.test) cycles.insert(d.cycle[d.points.observations[i].row]);
    CHECK(cycles.size() == 1);
  }
}

TEST_CASE("gap: bad data get a message, not a verdict") {
  const Description& desc = vmc()->description();
  auto error_of = [&](const std::string& csv, const std::string& holdout = "auto") {
    try {
      const MeasurementTable t = parse_measurements(csv, "b.csv");
      const GapData d = gap_data(t, desc);
      const auto h = parse_holdout(holdout);
      make_splits(d, h ? *h : default_holdout(d), 20);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK(error_of("X,Y,Z,t_s\n0,0,0,1\n") ==
        "b.csv:1: no deviation column (dx_um, dy_um, dz_um, da_urad, db_urad, dc_urad; "
        "columns: X, Y, Z, t_s)");
  std::string constant = "X,Y,Z,T_a,dx_um\n";
  for (int i = 0; i < 12; ++i) constant += std::to_string(i * 10) + ",0,0,21.5,1\n";
  CHECK(error_of(constant) ==
        "b.csv:1: column 'T_a' is constant (21.5 degC): it cannot explain anything; drop the "
        "column");
  std::string nan = "X,Y,Z,T_a,dx_um\n";
  for (int i = 0; i < 12; ++i)
    nan += std::to_string(i * 10) + ",0,0," + (i == 4 || i == 7 ? "" : "21." + std::to_string(i)) +
           ",1\n";
  CHECK(
      error_of(nan) ==
      "b.csv:6:8: column 'T_a' is empty in 2 rows where a deviation is measured (lines 6, 9): the "
      "diagnosis needs it in every row; fill or drop those rows");
  CHECK(error_of("X,Y,Z,dx_um\n0,0,0,1\n1,0,0,2\n") ==
        "b.csv: only 2 observations: the diagnosis needs at least 10");
  std::string few = "X,Y,Z,cycle,dx_um\n";
  for (int i = 0; i < 12; ++i)
    few += std::to_string(i * 10) + ",0,0," + (i < 11 ? "1" : "2") + ",1\n";
  CHECK(error_of(few, "cycle") ==
        "b.csv: --holdout cycle:5: too few observations: a training part has 1, the model needs at "
        "least 20");
  CHECK(error_of("Y,Z,dx_um\n0,0,1\n") ==
        "b.csv:1: missing column 'X' (give the coordinate of a pose the data do not vary with "
        "--at X=VALUE; columns: Y, Z, dx_um)");
  // A rotary coordinate in radians, a covariate with gaps: the cases above.
  CHECK_THROWS_WITH_AS(parse_holdout("weekly"),
                       "--holdout \"weekly\": unknown scheme 'weekly' (expected cycle[:K], "
                       "time[:K], space[:AXIS][:K], forward[:FRACTION] or auto)",
                       std::invalid_argument);
}

TEST_CASE("gap CLI: JSON schema, report, and bad flags or data") {
  const std::filesystem::path dir = test::fresh_dir("gap_cli");
  const std::string data = (dir / "rev.csv").string();
  std::ofstream(data) << synth(9, [](const Row& w) {
    return std::array<double, 3>{1.5 * w.dir_X, 0, 0};
  });
  const std::string json = (dir / "gap.json").string(), md = (dir / "gap.md").string();
  const test::Run ok = test::run(test::cli("gap vmc_3axis -q --pdge poly:2 --data " + data +
                                           " --json " + json + " --report " + md));
  REQUIRE_MESSAGE(ok.status == 0, ok.out);
  CHECK(ok.out.find("Verdict: reversal") != std::string::npos);
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  CHECK(j["verdict"]["effect"] == "reversal");
  CHECK(j["verdict"]["explanation"][0] == "reversal");
  CHECK(j["baseline"]["holdout"] == "cycle:4");
  CHECK(j["noise_floor_source"] == "repeats");
  CHECK(j["noise_floor_um"].get<double>() == doctest::Approx(0.5).epsilon(0.2));
  REQUIRE(j["effects"].size() >= 5);
  for (const char* key : {"name", "params", "heldout_rms_before_um", "heldout_rms_after_um",
                          "shrink_pct", "significant", "p_value"})
    CHECK(j["effects"][0].contains(key));
  CHECK(j["effects"][0]["name"] == "reversal");
  CHECK(std::abs(j["effects"][0]["params"]["reversal_um"].get<double>()) ==
        doctest::Approx(3.0).epsilon(0.1));
  CHECK(j["where"][0]["output"] == "dx");
  CHECK(std::filesystem::exists(md));

  const test::Run bad1 =
      test::run(test::cli("gap vmc_3axis -q --data " + data + " --holdout weekly"));
  CHECK(bad1.status == 2);
  const test::Run bad2 =
      test::run(test::cli("gap vmc_3axis -q --data " + data + " --effects gremlins"));
  CHECK(bad2.status == 2);
  CHECK(bad2.out.find("unknown effect 'gremlins'") != std::string::npos);
  const std::string flat = (dir / "flat.csv").string();
  std::string text = "X,Y,Z,T_a,dx_um\n";
  for (int i = 0; i < 12; ++i) text += std::to_string(i * 10) + ",0,0,21.5,1\n";
  std::ofstream(flat) << text;
  const std::string never = (dir / "never.json").string();
  const test::Run bad3 =
      test::run(test::cli("gap vmc_3axis -q --data " + flat + " --json " + never));
  CHECK(bad3.status == 3);
  CHECK(bad3.out.find("flat.csv:1: column 'T_a' is constant") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(never));
}
