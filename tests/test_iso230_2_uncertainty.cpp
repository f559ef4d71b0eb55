// The measurement uncertainty of the ISO 230-2 figures (weilgen/measure/iso230_2_uncertainty.hpp,
// docs/iso230-2.md "Measurement uncertainty"): the hand-worked budget of the small example, the
// Monte Carlo propagation of GUM Supplement 1 against the linearised budget on a synthetic run
// whose extremes do not compete, the ISO 14253-1 decisions, the budget file and the CLI.
#include <doctest/doctest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "test_support.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/measure/iso230_2_study.hpp"
#include "weilgen/measure/iso230_2_uncertainty.hpp"
#include "weilgen/report/iso230_2_document.hpp"
#include "weilgen/report/iso230_2_html.hpp"

using namespace weilgen;
using nlohmann::json;
using test::cli;
using test::run;

namespace {

std::string small_csv() {
  return std::string(WEILGEN_SOURCE_DIR) + "/examples/data/iso230_2_small.csv";
}

const UncertaintyContribution* contribution(const UncertaintyResult& r, const std::string& name) {
  for (const auto& c : r.contributions)
    if (c.name == name) return &c;
  return nullptr;
}

// 11 targets over 1000 mm, 5 bidirectional cycles: a slope of 20 um/m (the extremes of E, M and
// A are the ends, far apart), a reversal of 1 um with 3 um at 500 mm (B there), noise 0.3 um
// with 1.2 um at 800 mm forward (R there); air compensated by the instrument, the material at
// 21.5 degC normalised by it with alpha 11.7.
std::string synthetic_run() {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> z(0, 1);
  std::ostringstream s;
  s << "# axis: X\n# air_compensation: instrument\n# material_compensation: instrument\n"
    << "# expansion_ppm_per_K: 11.7\n# material_temperature_C: 21.5\nX,dir,cycle,dx_um\n";
  for (int j = 1; j <= 5; ++j)
    for (int d : {1, -1})
      for (int i = 0; i <= 10; ++i) {
        const double P = 100.0 * i;
        const double x =
            0.02 * P + d * (P == 500 ? 1.5 : 0.5) + (P == 800 && d > 0 ? 1.2 : 0.3) * z(rng);
        s << P << "," << d << "," << j << "," << x << "\n";
      }
  return s.str();
}

}  // namespace

