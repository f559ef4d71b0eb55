// Gap diagnosis: each library effect withheld from vmc_3axis on a grid (first-order truth with
// random errors) is named with its size, and a step the grid cannot tell from a shape is not.
#include <doctest/doctest.h>

#include <sstream>

#include "gap/fixtures.hpp"

using namespace weilgen;
using namespace weilgen::gap_test;

TEST_CASE("gap: reversal on X is named, with its size") {
  const GapResult r = diagnose(synth(1, [](const Row& w) {
    return std::array<double, 3>{2.0 * w.dir_X, 0, 0};  // B = 4 µm in dx
  }));
  CHECK(r.verdict.names("reversal"));
  const EffectFit* e = effect(r, "reversal");
  REQUIRE(e);
  CHECK(std::abs(e->params.at("reversal_um")) == doctest::Approx(4.0).epsilon(0.1));
  CHECK(e->heldout_rms_after_um < 1.2 * r.noise.sigma_um);
  CHECK(r.noise.sigma_um == doctest::Approx(0.5).epsilon(0.15));
}

TEST_CASE("gap: a periodic error along X: period and amplitude") {
  const GapResult r = diagnose(synth(
      2,
      [](const Row& w) {
        return std::array<double, 3>{0, 3.0 * std::sin(2 * M_PI * w.X / 125.0), 0};
      },
      0.5, 3, 21));
  CHECK(r.verdict.names("periodic"));
  const EffectFit* e = effect(r, "periodic");
  REQUIRE(e);
  CHECK(e->params.at("period_mm") == doctest::Approx(125).epsilon(0.05));
  CHECK(e->params.at("amplitude_um") == doctest::Approx(3.0).epsilon(0.15));
  // A shape of the straightness of X in y, through the kinematics.
  CHECK(e->params.count("error_E_YX") == 1);
  CHECK(e->summary.find("periodic E_YX of X: period 12") == 0);
  REQUIRE(e->region);
  CHECK(e->region->output == "dy");
}

TEST_CASE("gap: thermal drift with a lagged sensor") {
  const GapResult r = diagnose(synth(3, [](const Row& w) {
    return std::array<double, 3>{3.0 * (w.T - 22), 0, -1.0 * (w.T - 22)};
  }));
  CHECK(r.verdict.names("thermal_drift"));
  const EffectFit* e = effect(r, "thermal_drift");
  REQUIRE(e);
  CHECK(e->params.count("sensor_T_spindle") == 1);
  CHECK(e->params.at("drift_x_um_per_K") == doctest::Approx(3.0).epsilon(0.1));
  CHECK(e->params.at("drift_z_um_per_K") == doctest::Approx(-1.0).epsilon(0.1));
  // What remains is noise: no significant gap against σ²(1 + h). The held-out RMS after exceeds
  // the noise (0.5 µm) by the leverage of the heating cycle, whose temperatures the other
  // cycles do not span.
  CHECK(r.final.p_value >= 0.01);
  CHECK(r.final.rms_um < 1.4 * 0.5);
}

TEST_CASE("gap: a local bump along Y in dz is localised") {
  const GapResult r = diagnose(synth(
      4,
      [](const Row& w) {
        return std::array<double, 3>{0, 0, 4.0 * std::exp(-0.5 * std::pow((w.X - 300) / 40, 2))};
      },
      0.5, 3, 11));
  CHECK(r.verdict.names("pdge_shape"));
  const EffectFit* e = effect(r, "pdge_shape");
  REQUIRE(e);
  REQUIRE(e->region);
  CHECK(e->region->by == "X");
  CHECK(e->region->from <= 300);
  CHECK(e->region->to >= 300);
}

TEST_CASE("gap: an angular error the machine file leaves out is named") {
  // The model lacks E_AX (roll of X); the data come from the full machine with
  // E_AX(x) = 40 µrad · u², u = (2x − 500)/500. (A constant E_AX, or a missing squareness,
  // would be absorbed by E_AY's or E_CY's constant term: not a gap.)
  std::string yaml = test::read_text(test::machine_path("vmc_3axis"));
  const auto at = yaml.find("      E_AX:");
  REQUIRE(at != std::string::npos);
  yaml.erase(at, yaml.find('\n', at) - at + 1);
  const Description reduced = load_machine_text(yaml, "vmc_no_AX.yaml");
  auto model = std::make_shared<const Model>(reduced, 1, "numeric chain");
  const Model& full = *vmc();
  ModelData md(full);
  const int k = full.description().error_index("E_AX");
  const GapResult r =
      diagnose(synth(5, none, 0.5, 3, 6,
                     [&](const Row& w, const std::vector<double>&) {
                       std::vector<double> e(full.num_errors(), 0.0);
                       const double u = (2 * w.X - 500) / 500;
                       e[static_cast<std::size_t>(k)] = 40e-6 * u * u;
                       const double q[3] = {w.Y, w.X, w.Z};
                       std::array<double, 6> out{};
                       full.deviation(md, q, e.data(), out.data());
                       return std::array<double, 3>{out[0] * 1e3, out[1] * 1e3, out[2] * 1e3};
                     }),
               model);
  CHECK(r.verdict.names("missing_error"));
  const EffectFit* e = effect(r, "missing_error");
  REQUIRE(e);
  CHECK(e->variant == "E_AX");
  CHECK(e->params.at("E_AX_peak") == doctest::Approx(40).epsilon(0.15));
}

