// Gap diagnosis: gross readings are reported and removed, also where an effect masks them.
#include <doctest/doctest.h>

#include "gap/fixtures.hpp"

using namespace weilgen;
using namespace weilgen::gap_test;

TEST_CASE("gap: five gross readings are reported and removed, and the reversal is still named") {
  const std::string clean = synth(1, [](const Row& w) {
    return std::array<double, 3>{2.0 * w.dir_X, 0, 0};  // B = 4 µm in dx
  });
  const std::vector<int> rows = {17, 90, 151, 240, 333};
  const GapResult r = diagnose(with_gross_readings(clean, rows, 60));
  REQUIRE(r.outliers.size() == 5);
  for (std::size_t k = 0; k < 5; ++k) {
    CHECK(r.outliers[k].output == "dx");
    CHECK(r.outliers[k].line == rows[k] + 1);  // the header is line 1
    CHECK(r.outliers[k].residual_um == doctest::Approx(60).epsilon(0.1));
    CHECK(r.outliers[k].sigmas > 6);
  }
  CHECK(r.verdict.names("reversal"));
  const EffectFit* e = effect(r, "reversal");
  REQUIRE(e);
  CHECK(std::abs(e->params.at("reversal_um")) == doctest::Approx(4.0).epsilon(0.1));
  CHECK(std::isnan(r.residual_before[static_cast<std::size_t>(r.outliers[0].observation)]));
}

TEST_CASE("gap: gross readings the reversal masks are found against the model with it") {
  // B = 10 µm: the baseline's residual is ±5 µm, robust sigma about 7 µm, so 6 sigma is about
  // 44 µm and a 25 µm reading stays among them; against baseline and reversal (sigma 0.5 µm) it
  // lies 50 sigma out. Left in, the five fail the final gap test (unexplained).
  const std::string clean = synth(1, [](const Row& w) {
    return std::array<double, 3>{5.0 * w.dir_X, 0, 0};
  });
  const std::vector<int> big = {17, 240}, small = {90, 151, 333};
  const GapResult r = diagnose(with_gross_readings(with_gross_readings(clean, big, 60), small, 25));
  std::vector<int> lines;
  for (const GapOutlier& g : r.outliers) {
    CHECK(g.output == "dx");
    lines.push_back(g.line);
  }
  CHECK(lines == std::vector<int>{18, 91, 152, 241, 334});  // the header is line 1
  for (const GapOutlier& g : r.outliers)
    CHECK(std::abs(g.residual_um) ==
          doctest::Approx(g.line == 18 || g.line == 241 ? 60 : 25).epsilon(0.15));
  CHECK(r.verdict.names("reversal"));
  const EffectFit* e = effect(r, "reversal");
  REQUIRE(e);
  CHECK(std::abs(e->params.at("reversal_um")) == doctest::Approx(10.0).epsilon(0.05));
  for (const GapOutlier& g : r.outliers) {
    CHECK(std::isnan(r.residual_before[g.observation]));
    CHECK(std::isnan(r.residual_after[g.observation]));
  }
  // The reading kept beside them keeps its index: the residual vectors cover every observation.
  CHECK(r.residual_after.size() == r.observations + r.outliers.size());
}

TEST_CASE("gap: effect-free data with gross readings: outliers, and the verdict none") {
  int named = 0;
  for (std::uint32_t s = 0; s < 10; ++s) {
    const GapResult r =
        diagnose(with_gross_readings(synth(300 + s, none, 0.5, 3, 5), {5, 50, 95}, -40));
    CHECK(r.outliers.size() == 3);
    if (r.verdict.kind != GapVerdict::Kind::None) ++named;
  }
  CHECK(named <= 1);
}