TEST_CASE("uncertainty: the hand-worked budget of the small example (E, B, R)") {
  // docs/iso230-2.md, "Measurement uncertainty": x-bar up 2 6 3, down -1 4 7; s up 1 2 3,
  // down 1 0 2; n = 3; targets 0, 100, 200 mm, datum 0. Budget: the instrument 1 um/m (k = 2),
  // an environmental variation of 0.6 um, nothing else.
  //   E = 7 - (-1) = 8: x-bar down at 200 mm minus x-bar down at 0 mm.
  //     instrument  c = 0.2 m,  u = 0.5 um/m             -> 0.1 um
  //     EVE         c = sqrt 2, u = 0.6/(2 sqrt 3) um    -> 0.244949 um
  //     type A      sqrt(2^2/3 + 1^2/3)                  =  1.290994 um
  //     u = sqrt(0.01 + 0.06 + 5/3) = 1.317826, U = 2.635653 um
  //   B = |3 - 7| = 4 at 200 mm: type A sqrt(9/3 + 4/3) = 2.081666, EVE 0.244949;
  //     the instrument cancels (one target): u = 2.096028, U = 4.192056 um
  //   R = R_200 = 2 s up + 2 s down + |B| = 14: type A of the means as B's; of the s,
  //     c4(3) = 0.886227, sqrt(1 - c4^2) = 0.463251: (2 * 3 * 0.463251)^2 + (2 * 2 * 0.463251)^2
  //     = 11.159283; u = sqrt(13/3 + 11.159283 + 0.06) = 3.943682, U = 7.887364 um
  UncertaintyBudget b;
  b.values = {{"instrument_ppm", 1},
              {"eve_um", 0.6},
              {"resolution_um", 0},
              {"misalignment_mm", 0},
              {"monte_carlo_trials", 0}};
  Iso230_2StudyOptions o;
  o.uncertainty = b;
  o.normalisation.air = AirCompensation::Instrument;
  const Iso230_2StudyResult r = Iso230_2Study(o).run(read_measurements(small_csv()));
  REQUIRE(r.uncertainty.has_value());
  const UncertaintyResult& U = *r.uncertainty;
  CHECK(U.instrument_class == "laser-compensated");
  CHECK(U.figure("E")->value == doctest::Approx(8));
  CHECK(U.figure("E")->u == doctest::Approx(1.317826).epsilon(1e-6));
  CHECK(U.figure("E")->U == doctest::Approx(2.635653).epsilon(1e-6));
  CHECK(U.figure("B")->u == doctest::Approx(2.096028).epsilon(1e-6));
  CHECK(U.figure("B")->U == doctest::Approx(4.192056).epsilon(1e-6));
  CHECK(U.figure("R")->u == doctest::Approx(3.943682).epsilon(1e-6));
  CHECK(U.figure("R")->U == doctest::Approx(7.887364).epsilon(1e-6));
  // The rows of E's budget: sensitivities and contributions.
  const UncertaintyContribution* laser = contribution(U, "instrument calibration");
  REQUIRE(laser);
  CHECK(laser->u == doctest::Approx(0.5));
  CHECK(laser->unit == "um/m");
  CHECK(laser->sensitivity.at("E") == doctest::Approx(0.2).epsilon(1e-6));
  CHECK(laser->contribution_um.at("E") == doctest::Approx(0.1).epsilon(1e-6));
  CHECK(laser->sensitivity.at("B") == 0);
  const UncertaintyContribution* eve = contribution(U, "environmental variation (EVE)");
  REQUIRE(eve);
  CHECK(eve->sensitivity.at("E") == doctest::Approx(std::sqrt(2.0)).epsilon(1e-6));
  CHECK(eve->contribution_um.at("E") == doctest::Approx(0.244949).epsilon(1e-5));
  const UncertaintyContribution* a = contribution(U, "repeatability of the run (type A)");
  REQUIRE(a);
  CHECK(a->contribution_um.at("E") == doctest::Approx(1.290994).epsilon(1e-6));
  // No temperature recorded: the budget says what it leaves out.
  CHECK(U.notes.size() == 1);
  CHECK(U.notes[0].rfind("No material temperature recorded and no normalisation", 0) == 0);
  // The air not compensated is a contribution of the whole index (about 271 um/m).
  Iso230_2StudyOptions raw = o;
  raw.normalisation.air = AirCompensation::Unstated;
  const Iso230_2StudyResult rr = Iso230_2Study(raw).run(read_measurements(small_csv()));
  const UncertaintyContribution* air =
      contribution(*rr.uncertainty, "air refraction not compensated");
  REQUIRE(air);
  CHECK(air->u * std::sqrt(3.0) == doctest::Approx(271.4).epsilon(1e-3));
}

TEST_CASE("uncertainty: the Monte Carlo of GUM Supplement 1 agrees with the budget within 5 %") {
  UncertaintyBudget b;
  b.instrument_class = "laser-compensated";
  b.values = {
      {"instrument_ppm", 1},         {"material_temperature_C", 0.2}, {"eve_um", 0.4},
      {"abbe_offset_mm", 50},        {"abbe_angle_urad", 10},         {"misalignment_mm", 1},
      {"monte_carlo_trials", 200000}};
  Iso230_2StudyOptions o;
  o.uncertainty = b;
  const Iso230_2StudyResult r = Iso230_2Study(o).run(parse_measurements(synthetic_run(), "s.csv"));
  REQUIRE(r.uncertainty.has_value());
  const UncertaintyResult& U = *r.uncertainty;
  CHECK(U.trials == 200000);
  // Every kind of contribution is in the budget.
  for (const char* name :
       {"instrument calibration", "material temperature sensor", "expansion coefficient",
        "cosine error (beam misalignment)", "Abbe error", "environmental variation (EVE)",
        "repeatability of the run (type A)"})
    CHECK_MESSAGE(contribution(U, name) != nullptr, name);
  for (const char* name : {"E", "M", "A", "B", "R"}) {
    const FigureUncertainty* f = U.figure(name);
    REQUIRE(f);
    CAPTURE(name);
    CAPTURE(f->u);
    CAPTURE(f->mc_u);
    // docs/iso230-2.md quotes these numbers.
    MESSAGE(std::string(name) << ": value " << f->value << ", u " << f->u << ", U " << f->U
                              << ", Monte Carlo u " << f->mc_u << ", 95 % [" << f->mc_low << ", "
                              << f->mc_high << "]");
    CHECK(std::abs(f->mc_u / f->u - 1) <= 0.05);
    CHECK(f->validated);
    // The 95 % interval's half-width against U = 2u: within 10 % (a budget of rectangular
    // inputs has a 95 % interval narrower than +-2u; measured 2.5 to 5.2 % here).
    CHECK(std::abs((f->mc_high - f->mc_low) / 2 / f->U - 1) <= 0.10);
  }
  // The same inputs give the same draws.
  const Iso230_2StudyResult again =
      Iso230_2Study(o).run(parse_measurements(synthetic_run(), "s.csv"));
  CHECK(again.uncertainty->figure("E")->mc_u == U.figure("E")->mc_u);
}

