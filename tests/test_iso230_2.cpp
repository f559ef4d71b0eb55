// ISO 230-2 evaluation and Stejskal et al. 2017's thermal-drift elimination
// (weilgen/measure/iso230_2.hpp, docs/iso230-2.md): a hand-computed example with every figure
// pinned, invariants on random data, drift recovery on synthetic data, Stejskal et al. 2017's
// sqrt(2) Monte Carlo check, the anomaly test's false-positive rate and power, grouping errors, and
// the CLI end to end.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "bench/experiments/normal_deviates.hpp"
#include "test_support.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/measure/iso230_2.hpp"
#include "weilgen/measure/measurement_csv.hpp"
#include "weilgen/report/plot.hpp"

using namespace weilgen;
using nlohmann::json;
using test::cli;
using test::run;
using test::Run;

namespace {

const double kSqrt2 = std::sqrt(2.0);

using Normal = weilgen::bench::NormalDeviates;  // bench/experiments/normal_deviates.hpp

std::string small_csv() {
  return std::string(WEILGEN_SOURCE_DIR) + "/examples/data/iso230_2_small.csv";
}

IsoRuns runs_of(const MeasurementTable& t, const std::string& axis = "",
                const std::string& column = "") {
  return group_iso_runs(iso_observations(t, iso_columns(t, axis, column)), t.file);
}

IsoRuns runs_of_text(const std::string& text) { return runs_of(parse_measurements(text, "d.csv")); }

std::string error_of(const std::string& text) {
  try {
    runs_of_text(text);
  } catch (const InputError& e) {
    return e.what();
  }
  FAIL("no InputError for:\n" << text);
  return "";
}

// Synthetic line runs: static profile + reversal + drift linear in time + Gaussian noise.
// Each cycle runs up through targets 0..m-1, then down through m-1..0, one observation every
// dt_s seconds.
struct Synth {
  std::size_t m = 16, n = 30;
  double spacing_mm = 20;
  double dt_s = 15;
  double drift_per_h = 6;  // um/h
  double sigma = 0.5;      // um
  double reversal = 1.5;   // um: +reversal/2 up, -reversal/2 down
  std::size_t noisy_target = static_cast<std::size_t>(-1);
  double noisy_factor = 4;  // sigma multiplier at noisy_target, direction up only
};

double profile(double p) { return 3 * std::sin(p / 60.0) + 0.01 * p; }

std::vector<IsoObservation> synth(const Synth& s, Normal& rng) {
  std::vector<IsoObservation> out;
  double t = 0;
  for (std::size_t j = 0; j < s.n; ++j) {
    for (int pass = 0; pass < 2; ++pass) {
      for (std::size_t k = 0; k < s.m; ++k) {
        const std::size_t i = pass == 0 ? k : s.m - 1 - k;
        IsoObservation o;
        o.position_mm = static_cast<double>(i) * s.spacing_mm;
        o.direction = pass == 0 ? 1 : -1;
        o.cycle = static_cast<long>(j + 1);
        o.time_s = t;
        const double sig = s.sigma * (pass == 0 && i == s.noisy_target ? s.noisy_factor : 1.0);
        o.deviation = profile(o.position_mm) + o.direction * s.reversal / 2 +
                      s.drift_per_h * t / 3600.0 + sig * rng();
        out.push_back(o);
        t += s.dt_s;
      }
    }
  }
  return out;
}

json read_json(const std::string& path) {
  std::string text;
  REQUIRE(read_file(path, text));
  return json::parse(text);
}

void check_invariants(const IsoFigures& f) {
  CHECK(f.B >= 0);
  CHECK(f.R >= f.R_up);
  CHECK(f.R >= f.R_down);
  CHECK(f.A >= f.E);
  CHECK(f.A_up >= f.E_up);
  CHECK(f.A_down >= f.E_down);
  CHECK(f.M <= f.E + 1e-12);
  CHECK(f.E >= f.E_up);
  CHECK(f.E >= f.E_down);
  CHECK(f.A >= f.A_up);
  CHECK(f.A >= f.A_down);
  CHECK(std::abs(f.B_mean) <= f.B + 1e-12);
  for (std::size_t i = 0; i < f.R_i.size(); ++i) {
    CHECK(f.R_i[i] >= f.R_i_up[i]);
    CHECK(f.R_i[i] >= f.R_i_down[i]);
    CHECK(f.R_i[i] >= std::abs(f.B_i[i]));
  }
}

}  // namespace