TEST_CASE("gap: a step where the data cannot tell shapes apart is unexplained, not a shape") {
  // dx jumps by 6 µm at X = 250 mm. On 6 positions along X a quadratic PDGE basis leaves 3
  // shape degrees of freedom, and a period or a bump uses 3: either fits, neither is named.
  const EffectFn step = [](const Row& w) {
    return std::array<double, 3>{w.X >= 250 ? 6.0 : 0.0, 0, 0};
  };
  const GapResult coarse = diagnose(synth(11, step, 0.5, 3, 6));
  CHECK(coarse.verdict.kind == GapVerdict::Kind::Unexplained);
  REQUIRE_FALSE(coarse.explanation.empty());
  const EffectFit& first = coarse.explanation.front();
  CHECK_FALSE(first.distinguishable);
  CHECK(first.shape_dof_free == 3);
  CHECK(first.shape_dof_used >= 3);
  CHECK(coarse.verdict.reason.find("shape degrees of freedom along X") != std::string::npos);
  // On 21 positions the shapes are told apart, and none fits a step: still not a name.
  const GapResult fine = diagnose(synth(12, step, 0.5, 3, 21));
  CHECK(fine.verdict.kind == GapVerdict::Kind::Unexplained);
  CHECK(fine.baseline.p_value < 1e-6);
}

TEST_CASE("gap: a bump between the samples of a coarse grid is found and resolved") {
  // 11 positions along X (50 mm apart); the bump sits between two of them.
  const GapResult r = diagnose(synth(
      13,
      [](const Row& w) {
        return std::array<double, 3>{0, 5.0 * std::exp(-0.5 * std::pow((w.X - 262) / 50, 2)), 0};
      },
      0.5, 3, 11));
  CHECK(r.verdict.names("pdge_shape"));
  const EffectFit* e = effect(r, "pdge_shape");
  REQUIRE(e);
  CHECK(e->distinguishable);
  CHECK(e->params.at("centre_mm") == doctest::Approx(262).epsilon(0.03));
  CHECK(e->params.at("width_mm") == doctest::Approx(50).epsilon(0.15));
  CHECK(e->params.at("positions_covered") >= 3);
}

TEST_CASE("gap: products of errors (errors 200x their spreads) are higher_order, scale 1") {
  const GapResult r = diagnose(synth(
      31, none, 0.5, 3, 6,
      [](const Row& w, const std::vector<double>& e) { return exact_um(w, e); }, poly2(), 200));
  // Rotations of 2 mrad: products of errors reach µm, which a first-order model cannot fit.
  CHECK(r.verdict.names("higher_order"));
  const EffectFit* e = effect(r, "higher_order");
  REQUIRE(e);
  CHECK(e->params.at("scale") == doctest::Approx(1.0).epsilon(0.2));
}

TEST_CASE("gap: a tool 100 mm longer than the model's is fitted as a tool_offset of 100 mm") {
  const PdgeBasisChoice c = linear_translations();
  const GapResult r = diagnose(synth(
                                   32, none, 0.3, 3, 6,
                                   [](const Row& w, const std::vector<double>& e) {
                                     return exact_um(w, e, {{"tool_length", 100}});
                                   },
                                   c, 5),
                               vmc(), "cycle:3", c);
  // The tool column is the rotations' lever at the identified errors, which the first-order
  // data leave partly undetermined (rank-deficient model): the offset is recovered, and about
  // a fifth of the excess stays (the verdict then withholds the name).
  REQUIRE_FALSE(r.explanation.empty());
  const EffectFit& e = r.explanation.front();
  CHECK(e.name == "tool_offset");
  CHECK(e.params.at("offset_mm") == doctest::Approx(100).epsilon(0.05));
  CHECK(e.explained_fraction > 0.7);
}

TEST_CASE("gap: a cosine error of the measuring set-up along X is setup, with its size") {
  // dx reads 20 µm/m² · X² too much; its linear (scale) part is E_XX's own.
  const PdgeBasisChoice c = linear_translations();
  const GapResult r = diagnose(synth(
                                   33,
                                   [](const Row& w) {
                                     return std::array<double, 3>{20 * w.X * w.X / 1e6, 0, 0};
                                   },
                                   0.3, 3, 11, {}, c),
                               vmc(), "cycle:3", c);
  CHECK(r.verdict.names("setup"));
  const EffectFit* e = effect(r, "setup");
  REQUIRE(e);
  CHECK(e->variant == "dx along X");
  CHECK(e->params.at("quadratic_um_per_m2") == doctest::Approx(20).epsilon(0.1));
}

TEST_CASE("gap: a heat-up drift with a lag of 0.18 x the run is found under cycle folds") {
  // 432 rows 60 s apart: the run spans 25,860 s; the lag is 0.18 of it (4,655 s = 1.29 h). The
  // temperature column is dropped: the heat-up in time is what is tested (a sensor lagged behind
  // the synthetic spindle temperature can mimic it).
  const double span = 431 * 60.0, tau = 0.18 * span;
  std::string csv = synth(41, [tau](const Row& w) {
    return std::array<double, 3>{4 * (1 - std::exp(-w.t_s / tau)), 0,
                                 -3 * (1 - std::exp(-w.t_s / tau))};
  });
  std::istringstream in(csv);
  std::ostringstream out;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> f;
    std::stringstream ls(line);
    for (std::string cell; std::getline(ls, cell, ',');) f.push_back(cell);
    f.erase(f.begin() + 6);  // T_spindle
    for (std::size_t k = 0; k < f.size(); ++k) out << (k ? "," : "") << f[k];
    out << "\n";
  }
  const GapResult r = diagnose(out.str());
  CHECK(r.verdict.names("thermal_drift"));
  const EffectFit* e = effect(r, "thermal_drift");
  REQUIRE(e);
  INFO("variant: " << e->variant << ", summary: " << e->summary);
  REQUIRE(e->params.count("tau_h"));
  CHECK(e->params.at("tau_h") == doctest::Approx(tau / 3600).epsilon(0.1));
}
