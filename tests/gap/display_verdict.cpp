// Gap diagnosis, the display and the verdict: rejected candidates and indistinct shapes, plots
// along every coordinate that varies, where the residual lies on a rotary machine and in a
// diagonal run, and the verdict without a significant baseline gap.
#include <doctest/doctest.h>

#include "gap/fixtures.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/report/gap_document.hpp"

using namespace weilgen;
using namespace weilgen::gap_test;

namespace {

// A diagnosis result by hand: one measured output dx, a rejected tool offset with the absurd
// fit least squares made of noise, a significant period the data cannot tell from another shape.
GapResult hand_result(std::size_t observations) {
  GapResult r;
  r.holdout = "time:5";
  r.holdout_reason = "given";
  r.observations = observations;
  r.count[0] = observations;
  r.noise.sigma_um = 0.5;
  r.noise.source = "small-scale";
  r.verdict.kind = GapVerdict::Kind::Unexplained;
  r.verdict.reason = "test";
  EffectFit tool;
  tool.name = "tool_offset";
  tool.summary = "tool offset -2.56e+05 mm (tool_length 120 -> -2.56e+05 mm)";
  tool.params["tool_offset_mm"] = -2.56e5;
  tool.p_value = 0.7;
  tool.significant = false;
  EffectFit period;
  period.name = "periodic";
  period.summary = "periodic E_XX of X: period 37 mm, 2.1 µm";
  period.p_value = 1e-4;
  period.significant = true;
  period.shape_dof_free = 2;
  period.shape_dof_used = 3;
  period.distinguishable = false;
  r.effects = {period, tool};
  for (std::size_t i = 0; i < observations; ++i) {
    r.residual_before.push_back(1 + 0.1 * static_cast<double>(i % 7));
    r.residual_after.push_back(0.5);
  }
  return r;
}

}  // namespace

TEST_CASE("gap display: a rejected candidate's fit is not printed, an indistinct shape says why") {
  const auto model = test::builtin_model("vmc_3axis");
  const GapResult r = hand_result(20);
  for (bool markdown : {false, true}) {
    const std::string text = gap_text(r, *model, "d.csv", markdown);
    INFO(text);
    CHECK(text.find("2.56e+05") == std::string::npos);
    CHECK(text.find("not significant") != std::string::npos);
    CHECK(text.find("periodic E_XX of X: period 37 mm, 2.1 µm (needs 3 shape degrees of freedom "
                    "where the data leave 2: any shape fits)") != std::string::npos);
    CHECK(text.find("of the 2") == std::string::npos);
  }
  // The CSV's summary column is read by people too.
  const std::string csv = gap_csv(r, "d.csv");
  INFO(csv);
  CHECK(csv.find("2.56e+05") == std::string::npos);
  CHECK(csv.find("not significant") != std::string::npos);
  // The JSON keeps every candidate's numbers (params) for a program that wants them.
  CHECK(gap_json(r, *model, "d.csv")["effects"][1]["params"]["tool_offset_mm"] == -2.56e5);
}

TEST_CASE("gap display: --plot draws every coordinate that varies, rotary ones in deg, no other") {
  // five_axis_ac with X, Y, Z fixed and A, C turning: the residual along A and C (deg) and t,
  // never along X, Y or Z; each with the baseline, the explanation and the noise floor.
  std::vector<std::string> c;
  for (int k = 0; k < 8; ++k) c.push_back(std::to_string(45 * k));
  const Description& desc = test::builtin_model("five_axis_ac")->description();
  const GapData d = gap_data(parse_measurements(five_axis_rows(c), "r.csv"), desc);
  GapResult r = hand_result(d.points.observations.size());
  r.explanation = {r.effects[0]};
  GapRegion speed;  // a significant dimension: drawn too, in its unit
  speed.by = "rpm";
  speed.significant = true;
  r.where = {speed};
  std::vector<std::string> stems;
  for (const GapPlot& p : gap_plots(d, r)) stems.push_back(p.stem);
  CHECK(stems == std::vector<std::string>{"residual_t_s", "residual_A", "residual_C",
                                          "residual_rpm", "effects"});
  for (const GapPlot& p : gap_plots(d, r)) {
    if (p.stem == "effects") continue;  // the bar chart of the candidates
    const std::string x = std::get<LinePlot>(p.panels.at(0)).xlabel;
    if (p.stem == "residual_t_s") CHECK(x == "t (s)");
    if (p.stem == "residual_A") CHECK(x == "A (deg)");
    if (p.stem == "residual_rpm") CHECK(x == "rpm (1/min)");
    if (p.stem != "residual_C") continue;
    const LinePlot& lp = std::get<LinePlot>(p.panels.at(0));
    CHECK(lp.xlabel == "C (deg)");
    CHECK(lp.x == std::vector<double>{0, 45, 90, 135, 180, 225, 270, 315});  // one bin each
    REQUIRE(lp.lines.size() == 3);
    CHECK(lp.lines[0].first == "baseline");
    CHECK(lp.lines[1].first == "with the explanation");
    CHECK(lp.lines[2].first == "noise floor");
    CHECK(lp.lines[2].second == std::vector<double>(8, 0.5));
    for (double v : lp.lines[1].second) CHECK(v == doctest::Approx(0.5));
  }
  // Nothing accepted: no "after" line drawn over the baseline.
  r.explanation.clear();
  const std::vector<GapPlot> plain = gap_plots(d, r);
  const LinePlot& none = std::get<LinePlot>(plain.at(2).panels.at(0));
  REQUIRE(none.lines.size() == 2);
  CHECK(none.lines[1].first == "noise floor");
}