// ---- The hand-computed example ---------------------------------------------------------------
//
// examples/data/iso230_2_small.csv: targets X = 0, 100, 200 mm, cycles 1..3 (um):
//   up:   X=0: 1 2 3      X=100: 4 6 8    X=200: 0 3 6
//   down: X=0: -2 -1 0    X=100: 4 4 4    X=200: 5 7 9
// Means x̄↑ = 2, 6, 3; x̄↓ = -1, 4, 7. Estimators (n-1 = 2): s↑ = 1, 2, 3 (sums of squares 2, 8,
// 18); s↓ = 1, 0, 2 (2, 0, 8).
// B_i = x̄↑ - x̄↓ = 3, 2, -4: B = 4, B̄ = (3 + 2 - 4)/3 = 1/3.
// R_i↑ = 4 s↑ = 4, 8, 12 (R↑ = 12); R_i↓ = 4, 0, 8 (R↓ = 8).
// R_i = max(2s↑ + 2s↓ + |B_i|, R_i↑, R_i↓) = max(7,4,4) = 7, max(6,8,0) = 8, max(14,12,8) = 14:
// R = 14.
// x̄_i = 0.5, 5, 5: M = 4.5. E↑ = 6 - 2 = 4, E↓ = 7 - (-1) = 8, E = 7 - (-1) = 8.
// A↑ = max(4, 10, 9) - min(0, 2, -3) = 13; A↓ = max(1, 4, 11) - min(-3, 4, 3) = 14;
// A = max(10, 11) - min(-3, -3) = 14.
TEST_CASE("iso230-2: hand-computed example, every classical figure") {
  const MeasurementTable t = read_measurements(small_csv());
  const IsoColumns c = iso_columns(t);
  CHECK(c.axis == "X");  // from "# axis: X"
  CHECK(c.direction == "dir");
  CHECK(c.deviation == "dx_um");
  CHECK(c.time == "t_s");
  CHECK(c.unit == "um");
  const IsoRuns runs = runs_of(t);
  CHECK(runs.positions_mm == std::vector<double>{0, 100, 200});
  CHECK(runs.cycles[kUp] == std::vector<long>{1, 2, 3});
  CHECK(runs.has_time);
  const auto ev = Iso230_2Evaluation().run(runs);
  const IsoFigures& f = ev.figures;
  CHECK(f.k_up == 2);
  CHECK(f.mean_up == std::vector<double>{2, 6, 3});
  CHECK(f.mean_down == std::vector<double>{-1, 4, 7});
  CHECK(f.s_up == std::vector<double>{1, 2, 3});
  CHECK(f.s_down == std::vector<double>{1, 0, 2});
  CHECK(f.B_i == std::vector<double>{3, 2, -4});
  CHECK(f.R_i_up == std::vector<double>{4, 8, 12});
  CHECK(f.R_i_down == std::vector<double>{4, 0, 8});
  CHECK(f.R_i == std::vector<double>{7, 8, 14});
  CHECK(f.mean_bi == std::vector<double>{0.5, 5, 5});
  CHECK(f.B == 4);
  CHECK(f.B_mean == doctest::Approx(1.0 / 3).epsilon(1e-15));
  CHECK(f.R_up == 12);
  CHECK(f.R_down == 8);
  CHECK(f.R == 14);
  CHECK(f.E_up == 4);
  CHECK(f.E_down == 8);
  CHECK(f.E == 8);
  CHECK(f.M == 4.5);
  CHECK(f.A_up == 13);
  CHECK(f.A_down == 14);
  CHECK(f.A == 14);
}

// Student-t widened set: k = t_{p,2} with p = Φ(2). For 2 degrees of freedom the t CDF is
// 1/2 + t/(2 sqrt(t² + 2)), so k = a sqrt(2/(1 - a²)) with a = 2p - 1 = erf(√2): k = 4.5265...
// With s as above: R↑ = 2k·3 = 6k, R↓ = 2k·2 = 4k; R_i = max(k s↑ + k s↓ + |B_i|, 2k s↑, 2k s↓):
// max(2k + 3, 2k, 2k) = 2k + 3; max(2k + 2, 4k, 0) = 4k; max(5k + 4, 6k, 4k) = 6k (k > 4): R = 6k.
// A↑ = max(2 + k, 6 + 2k, 3 + 3k) - min(2 - k, 6 - 2k, 3 - 3k) = (3 + 3k) - (3 - 3k) = 6k;
// A↓ = (7 + 2k) - (-1 - k) = 8 + 3k; A = (3 + 3k) - (3 - 3k) = 6k. B, E, M as for k = 2.
TEST_CASE("iso230-2: hand-computed example, the Student-t widened set") {
  const double a = std::erf(std::sqrt(2.0));
  const double k = a * std::sqrt(2 / (1 - a * a));
  CHECK(k == doctest::Approx(4.5265).epsilon(1e-4));
  CHECK(student_coverage_factor(2) == doctest::Approx(k).epsilon(1e-12));
  // One degree of freedom: Cauchy, k = tan(π (p - 1/2)).
  CHECK(student_coverage_factor(1) == doctest::Approx(std::tan(M_PI * a / 2)).epsilon(1e-12));
  CHECK(student_coverage_factor(1000000) == doctest::Approx(2.0).epsilon(1e-5));
  for (std::size_t dof = 1; dof < 60; ++dof)
    CHECK(student_coverage_factor(dof) > student_coverage_factor(dof + 1));

  const auto ev = Iso230_2Evaluation().run(runs_of(read_measurements(small_csv())));
  REQUIRE(ev.student);
  const IsoFigures& s = *ev.student;
  CHECK(s.k_up == doctest::Approx(k).epsilon(1e-12));
  CHECK(s.R_up == doctest::Approx(6 * k).epsilon(1e-12));
  CHECK(s.R_down == doctest::Approx(4 * k).epsilon(1e-12));
  CHECK(s.R_i[0] == doctest::Approx(2 * k + 3).epsilon(1e-12));
  CHECK(s.R_i[1] == doctest::Approx(4 * k).epsilon(1e-12));
  CHECK(s.R == doctest::Approx(6 * k).epsilon(1e-12));
  CHECK(s.A_up == doctest::Approx(6 * k).epsilon(1e-12));
  CHECK(s.A_down == doctest::Approx(8 + 3 * k).epsilon(1e-12));
  CHECK(s.A == doctest::Approx(6 * k).epsilon(1e-12));
  CHECK(s.B == 4);
  CHECK(s.E == 8);
  CHECK(s.M == 4.5);
}

