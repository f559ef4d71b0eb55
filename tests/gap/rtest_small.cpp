// Gap diagnosis on small R-test sets of head_head_bc: the floor without repeats, the lack of
// fit seeing a step the folds cannot predict, and two effects the search must both name.
#include <doctest/doctest.h>

#include "gap/fixtures.hpp"

using namespace weilgen;
using namespace weilgen::gap_test;

namespace {

// head_head_bc, one pass of 60 R-test poses, time:5 folds, poly:3 PDGEs, noise 0.5 µm: a step of
// 4 µm (8x the noise) in dz from the middle of the run on (outside the library), seeds 45-50.
// Diagnosed once for the two tests that read it.
const std::vector<std::pair<std::uint32_t, GapResult>>& step_in_time_results() {
  static const std::vector<std::pair<std::uint32_t, GapResult>> results = [] {
    const auto model = test::builtin_model("head_head_bc");
    const std::vector<ChainRow> rows = head_rtest_one_pass(*model);
    REQUIRE(rows.size() == 60);
    std::vector<std::pair<std::uint32_t, GapResult>> out;
    for (std::uint32_t seed : {45u, 46u, 47u, 48u, 49u, 50u}) {
      const std::string csv = chain_csv(
          *model, rows, 0.5, seed,
          [&](const ChainRow& r, std::vector<double>&, std::vector<double>&, Eigen::Vector3d& x) {
            x = Eigen::Vector3d(0, 0, r.t_s >= 30 * 20 ? 4.0 : 0.0);
          });
      out.emplace_back(seed, diagnose(csv, model, "time:5", poly(3)));
    }
    return out;
  }();
  return results;
}

}  // namespace

TEST_CASE(
    "gap: on a small rotary set without repeats the floor reads the noise, and a step is seen") {
  // head_head_bc, one pass of 60 R-test poses (no pose repeated), time:5 folds, poly:3 PDGEs:
  // the held-out residual carries each fold's prediction error (held-out leverage up to several),
  // which neighbours in time far apart in B and C do not share. Taken as noise (Var(d) = 2σ²),
  // the floor read up to 2.8x σ on the benchmark's effect-free sets of this layout and steps
  // were `none`; with the differences' exact variance from the folds' factors it reads σ.
  const auto model = test::builtin_model("head_head_bc");
  const std::vector<ChainRow> rows = head_rtest_one_pass(*model);
  REQUIRE(rows.size() == 60);
  const PdgeBasisChoice poly3 = poly(3);
  const double noise = 0.5;
  for (std::uint32_t seed : {41u, 42u, 43u, 44u}) {
    const GapResult r = diagnose(chain_csv(*model, rows, noise, seed, {}), model, "time:5", poly3);
    INFO("seed " << seed << ": floor " << r.noise.sigma_um << " µm, " << r.noise.detail);
    CHECK(r.noise.source == "small-scale");
    CHECK(r.noise.sigma_um == doctest::Approx(noise).epsilon(0.25));
    // (The verdict on such sets: "effect-free small rotary sets are none when folds leave
    // directions undetermined".)
  }
  // A step of 4 µm in dz from the middle of the run on (outside the library).
  const std::string csv = chain_csv(
      *model, rows, noise, 45,
      [&](const ChainRow& r, std::vector<double>&, std::vector<double>&, Eigen::Vector3d& x) {
        x = Eigen::Vector3d(0, 0, r.t_s >= 30 * 20 ? 4.0 : 0.0);
      });
  const GapResult r = diagnose(csv, model, "time:5", poly3);
  INFO(r.verdict.reason);
  CHECK(r.noise.sigma_um < 1.25 * noise);
  // Seen: not `none`. (Which name it gets is the step's own problem, outside the library: the
  // model's errors absorb most of a step on 60 poses and thermal_drift fits the rest.)
  CHECK(r.verdict.kind != GapVerdict::Kind::None);
}