TEST_CASE("uncertainty: ISO 14253-1 decides conformance with U") {
  UncertaintyBudget b;
  b.values = {{"monte_carlo_trials", 0}};
  Iso230_2StudyOptions o;
  o.uncertainty = b;
  const MeasurementTable t = parse_measurements(synthetic_run(), "s.csv");
  const Iso230_2StudyResult plain = Iso230_2Study(o).run(t);
  const double E = plain.uncertainty->figure("E")->value, UE = plain.uncertainty->figure("E")->U;
  REQUIRE(UE > 0.1);
  auto verdict = [&](double limit) {
    Iso230_2StudyOptions w = o;
    w.tolerance = parse_iso_tolerance("E=" + format_number(limit));
    const Iso230_2StudyResult r = Iso230_2Study(w).run(t);
    REQUIRE(r.tolerance.size() == 1);
    CHECK(r.tolerance[0].U == doctest::Approx(UE));
    return r;
  };
  CHECK(verdict(E + UE * 1.01).verdict == Decision::Conforms);
  const Iso230_2StudyResult open = verdict(E + UE * 0.5);
  CHECK(open.verdict == Decision::NotProven);
  CHECK(open.tolerance[0].pass);  // within the limit, but not proven
  CHECK(open.verdict_reason == "E: the value +- U straddles the limit (ISO 14253-1)");
  CHECK(verdict(E - UE * 0.5).verdict == Decision::NotProven);
  CHECK(verdict(E - UE * 1.01).verdict == Decision::DoesNotConform);
  const auto lines = iso230_2_tolerance_statement(open);
  CHECK(lines.back() ==
        "  verdict: NOT PROVEN (E: the value +- U straddles the limit (ISO 14253-1))");
}