// Drift elimination of the small example, reference X = 0, cycle 1.
// Adjacent differences (per cycle): up 0→100: 3 4 5 (mean 4, s 1), 100→200: -4 -3 -2 (mean -3,
// s 1); down 0→100: 6 5 4 (mean 5, s 1), 100→200: 1 3 5 (mean 3, s 2).
// Chart up: x̂ = 1 (cycle 1 at X=0), 1 + 4 = 5, 5 - 3 = 2; down: -2, 3, 6.
// s* = s/√2 of the difference toward the reference (the reference takes its neighbour's):
// up 1/√2 ×3; down 1/√2, 1/√2, 2/√2.
// B_i = 3, 2, -4: B = 4, B̄ = 1/3. R↑ = 4/√2 = 2√2, R↓ = 8/√2 = 4√2.
// R_i = max(2/√2 + 2/√2 + 3, ...) = 2√2 + 3; 2√2 + 2; 1/√2·2 + 2·√2 + 4 = 3√2 + 4: R = 4 + 3√2.
// x̄ = -0.5, 4, 4: M = 4.5; E↑ = 5 - 1 = 4, E↓ = 6 + 2 = 8, E = 6 + 2 = 8.
// A↑ = (5 + √2) - (1 - √2) = 4 + 2√2; A↓ = (6 + 2√2) - (-2 - √2) = 8 + 3√2; A = 8 + 3√2.
// Drift per cycle: residuals from the target means, averaged over targets: up (-2, 0, 2), down
// (-1, 0, 1); relative to cycle 1: up 0 2 4, down 0 1 2, mean 0 1.5 3. Slope against the cycle
// (one intercept per target and direction): Σ(u-ū)(y-ȳ) = 2(1+2+3) + 2(1+0+2) = 18 over
// Σ(u-ū)² = 6·2 = 12: 1.5 um/cycle; residual sum of squares 11 on 18 - 6 - 1 = 11 degrees of
// freedom: σ̂² = 1, se = sqrt(1/12).
TEST_CASE("iso230-2: hand-computed example, drift elimination and drift per cycle") {
  const IsoRuns runs = runs_of(read_measurements(small_csv()));
  const auto de = DriftElimination().run(runs);
  const DriftResult& d = de;
  CHECK(d.reference_target == 0);
  CHECK(d.reference_cycle == 1);
  CHECK(d.differences[kUp].mean == std::vector<double>{4, -3});
  CHECK(d.differences[kUp].s == std::vector<double>{1, 1});
  CHECK(d.differences[kDown].mean == std::vector<double>{5, 3});
  CHECK(d.differences[kDown].s == std::vector<double>{1, 2});
  CHECK(d.differences[kDown].sem[1] == doctest::Approx(2 / std::sqrt(3.0)).epsilon(1e-15));
  CHECK(d.chart[kUp].value == std::vector<double>{1, 5, 2});
  CHECK(d.chart[kDown].value == std::vector<double>{-2, 3, 6});
  CHECK(d.chart[kDown].s_diff == std::vector<double>{1, 1, 2});
  CHECK(d.chart[kDown].s[2] == doctest::Approx(kSqrt2).epsilon(1e-15));
  const IsoFigures& f = d.figures;
  CHECK(f.B_i == std::vector<double>{3, 2, -4});
  CHECK(f.B == 4);
  CHECK(f.B_mean == doctest::Approx(1.0 / 3).epsilon(1e-15));
  CHECK(f.R_up == doctest::Approx(2 * kSqrt2).epsilon(1e-15));
  CHECK(f.R_down == doctest::Approx(4 * kSqrt2).epsilon(1e-15));
  CHECK(f.R_i[0] == doctest::Approx(2 * kSqrt2 + 3).epsilon(1e-15));
  CHECK(f.R_i[1] == doctest::Approx(2 * kSqrt2 + 2).epsilon(1e-15));
  CHECK(f.R == doctest::Approx(4 + 3 * kSqrt2).epsilon(1e-15));
  CHECK(f.M == 4.5);
  CHECK(f.E_up == 4);
  CHECK(f.E_down == 8);
  CHECK(f.E == 8);
  CHECK(f.A_up == doctest::Approx(4 + 2 * kSqrt2).epsilon(1e-15));
  CHECK(f.A_down == doctest::Approx(8 + 3 * kSqrt2).epsilon(1e-15));
  CHECK(f.A == doctest::Approx(8 + 3 * kSqrt2).epsilon(1e-15));
  // Three targets: no difference has a same-parity partner, nothing is tested.
  CHECK(d.tests == 0);
  CHECK(std::isnan(d.differences[kUp].p_value[0]));
  CHECK(d.anomalous_positions.empty());
  // s ratio: up sqrt((1+1)/2) / sqrt((1+4+9)/3) = sqrt(3/14); down sqrt(5/2)/sqrt(5/3).
  CHECK(d.s_ratio[kUp] == doctest::Approx(std::sqrt(3.0 / 14)).epsilon(1e-14));
  CHECK(d.s_ratio[kDown] == doctest::Approx(std::sqrt(1.5)).epsilon(1e-14));

  const DriftPerCycle& p = d.per_cycle;
  CHECK(p.cycles == std::vector<long>{1, 2, 3});
  CHECK(p.offset_up == std::vector<double>{0, 2, 4});
  CHECK(p.offset_down == std::vector<double>{0, 1, 2});
  CHECK(p.offset == std::vector<double>{0, 1.5, 3});
  CHECK(p.rate_per_cycle == doctest::Approx(1.5).epsilon(1e-14));
  CHECK(p.rate_per_cycle_se == doctest::Approx(std::sqrt(1.0 / 12)).epsilon(1e-14));
  // Cycle j's six observations are at 360(j-1) + 0, 60, ..., 300 s: mean 360(j-1) + 150 s.
  REQUIRE(p.time_h.size() == 3);
  CHECK(p.time_h[0] == doctest::Approx(150.0 / 3600).epsilon(1e-14));
  CHECK(p.time_h[2] == doctest::Approx(870.0 / 3600).epsilon(1e-14));
  // Rate per hour: the same within-group regression on time, checked against a dummy-variable
  // least-squares fit (one column per target and direction, one for time).
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(18, 7);
  Eigen::VectorXd y(18);
  int row = 0;
  for (int dir = 0; dir < 2; ++dir)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j, ++row) {
        X(row, dir * 3 + i) = 1;
        X(row, 6) = runs.t[dir][i][j] / 3600;
        y(row) = runs.x[dir][i][j];
      }
  const Eigen::VectorXd beta = X.colPivHouseholderQr().solve(y);
  CHECK(p.rate_per_h == doctest::Approx(beta(6)).epsilon(1e-10));

  // Another reference: X = 100 mm, cycle 2. Chart up: 6 at X=100, 6 - 4 = 2, 6 - 3 = 3.
  DriftOptions o;
  o.reference_position_mm = 100;
  o.reference_cycle = 2;
  const auto de2 = DriftElimination(o).run(runs);
  CHECK(de2.reference_target == 1);
  CHECK(de2.chart[kUp].value == std::vector<double>{2, 6, 3});
  CHECK(de2.per_cycle.offset_up == std::vector<double>{-2, 0, 2});
  o.reference_cycle = 7;
  CHECK_THROWS_WITH_AS(DriftElimination(o).run(runs),
                       "--reference-cycle 7: not a cycle of direction +1 (cycles 1 to 3)",
                       std::invalid_argument);
  o.reference_cycle.reset();
  o.reference_position_mm = 50;
  CHECK_THROWS_WITH_AS(DriftElimination(o).run(runs),
                       "--reference-position 50: not a target (targets: 0, 100, 200 mm)",
                       std::invalid_argument);
}