namespace {

// vmc_3axis along the diagonal (X 0..500, Y -350..-50, Z -250..-50 together), back and forth in
// `cycles` cycles, so dir_X, dir_Y and dir_Z are one column; deviation = `effect` + N(0, 0.5²).
// `line`: an ISO line run along X instead (Y, Z fixed; dir_Y, dir_Z constant).
std::string diagonal(std::uint32_t seed, int cycles,
                     const std::function<double(double dir, double s)>& effect, bool line = false) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0, 1);
  std::ostringstream csv;
  csv << "X,Y,Z,dir_X,dir_Y,dir_Z,cycle,t_s,dx_um,dy_um,dz_um\n";
  double t = 0;
  for (int cy = 1; cy <= cycles; ++cy)
    for (int k = 0; k < 24; ++k) {
      const bool up = k < 12;
      const double s = (up ? k : 23 - k) / 11.0, dir = up ? 1 : -1;
      const double m = line ? 0 : 1, other = line ? 1 : dir;
      csv << 500 * s << "," << -350 + 300 * s * m << "," << -250 + 200 * s * m << "," << dir << ","
          << other << "," << other << "," << cy << "," << t;
      for (int o = 0; o < 3; ++o) csv << "," << (o == 0 ? effect(dir, s) : 0) + 0.5 * n01(rng);
      csv << "\n";
      t += 60;
    }
  return csv.str();
}

}  // namespace

TEST_CASE("gap where: identical dimensions (dir_X = dir_Y = dir_Z on a diagonal) once") {
  const GapResult r = diagnose(diagonal(5, 5, [](double dir, double) { return 2.0 * dir; }),
                               "vmc_3axis", "cycle:5");
  std::size_t dirs = 0;
  for (const GapRegion& g : r.where) {
    if (g.by.rfind("dir_", 0) != 0 || g.source != "residual" || g.output != "dx") continue;
    ++dirs;
    INFO(g.by);
    CHECK(g.same_as.size() == 2);
    CHECK(g.unit.empty());
  }
  CHECK(dirs == 1);
  REQUIRE_FALSE(r.where.empty());
  CHECK(r.where.front().by.rfind("dir_", 0) == 0);
  CHECK(r.where.front().output == "dx");
}

TEST_CASE("gap where: on a rotary table the bins along A and C are in deg") {
  // five_axis_ac, the tool over a point off the table's centre, A and C turning, C approached
  // from both sides with 8 µrad of lost motion (a reversal of C reaches dx and dy rotated).
  const auto model = test::builtin_model("five_axis_ac");
  const Description& desc = model->description();
  NumericChain chain(desc);
  std::mt19937 rng(11);
  std::normal_distribution<double> n01(0, 1);
  const std::vector<double> zero(desc.errors.size(), 0.0);
  const double half_deg = 0.5 * 8e-6 * 180 / kPi;
  std::ostringstream csv;
  csv << "X,Y,Z,A,C,dir_C,cycle,t_s,dx_um,dy_um,dz_um\n";
  double t = 0;
  for (int cy = 1; cy <= 3; ++cy)
    for (double A : {-30.0, 0.0, 30.0})
      for (int k = 0; k < 16; ++k) {
        const bool up = k < 8;
        const double C = 45.0 * (up ? k : 15 - k), dir = up ? 1 : -1;
        // Coordinates in the order of desc.axes(): X, Z, Y, A, C on five_axis_ac.
        std::vector<double> q, actual;
        for (int b : desc.axes()) {
          const std::string& n = desc.bodies[static_cast<std::size_t>(b)].joint.coordinate;
          q.push_back(n == "X" ? 120 : n == "Y" ? -60 : n == "Z" ? -150 : n == "A" ? A : C);
          actual.push_back(q.back() - (n == "C" ? dir * half_deg : 0));
        }
        const Eigen::Matrix4d real = chain.tool_in_workpiece(actual, zero);
        const Eigen::Matrix4d nominal = chain.tool_in_workpiece(q, zero);
        csv << "120,-60,-150," << A << "," << C << "," << dir << "," << cy << "," << t;
        for (int o = 0; o < 3; ++o)
          csv << "," << 1000 * (real(o, 3) - nominal(o, 3)) + 0.3 * n01(rng);
        csv << "\n";
        t += 30;
      }
  const GapResult r = diagnose(csv.str(), "five_axis_ac", "cycle:3");
  std::size_t rotary = 0;
  for (const GapRegion& g : r.where) {
    if (g.by != "A" && g.by != "C") continue;
    ++rotary;
    INFO(g.by << " " << g.output << " " << g.from << " .. " << g.to << " " << g.unit);
    CHECK(g.unit == "deg");
    const double lo = g.by == "A" ? -30 : 0, hi = g.by == "A" ? 30 : 315;
    CHECK(g.from >= lo);
    CHECK(g.to <= hi);
    CHECK(g.from <= g.to);
  }
  CHECK(rotary >= 2);  // A and C in at least one output each
  CHECK(r.verdict.names("reversal"));
  REQUIRE_FALSE(r.where.empty());
  CHECK(r.where.front().by == "dir_C");
}