TEST_CASE(
    "gap: effect-free small rotary sets are none when folds leave directions undetermined, and a "
    "periodic error is still named") {
  // head_head_bc, 60 R-test poses, time:5 folds, poly:3 PDGEs (the benchmark's rtest_small): each
  // fold's held-out poses carry 3-5 directions of the errors that its training poses do not
  // determine. The minimum-norm fit predicts nothing along them, so the held-out residual holds
  // the true errors' part there, which no noise model contains; tested on all of it, some such
  // sets read `unexplained` (p down to 1e-7 in the benchmark). The test on the part each fold can
  // predict is at the floor.
  const auto model = test::builtin_model("head_head_bc");
  const std::vector<ChainRow> rows = head_rtest_one_pass(*model);
  REQUIRE(rows.size() == 60);
  const PdgeBasisChoice poly3 = poly(3);
  const double noise = 0.5;
  int flagged = 0;
  for (std::uint32_t seed = 60; seed < 72; ++seed) {
    const GapResult r = diagnose(chain_csv(*model, rows, noise, seed, {}), model, "time:5", poly3);
    INFO("seed " << seed << ": " << r.verdict.str() << ", " << r.verdict.reason);
    if (r.verdict.kind != GapVerdict::Kind::None) ++flagged;
  }
  CHECK(flagged == 0);  // 2 of these 12 on the test over all of the residual
  // The same layout with a periodic error of the C head (amplitude 2.5 µm, visible ~5x the noise).
  const int k = error_index(*model, "E_ZC");
  int named = 0;
  for (std::uint32_t seed = 60; seed < 64; ++seed) {
    const std::string csv = chain_csv(
        *model, rows, noise, seed,
        [&](const ChainRow& r, std::vector<double>&, std::vector<double>& e, Eigen::Vector3d&) {
          e[static_cast<std::size_t>(k)] += 2.5e-3 * std::sin(2 * M_PI * r.q[3] / 120 + 0.4);
        });
    const GapResult r = diagnose(csv, model, "time:5", poly3);
    INFO("seed " << seed << ": " << r.verdict.str() << ", " << r.verdict.reason);
    if (r.verdict.names("periodic")) ++named;
  }
  CHECK(named == 4);
}

TEST_CASE("gap: a step that an effect of the library only imitates is unexplained (lack of fit)") {
  // The step of step_in_time_results(): the model's errors absorb most of it and a thermal drift
  // in time, a set-up or a shape fits the rest, so a name was given; the lack-of-fit test after
  // acceptance (free offsets per output in bins of time and of every axis) finds the structure
  // the named effect leaves along time or an axis.
  int named = 0, seen = 0;
  for (const auto& seed_result : step_in_time_results()) {
    const auto& seed = seed_result.first;  // clang < 16 cannot capture a structured binding
    const auto& r = seed_result.second;
    INFO("seed " << seed << ": " << r.verdict.str() << ": " << r.verdict.reason);
    // (`none` is allowed here: the held-out gap alone can sit at the floor; the baseline's lack
    // of fit, tested below, is what sees the step then.)
    CHECK(!r.verdict.names("thermal_drift"));
    if (r.verdict.kind != GapVerdict::Kind::None && r.verdict.kind != GapVerdict::Kind::Unexplained)
      ++named;
    if (r.verdict.kind == GapVerdict::Kind::Unexplained) ++seen;
  }
  CHECK(named == 0);
  CHECK(seen >= 3);
}

TEST_CASE(
    "gap: products of errors with a part in the R-test's null space are higher_order, to the "
    "noise") {
  // head_head_bc on an R-test: the first-order model is rank-deficient, and errors 100x their
  // spreads have a null-space part the linear fit cannot see; its products with the rest can.
  // The one column at the minimum-norm errors leaves most of the products unexplained; the
  // exact chain refitted over all errors (Levenberg-Marquardt) fits them to the noise.
  const auto model = test::builtin_model("head_head_bc");
  const double noise = 0.3;
  const std::string csv = chain_csv(
      *model, head_rtest(*model), noise, 25,
      [](const ChainRow&, std::vector<double>&, std::vector<double>& e, Eigen::Vector3d&) {
        for (double& v : e) v *= 100;
      });
  const GapResult r = diagnose(csv, model, "cycle:3", poly2());
  INFO(r.verdict.reason);
  CHECK(r.verdict.names("higher_order"));
  const EffectFit* e = effect(r, "higher_order");
  REQUIRE(e);
  CHECK(e->params.at("scale") == doctest::Approx(1.0).epsilon(0.05));
  for (int o = 0; o < 3; ++o) CHECK(r.final.rms[o] < 1.2 * noise);
}