// ---- Invariants ------------------------------------------------------------------------------

TEST_CASE("iso230-2: invariants on random data (B = 0 when directions agree, R >= R up ...)") {
  Normal rng(20240502);
  for (int rep = 0; rep < 300; ++rep) {
    const std::size_t m = 2 + static_cast<std::size_t>(rng.uniform() * 9);
    const long n = 2 + static_cast<long>(rng.uniform() * 7);
    const double b = 3 * rng();
    const bool agree = rep % 3 == 0;
    std::vector<IsoObservation> obs;
    for (std::size_t i = 0; i < m; ++i) {
      const double f = 5 * rng();
      for (long j = 1; j <= n; ++j) {
        const double up = f + b / 2 + rng();
        obs.push_back({static_cast<double>(i) * 25.0, +1, j, up, NAN, 0});
        obs.push_back(
            {static_cast<double>(i) * 25.0, -1, j, agree ? up : f - b / 2 + rng(), NAN, 0});
      }
    }
    const IsoRuns runs = group_iso_runs(obs, "random");
    const auto ev = Iso230_2Evaluation().run(runs);
    const IsoFigures& f = ev.figures;
    CAPTURE(rep);
    check_invariants(f);
    check_invariants(*ev.student);
    CHECK(ev.student->R >= f.R);
    CHECK(ev.student->A >= f.A);
    if (agree) {
      CHECK(f.B == 0);
      CHECK(f.B_mean == 0);
      CHECK(f.E == f.E_up);
      CHECK(f.M == f.E_up);
    }
    const auto de = DriftElimination().run(runs);
    check_invariants(de.figures);
    if (agree) CHECK(de.figures.B == 0);
  }
}

// ---- Drift elimination on synthetic data --------------------------------------------------