TEST_CASE("gap verdict: no significant baseline gap is none, and the near candidates are named") {
  // Effect-free diagonal and line runs (the case: a reversal accepted on an effect-free
  // line set at baseline p = 0.53): the baseline's held-out gap decides (docs/gap.md, "Verdict").
  int none = 0, named_close = 0;
  for (std::uint32_t seed = 0; seed < 12; ++seed) {
    const GapResult r =
        diagnose(diagonal(
                     100 + seed, 5, [](double, double) { return 0.0; }, seed % 2 == 1),
                 "vmc_3axis", "cycle:5");
    INFO("seed " << seed << ": " << r.verdict.str() << " (" << r.verdict.reason << "), baseline p "
                 << r.baseline.p_value);
    if (r.baseline.p_value < 0.01) continue;
    CHECK(r.verdict.kind == GapVerdict::Kind::None);
    CHECK(r.explanation.empty());
    ++none;
    for (const EffectFit& e : r.effects)
      if (e.p_value < 0.5) {
        CHECK(r.verdict.reason.find("closest candidates: ") != std::string::npos);
        CHECK(r.verdict.reason.find(e.name + " (p = ") != std::string::npos);
        ++named_close;
      }
  }
  CHECK(none >= 10);  // the test is not vacuous: the baseline gap is at the floor
  MESSAGE("near candidates named: " << named_close);
}

TEST_CASE(
    "gap verdict: a candidate significant in training, with no held-out gap, is named close") {
  // A 0.4 µm reversal of X on a diagonal run (noise 0.5 µm): the training F test sees it
  // (corrected p 7.6e-5), the held-out gap does not (p 0.35 with the regional noise floor):
  // none, and the reason says why.
  const GapResult r = diagnose(diagonal(200, 5, [](double dir, double) { return 0.2 * dir; }),
                               "vmc_3axis", "cycle:5");
  INFO(r.verdict.reason);
  CHECK(r.baseline.p_value > 0.1);
  CHECK(r.verdict.kind == GapVerdict::Kind::None);
  CHECK(r.verdict.reason.find("closest candidates: reversal (p = ") != std::string::npos);
  CHECK(r.verdict.reason.find("significant in training but not needed") != std::string::npos);
}

// Issue 14 item 6: with no significant baseline gap, a candidate accepted by the overwhelming-
// evidence exception (corrected p < alpha^3) used to be judged by the share of the baseline's
// "excess" it removes — an excess at the noise floor — and read "unexplained: the accepted
// effects remove only 11 % of the excess". The accepted effect stands when nothing significant
// remains (decide_verdict).
TEST_CASE("gap verdict: an effect accepted without a significant baseline gap is not unexplained") {
  for (const auto& b_seed : std::vector<std::pair<double, std::uint32_t>>{
           {0.2, 202}, {0.3, 200}, {0.3, 203}, {0.4, 203}}) {
    const double b = b_seed.first;  // a plain pair: clang < 16 cannot capture a structured binding
    const std::uint32_t seed = b_seed.second;
    const double size = b;
    const GapResult r =
        diagnose(diagonal(seed, 5, [size](double dir, double) { return size * dir; }), "vmc_3axis",
                 "cycle:5");
    INFO("reversal " << 2 * b << " um, seed " << seed << ": baseline p " << r.baseline.p_value
                     << ", " << r.verdict.str() << " (" << r.verdict.reason << ")");
    REQUIRE(r.baseline.p_value > 0.01);
    CHECK(r.verdict.kind != GapVerdict::Kind::Unexplained);
    CHECK(r.verdict.names("reversal"));
  }
}