TEST_CASE("gap: a step in time that the folds cannot predict is still seen (lack of fit)") {
  // The step of step_in_time_results(). Each fold's held-out poses lie mostly in directions its
  // training poses do not determine, which the held-out test leaves out, so its p can sit at the
  // floor; on all data the model cannot follow the step (lack of fit along time), so the gap is
  // significant, no candidate of the library removes it whole, and the verdict is unexplained.
  int unexplained = 0, heldout_blind = 0;
  for (const auto& seed_result : step_in_time_results()) {
    const auto& seed = seed_result.first;  // clang < 16 cannot capture a structured binding
    const auto& r = seed_result.second;
    INFO("seed " << seed << ": " << r.verdict.str() << ": " << r.verdict.reason << " (held-out p "
                 << r.baseline.p_value << ", lack of fit p " << r.baseline_lack_of_fit_p << ")");
    CHECK(r.baseline_lack_of_fit_p < 1e-6);
    CHECK(r.baseline_lack_of_fit_along == "time");
    if (r.verdict.kind == GapVerdict::Kind::Unexplained) ++unexplained;
    if (r.baseline.p_value >= 0.01) ++heldout_blind;
  }
  CHECK(unexplained == 6);
  CHECK(heldout_blind >= 2);  // the held-out test alone reads `none` there (p 0.064 and 0.021)
}

TEST_CASE(
    "gap: a thermal drift and a bump along C on a head-head R-test are both named (the search "
    "goes on while all data show a structure)") {
  // head_head_bc, 180 R-test poses, a spindle drift fixed in the machine frame plus a bump of
  // E_ZC along C (the benchmark's pdge_shape+thermal_drift on rtest). The drift is accepted
  // first; after it the held-out gap is at the floor, since the bump lies mostly in directions a
  // fold cannot predict from its training poses, while on all data the structure along C
  // stands out (lack of fit p < alpha^3). Stopping there named the drift alone, or called the
  // drift an imitation of a shape outside the library.
  const auto model = test::builtin_model("head_head_bc");
  const int k = error_index(*model, "E_ZC");
  auto T = [](double t) { return 22 + 2.5 * (1 - std::exp(-t / 1500)); };
  const double centre = 180, width = 30;
  const std::string csv = chain_csv(
      *model, head_rtest(*model), 1.0, 31,
      [&](const ChainRow& r, std::vector<double>&, std::vector<double>& e, Eigen::Vector3d& x) {
        const double z = (r.q[3] - centre) / width;
        e[static_cast<std::size_t>(k)] += 30 * 1e-3 * std::exp(-0.5 * z * z);
        x = Eigen::Vector3d(-8, 4, 6) * (T(r.t_s) - 22);  // µm/K
      },
      ",T_spindle", [&](const ChainRow& r) { return std::to_string(T(r.t_s)); });
  const GapResult r = diagnose(csv, model, "cycle:3", poly(3));
  std::set<std::string> named;
  for (const EffectFit& f : r.explanation) named.insert(f.name);
  INFO(r.verdict << ": " << r.verdict.reason);
  CHECK((r.verdict.names("thermal_drift") || r.verdict.names("pdge_shape")));
  CHECK(named == std::set<std::string>{"pdge_shape", "thermal_drift"});
  const EffectFit* b = effect(r, "pdge_shape");
  REQUIRE(b);
  INFO(b->summary);
  CHECK(b->summary.find("bump of E_ZC of C") == 0);
  CHECK(b->params.at("centre_deg") == doctest::Approx(centre).epsilon(0.05));
}