// x_ij = profile(P_i) ± reversal/2 + c t_ij + N(0, σ²). The rebuilt chart relative to the
// reference target r is x̄_i - x̄_r: the static profile difference, plus c (t̄_i - t̄_r) (the
// drift within one pass, which differences cannot remove: i·dt in the up pass), plus noise of
// standard deviation σ sqrt(2/n). Bound: 5 σ sqrt(2/n) per target (32 targets × 2-sided
// P(|z| > 5) = 2e-5).
TEST_CASE("iso230-2 drift: the rebuilt chart recovers the static profile within the noise") {
  Synth s;  // 16 targets, 30 cycles, 6 um/h, σ 0.5 um, 8 min per cycle, 4 h in all
  Normal rng(7);
  const IsoRuns runs = group_iso_runs(synth(s, rng), "synthetic");
  const auto de = DriftElimination().run(runs);
  const DriftResult& d = de;
  const double noise = 5 * s.sigma * std::sqrt(2.0 / static_cast<double>(s.n));
  const double c = s.drift_per_h / 3600;  // um/s
  for (int dir = 0; dir < 2; ++dir) {
    const auto& v = d.chart[dir].value;
    for (std::size_t i = 0; i < s.m; ++i) {
      const double rel = v[i] - v[0];
      const double truth = profile(runs.positions_mm[i]) - profile(0);
      const double lag = c * s.dt_s * static_cast<double>(i) * (dir == kUp ? 1 : -1);
      CAPTURE(dir);
      CAPTURE(i);
      CHECK(std::abs(rel - truth - lag) <= noise);
      CHECK(std::abs(rel - truth) <= noise + std::abs(c) * s.dt_s * static_cast<double>(s.m));
    }
  }
  // s* estimates σ (pooled over targets and directions: relative standard error about 3 %),
  // while the classical s is inflated by the drift (c·sd(t) = 6 um/h × 1.15 h ≈ 7 um).
  const auto ev = Iso230_2Evaluation().run(runs);
  double star2 = 0, classical2 = 0;
  for (int dir = 0; dir < 2; ++dir)
    for (std::size_t i = 0; i < s.m; ++i) {
      star2 += std::pow(d.chart[dir].s[i], 2) / (2.0 * static_cast<double>(s.m));
      classical2 += std::pow(dir == kUp ? ev.figures.s_up[i] : ev.figures.s_down[i], 2) /
                    (2.0 * static_cast<double>(s.m));
    }
  CHECK(std::abs(std::sqrt(star2) - s.sigma) < 0.15 * s.sigma);
  CHECK(std::sqrt(classical2) > 10 * s.sigma);
  CHECK(d.figures.R < 0.2 * ev.figures.R);
  // The drift: 6 um/h, 0.8 um per cycle (8 min).
  const DriftPerCycle& p = d.per_cycle;
  CHECK(p.rate_per_h_se < 0.05);
  CHECK(std::abs(p.rate_per_h - s.drift_per_h) < 5 * p.rate_per_h_se);
  CHECK(std::abs(p.rate_per_cycle - 0.8) < 0.02);
  for (std::size_t j = 0; j < s.n; ++j) {
    // offset_j = c (t_j - t_1) + mean noise difference (sd σ sqrt(2/m) = 0.18 um).
    CHECK(std::abs(p.offset[j] - 0.8 * static_cast<double>(j)) < 5 * s.sigma * 0.25 * kSqrt2);
  }
  CHECK(d.anomalous_positions.empty());
}

// Stejskal et al. 2017, eqs. (7)-(10): b_n = a_n - a_{n+1} of independent normal a_n has s_b / s_a
// = √2
// ("1.4076" from its Monte Carlo run on 1000 samples). One run of 1000 samples has a standard
// error of about 0.04 on the ratio; the mean of 1000 such runs has about 0.0013: tolerance 0.01.
TEST_CASE("iso230-2 drift: Stejskal et al. 2017's Monte Carlo check of s_b / s_a = sqrt(2)") {
  Normal rng(1000);
  double sum = 0;
  const int runs = 1000;
  for (int r = 0; r < runs; ++r) {
    std::vector<double> a(1000);
    for (double& x : a) x = 3 + 0.7 * rng();
    sum += difference_sd_ratio(a);
  }
  CHECK(std::abs(sum / runs - kSqrt2) < 0.01);

  // The same ratio in the evaluation: without drift, the pooled s of the adjacent differences
  // over the pooled classical s is √2 (200 runs of 16 targets × 10 cycles; the per-run ratio
  // has a standard error of about 0.06, the mean about 0.004: tolerance 0.03).
  Synth s;
  s.n = 10;
  s.drift_per_h = 0;
  double ratio = 0;
  for (int r = 0; r < 200; ++r) {
    const IsoRuns runs_ = group_iso_runs(synth(s, rng), "synthetic");
    const auto de = DriftElimination().run(runs_);
    ratio += (de.s_ratio[kUp] + de.s_ratio[kDown]) / 400;
  }
  CHECK(std::abs(ratio - kSqrt2) < 0.03);
}

// ---- The anomaly test ------------------------------------------------------------------------