TEST_CASE("uncertainty: budget files, classes and the CLI") {
  const UncertaintyBudget b = parse_uncertainty_budget(
      "# a lab's budget\nclass: laser-edlen\ninstrument_ppm: 0.1\neve_um: 0.5\n", "b.yaml");
  CHECK(b.instrument_class == "laser-edlen");
  CHECK(b.values.at("instrument_ppm") == 0.1);
  CHECK(b.source == "b.yaml");
  CHECK(uncertainty_defaults("laser-edlen").at("air_temperature_C") == 0.2);
  CHECK(uncertainty_defaults("laser-compensated").at("instrument_ppm") == 0.5);
  auto error = [](const std::string& text) {
    try {
      parse_uncertainty_budget(text, "b.yaml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  CHECK(error("class: laser\n")
            .rfind("b.yaml:1:8: uncertainty class 'laser' (classes: auto, "
                   "laser-compensated",
                   0) == 0);
  CHECK(error("eve_um: 0.5\nlaser_ppm: 1\n")
            .rfind("b.yaml:2:1: unknown key 'laser_ppm' (keys: "
                   "class, coverage_factor",
                   0) == 0);
  CHECK(error("eve_um: -1\n") == "b.yaml:1:9: eve_um: '-1' is not a number >= 0");
  CHECK(error("eve_um: [1]\n") == "b.yaml:1:9: eve_um: '' is not a number >= 0");
  CHECK(error("- eve_um\n").rfind("b.yaml:1:1: an uncertainty budget is a YAML mapping", 0) == 0);
  CHECK(error("coverage_factor: 9\n") ==
        "b.yaml:1:1: uncertainty budget: coverage_factor must be in [1, 4]");
  CHECK_THROWS_WITH_AS(uncertainty_budget_from_flag("lasr"),
                       doctest::Contains("--uncertainty lasr: expected auto, a class"),
                       std::invalid_argument);
  CHECK(uncertainty_budget_from_flag("scale").instrument_class == "scale");

  const auto dir = test::fresh_dir("uncertainty_cli");
  const std::string budget = (dir / "budget.yaml").string(), js = (dir / "u.json").string(),
                    html = (dir / "u.html").string();
  write_file_atomically(budget,
                        "class: laser-compensated\neve_um: 0.4\nmonte_carlo_trials: 20000\n");
  const std::string carto = std::string(WEILGEN_SOURCE_DIR) + "/examples/data/carto_x.csv";
  test::Run r = run(cli("iso230-2 " + carto + " --uncertainty " + budget +
                        " --tolerance 25,A=30 --json " + js + " --report " + html));
  REQUIRE(r.status == 0);
  CHECK(r.out.find("Measurement uncertainty (um; ISO 230-9 and the GUM; class "
                   "laser-compensated, budget: " +
                   budget) != std::string::npos);
  CHECK(r.out.find("  Budget of E = 9.234 um:") != std::string::npos);
  CHECK(r.out.find("decided on the classical ISO 230-2 figures (k = 2) with their expanded "
                   "uncertainty U (ISO 14253-1)") != std::string::npos);
  const json j = json::parse(test::read_text(js));
  const json& u = j["uncertainty"];
  CHECK(u["class"] == "laser-compensated");
  CHECK(u["monte_carlo"]["trials"] == 20000);
  CHECK(u["figures"]["E"]["U_um"].get<double>() ==
        doctest::Approx(2 * u["figures"]["E"]["u_um"].get<double>()));
  CHECK(j["tolerance"]["checks"][1]["U_um"] == u["figures"]["A"]["U_um"]);
  double share = 0;
  for (const json& c : u["contributions"]) share += c["share_pct"]["E"].get<double>();
  CHECK(share == doctest::Approx(100).epsilon(1e-9));
  // The report: the table's U equal to the JSON's, the budget of every figure.
  const std::string page = test::read_text(html);
  for (const char* f : {"E", "M", "A", "B", "R"}) {
    const std::string cell = "data-uncertainty=\"" + std::string(f) + "\" data-field=\"U_um\">" +
                             format_fixed(u["figures"][f]["U_um"].get<double>(), 3) + "<";
    CHECK_MESSAGE(page.find(cell) != std::string::npos, f);
    CHECK(page.find("data-budget=\"" + std::string(f) + "\"") != std::string::npos);
  }
  // Bad budgets: a bad file exits 3, a bad flag 2, nothing written.
  write_file_atomically(js, "keep\n");
  write_file_atomically(budget, "eve: 1\n");
  r = run(cli("iso230-2 " + carto + " --uncertainty " + budget + " --json " + js));
  CHECK(r.status == 3);
  CHECK(r.out.find("budget.yaml:1:1: unknown key 'eve'") != std::string::npos);
  CHECK(run(cli("iso230-2 " + carto + " --uncertainty nonsense --json " + js)).status == 2);
  CHECK(test::read_text(js) == "keep\n");
  // A class by name: the defaults.
  r = run(cli("iso230-2 " + carto + " --uncertainty laser-edlen --json " + js));
  REQUIRE(r.status == 0);
  CHECK(json::parse(test::read_text(js))["uncertainty"]["source"] == "defaults");
}

TEST_CASE("uncertainty: a rotary axis, its scale error per radian of rotation") {
  // C at 0, 90, 180 deg; the means rise with the angle, so E runs from 0 to 180 deg: a scale
  // error of 1 urad/rad (k = 2) contributes 0.5 urad/rad * pi rad.
  std::string text = "# axis: C\nC,dir,cycle,dc_urad\n";
  for (int j = 1; j <= 3; ++j)
    for (int d : {1, -1})
      for (int i = 0; i <= 2; ++i)
        text += std::to_string(90 * i) + "," + std::to_string(d) + "," + std::to_string(j) + "," +
                format_number(10.0 * i + 0.1 * j) + "\n";
  UncertaintyBudget b;
  b.values = {{"instrument_ppm", 1}, {"resolution_um", 0}, {"monte_carlo_trials", 0}};
  Iso230_2StudyOptions o;
  o.uncertainty = b;
  const Iso230_2StudyResult r = Iso230_2Study(o).run(parse_measurements(text, "c.csv"));
  const UncertaintyContribution* laser = contribution(*r.uncertainty, "instrument calibration");
  REQUIRE(laser);
  CHECK(laser->unit == "urad/rad");
  CHECK(laser->sensitivity.at("E") == doctest::Approx(3.14159265358979).epsilon(1e-6));
  CHECK(laser->contribution_um.at("E") == doctest::Approx(0.5 * 3.14159265358979).epsilon(1e-6));
  // No air, material or set-up contributions for an angle; the note says so.
  CHECK(contribution(*r.uncertainty, "air refraction not compensated") == nullptr);
  CHECK(r.uncertainty->notes.back().rfind("A rotary axis:", 0) == 0);
}