TEST_CASE(
    "iso230-2 drift: Stejskal et al. 2017's 'position 3' anomaly is found, at the stated "
    "false-positive rate") {
  // Power: target 3 (index 2) with 4× the noise in the up direction, under drift.
  Synth s;
  s.noisy_target = 2;
  Normal rng(3);
  const IsoRuns runs = group_iso_runs(synth(s, rng), "synthetic");
  const auto de = DriftElimination().run(runs);
  const DriftResult& d = de;
  CHECK(d.tests == 2 * 15);
  REQUIRE(d.anomalous_positions.size() == 1);
  CHECK(d.anomalous_positions[0].direction == +1);
  CHECK(d.anomalous_positions[0].target == 2);
  REQUIRE(d.anomalous_differences.size() == 2);
  CHECK(d.anomalous_differences[0].from == 1);
  CHECK(d.anomalous_differences[1].from == 2);
  CHECK(d.differences[kUp].flagged[1]);
  CHECK(d.differences[kUp].flagged[2]);
  for (bool f : d.differences[kDown].flagged) CHECK(!f);

  // Under H0 every F is exact: the fraction of p < 0.1 is 0.1 (6000 up-direction tests,
  // correlated within a run through their pools: standard error below 0.008; a 4000-run check
  // gave 0.0994), and the Bonferroni family-wise rate is at most alpha (400 runs: standard error
  // 0.011; the 4000-run check gave 0.047 for alpha = 0.05).
  Synth h;
  h.n = 10;
  const double alpha = 0.05;
  int any = 0, below = 0;
  const int runs_n = 400;
  for (int r = 0; r < runs_n; ++r) {
    const IsoRuns null_runs = group_iso_runs(synth(h, rng), "synthetic");
    DriftOptions o;
    o.alpha = alpha;
    const auto n = DriftElimination(o).run(null_runs);
    any += n.anomalous_differences.empty() ? 0 : 1;
    for (double pv : n.differences[kUp].p_value) below += pv < 0.1 ? 1 : 0;
  }
  CHECK(static_cast<double>(any) / runs_n <= alpha + 3 * 0.011);
  CHECK(std::abs(static_cast<double>(below) / (15.0 * runs_n) - 0.1) < 0.03);
}

// ---- Grouping and column errors -------------------------------------------------------------

TEST_CASE("iso230-2: grouping of targets and bad runs name the file and line") {
  // Targets within 1e-6 mm are one target (the mean of its 4 positions); the order of rows does
  // not matter.
  const IsoRuns r = runs_of_text(
      "X,dir,cycle,dx_um\n100.0000004,1,2,4\n0,1,1,1\n100,1,1,2\n0,-1,1,0\n0,1,2,3\n"
      "100,-1,2,1\n100,-1,1,1\n0,-1,2,2\n");
  REQUIRE(r.positions_mm.size() == 2);
  CHECK(r.positions_mm[1] == doctest::Approx(100.0000001).epsilon(1e-13));
  CHECK(r.x[kUp][1] == std::vector<double>{2, 4});
  CHECK(!r.has_time);

  const std::string head = "X,dir,cycle,dx_um\n";
  CHECK(error_of(head + "0,1,1,1\n0,1,2,1\n0,-1,1,1\n0,1,1,5\n0,-1,2,1\n") ==
        "d.csv:5: target 0 mm, direction +1, cycle 1 is measured twice (also line 2)");
  CHECK(error_of(head + "0,1,1,1\n0,1,2,1\n0,-1,1,1\n100,1,1,1\n100,1,2,1\n100,-1,1,1\n"
                        "100,-1,2,1\n") ==
        "d.csv:4: target 0 mm, direction -1: no observation in cycle 2 (every target of a "
        "direction needs the 2 cycles 1, 2)");
  CHECK(error_of(head + "0,1,1,1\n0,-1,1,1\n") ==
        "d.csv: direction +1 has 1 cycle (1): ISO 230-2 needs at least 2 cycles per target and "
        "direction (the standard asks for 5)");
  CHECK(error_of(head + "0,1,1,1\n0,1,2,1\n0,-1,1,1\n0,-1,2,1\n50,1,1,1\n50,1,2,1\n") ==
        "d.csv:6: target 50 mm is measured in direction +1 but not in direction -1 (both "
        "directions need the same targets)");
  CHECK(error_of(head + "0,1,1,1\n0,1,2,1\n") ==
        "d.csv: no observation in direction -1: ISO 230-2 needs both approach directions "
        "(column dir or dir_<axis>)");
  CHECK(error_of(head + "0,1,1,\n") == "d.csv: no observations (no row has a measured deviation)");
  CHECK(error_of(head + "0,,1,2\n") ==
        "d.csv:2:3: column 'dir' is empty but 'dx_um' is measured (every observation needs its "
        "position, direction and cycle)");
  CHECK(error_of("X,cycle,dx_um\n0,1,2\n") ==
        "d.csv:1: missing column 'dir' or 'dir_X' (the approach direction, +1 or -1; columns: "
        "X, cycle, dx_um)");
  CHECK(error_of("X,dir,dx_um\n0,1,2\n") ==
        "d.csv: missing column 'cycle' (columns: X, dir, dx_um)");
  CHECK(error_of("X,dir,cycle,dy_um\n0,1,1,2\n") ==
        "d.csv: missing column 'dx_um' (columns: X, dir, cycle, dy_um)");
  CHECK(error_of("X,Y,dir,cycle,dx_um\n0,0,1,1,2\n1,1,1,1,2\n") ==
        "d.csv:1: several coordinate columns (X, Y), X, Y varying: say which axis with --axis "
        "or a '# axis: X' header line");
  // Directions without a common cycle: no default reference cycle for the drift elimination.
  const IsoRuns apart = runs_of_text(head +
                                     "0,1,1,1\n0,1,2,1\n0,-1,3,1\n0,-1,4,1\n9,1,1,1\n"
                                     "9,1,2,1\n9,-1,3,1\n9,-1,4,1\n");
  CHECK_THROWS_WITH_AS(DriftElimination().run(apart),
                       "d.csv: the two directions share no cycle id: the drift elimination needs "
                       "a reference cycle measured in both directions",
                       InputError);
  CHECK(error_of("# axis: Q\nX,dir,cycle,dx_um\n0,1,1,2\n") ==
        "d.csv:1: axis: 'Q' is not a coordinate column (coordinate columns: X)");
}

TEST_CASE("iso230-2: column choice by --axis, dir_<axis>, the varying axis and --column") {
  const MeasurementTable t = parse_measurements(
      "X,Y,Z,dir_Y,dir,cycle,dy_um,dx_um,cov_alt\n0,0,5,1,1,1,2,0,1\n0,10,5,1,1,1,2,0,1\n",
      "e.csv");
  const IsoColumns c = iso_columns(t);  // Y is the only coordinate that varies
  CHECK(c.axis == "Y");
  CHECK(c.direction == "dir_Y");
  CHECK(c.deviation == "dy_um");
  CHECK(c.time.empty());
  const IsoColumns x = iso_columns(t, "X");
  CHECK(x.direction == "dir");
  CHECK(x.deviation == "dx_um");
  CHECK(iso_columns(t, "Y", "cov_alt").deviation == "cov_alt");
  CHECK_THROWS_WITH_AS(iso_columns(t, "A"),
                       "--axis A: e.csv has no coordinate column 'A' (coordinate columns: X, Y, Z)",
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(iso_columns(t, "Y", "dq_um"),
                       "--column dq_um: e.csv has no such column (columns: X, Y, Z, dir_Y, dir, "
                       "cycle, dy_um, dx_um, cov_alt)",
                       std::invalid_argument);
  CHECK_THROWS_AS(iso_columns(t, "Y", "cycle"), std::invalid_argument);
}

// ---- CLI -------------------------------------------------------------------------------------

TEST_CASE("iso230-2 CLI: the small example, its tables and JSON") {
  const auto dir = test::fresh_dir("cli_iso230_2");
  const std::string out = (dir / "iso.json").string();
  const Run r = run(cli("iso230-2 " + small_csv() + " --json " + out));
  REQUIRE(r.status == 0);
  CHECK(r.out.find("axis X (deviation dx_um), 3 targets, 3 cycles up, 3 cycles down") !=
        std::string::npos);
  CHECK(r.out.find("bidirectional accuracy") != std::string::npos);
  CHECK(r.out.find("wrote " + out) != std::string::npos);
  const json j = read_json(out);
  CHECK(j["verb"] == "iso230-2");
  CHECK(j["weilgen"] == kVersion);
  CHECK(j["axis"] == "X");
  CHECK(j["column"] == "dx_um");
  CHECK(j["deviation_unit"] == "um");
  CHECK(j["positions_mm"] == json({0, 100, 200}));
  const std::map<std::string, double> expect = {
      {"B_um", 4},     {"R_up_um", 12},   {"R_down_um", 8}, {"R_um", 14},
      {"E_up_um", 4},  {"E_down_um", 8},  {"E_um", 8},      {"M_um", 4.5},
      {"A_up_um", 13}, {"A_down_um", 14}, {"A_um", 14}};
  for (const auto& [k, v] : expect) CHECK(j[k].get<double>() == v);
  CHECK(j["B_mean_um"].get<double>() == doctest::Approx(1.0 / 3));
  CHECK(j["mean_up_um"] == json({2, 6, 3}));
  CHECK(j["mean_down_um"] == json({-1, 4, 7}));
  CHECK(j["s_up_um"] == json({1, 2, 3}));
  CHECK(j["s_down_um"] == json({1, 0, 2}));
  CHECK(j["B_i_um"] == json({3, 2, -4}));
  CHECK(j["R_i_up_um"] == json({4, 8, 12}));
  CHECK(j["R_i_down_um"] == json({4, 0, 8}));
  CHECK(j["R_i_um"] == json({7, 8, 14}));
  CHECK(j["mean_bi_um"] == json({0.5, 5, 5}));
  CHECK(j["student"]["A_down_um"].get<double>() ==
        doctest::Approx(8 + 3 * student_coverage_factor(2)));
  const json& d = j["drift_eliminated"];
  for (const char* k : {"B_um", "B_mean_um", "R_up_um", "R_down_um", "R_um", "E_up_um", "E_down_um",
                        "E_um", "M_um", "A_up_um", "A_down_um", "A_um"})
    CHECK(d.contains(k));
  CHECK(d["R_um"].get<double>() == doctest::Approx(4 + 3 * kSqrt2));
  CHECK(d["A_um"].get<double>() == doctest::Approx(8 + 3 * kSqrt2));
  CHECK(d["mean_up_um"] == json({1, 5, 2}));
  CHECK(d["reference_position_mm"] == 0);
  CHECK(d["reference_cycle"] == 1);
  CHECK(d["adjacent_differences"]["down"]["s_um"] == json({1, 2}));
  CHECK(d["adjacent_differences"]["up"]["p_value"] == json({nullptr, nullptr}));
  CHECK(j["drift_per_cycle"]["offset_um"] == json({0, 1.5, 3}));
  CHECK(j["drift_per_cycle"]["rate_um_per_cycle"].get<double>() == doctest::Approx(1.5));
  CHECK(j["drift_per_cycle"]["rate_um_per_h"].is_number());
  CHECK(j["anomalous_positions"] == json::array());
  CHECK(j["anomaly_test"]["tests"] == 0);

  // --reference-cycle and --reference-position.
  const Run r2 = run(cli("iso230-2 " + small_csv() +
                         " --reference-position 100 --reference-cycle 2 --json " + out));
  REQUIRE(r2.status == 0);
  CHECK(read_json(out)["drift_eliminated"]["mean_up_um"] == json({2, 6, 3}));
}

TEST_CASE("iso230-2 CLI: bad input exits 3, bad flags exit 2, and nothing is written") {
  const auto dir = test::fresh_dir("cli_iso230_2_bad");
  const std::string out = (dir / "iso.json").string();
  write_file_atomically(out, "old\n");
  const std::string bad = (dir / "bad.csv").string();
  write_file_atomically(bad, "X,dir,cycle,dx_um\n0,1,1,1\n0,1,2,abc\n");
  auto unchanged = [&] {
    std::string text;
    REQUIRE(read_file(out, text));
    CHECK(text == "old\n");
  };
  Run r = run(cli("iso230-2 " + bad + " --json " + out));
  CHECK(r.status == 3);
  CHECK(r.out == bad + ":3:7: column 'dx_um': 'abc' is not a number\n");
  unchanged();
  write_file_atomically(bad, "X,dir,cycle,dx_um\n0,1,1,1\n0,-1,1,1\n");
  r = run(cli("iso230-2 " + bad + " --json " + out));
  CHECK(r.status == 3);
  CHECK(r.out.find("needs at least 2 cycles") != std::string::npos);
  unchanged();
  r = run(cli("iso230-2 " + (dir / "missing.csv").string() + " --json " + out));
  CHECK(r.status == 3);
  CHECK(r.out.find("missing.csv: cannot read the data file: no such file") != std::string::npos);
  unchanged();
  r = run(cli("iso230-2 " + small_csv() + " --axis Q --json " + out));
  CHECK(r.status == 2);
  CHECK(r.out.find("--axis Q: ") != std::string::npos);
  unchanged();
  r = run(cli("iso230-2 " + small_csv() + " --alpha 1.5 --json " + out));
  CHECK(r.status == 2);
  CHECK(r.out.rfind(
            "weilgen iso230-2: --alpha: '1.5' is out of range (allowed: a number in (0, 1))", 0) ==
        0);
  r = run(cli("iso230-2 " + small_csv() + " --reference-cycle 9 --json " + out));
  CHECK(r.status == 2);
  unchanged();
  r = run(
      cli("iso230-2 " + small_csv() + " --plot " + (dir / "x.pdf").string() + " --json " + out));
  CHECK(r.status == 2);
  CHECK(!std::filesystem::exists(dir / "x.pdf"));
  unchanged();
  r = run(cli("iso230-2 " + small_csv() + " --no-such-flag"));
  CHECK(r.status == 2);
  r = run(cli("iso230-2"));
  CHECK(r.status == 2);
  // Unknown columns: an error, or a warning with --allow-unknown.
  write_file_atomically(bad,
                        "X,dir,cycle,dx_um,load\n0,1,1,1,0\n0,1,2,1,0\n0,-1,1,1,0\n"
                        "0,-1,2,2,0\n");
  r = run(cli("iso230-2 " + bad + " --json " + out));
  CHECK(r.status == 3);
  CHECK(r.out.find(bad + ":1: unknown column 'load'") == 0);
  unchanged();
  r = run(cli("iso230-2 " + bad + " --allow-unknown"));
  CHECK(r.status == 0);
  CHECK(r.out.find(bad + ":1:19: unknown column 'load' (kept, not interpreted)") == 0);
  CHECK(r.out.find("Drift elimination: needs at least 2 targets") != std::string::npos);
}

TEST_CASE(
    "iso230-2 CLI: the drift example finds Stejskal et al. 2017's position 3 and draws the "
    "charts") {
  const std::string data = std::string(WEILGEN_SOURCE_DIR) + "/examples/data/iso230_2_drift.csv";
  const auto dir = test::fresh_dir("cli_iso230_2_drift");
  const std::string out = (dir / "drift.json").string();
  std::string plot_flag;
  if (gnuplot_available()) plot_flag = " --plot " + (dir / "drift.svg").string();
  const Run r = run(cli("iso230-2 " + data + " --json " + out + plot_flag));
  REQUIRE(r.status == 0);
  CHECK(r.out.find("anomalous position: X=40 mm (target 3), dir +1") != std::string::npos);
  const json j = read_json(out);
  CHECK(j["targets"] == 16);
  CHECK(j["cycles_up"].size() == 30);
  REQUIRE(j["anomalous_positions"].size() == 1);
  CHECK(j["anomalous_positions"][0]["position_mm"] == 40);
  // The generator's drift is 4 um/h and its noise 0.4 um (bench/experiments/make_iso_drift_data).
  CHECK(std::abs(j["drift_per_cycle"]["rate_um_per_h"].get<double>() - 4) < 0.2);
  CHECK(j["drift_eliminated"]["R_up_um"].get<double>() < j["R_up_um"].get<double>() / 3);
  if (!plot_flag.empty()) {
    std::string svg;
    REQUIRE(read_file((dir / "drift.svg").string(), svg));
    CHECK(svg.find("<svg") != std::string::npos);
    CHECK(svg.find("drift eliminated") != std::string::npos);
  }
}
