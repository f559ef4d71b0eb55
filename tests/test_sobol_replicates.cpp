// Randomised QMC for the Sobol' indices: the scrambled sequence, the batched evaluation and the
// replicate intervals, whose coverage of exact indices is checked at the nominal rate (on a
// linear function and on the gantry grinder's order-1 model, where S = S_exact exactly).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "weilgen/analysis/sensitivity_study.hpp"
#include "weilgen/analysis/study.hpp"
#include "weilgen/uq/sobol_indices.hpp"
#include "weilgen/uq/sobol_sequence.hpp"

using namespace weilgen;

namespace {

// Equal element by element, NaN equal to NaN (intervals that were not computed).
bool same(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!(a[i] == b[i] || (std::isnan(a[i]) && std::isnan(b[i])))) return false;
  return true;
}

// A coverage rate of `covered` out of `n` independent 95 % intervals is consistent with the
// nominal rate: within 3.5 binomial standard deviations of 0.95 (two-sided, ~5e-4 false alarm).
void check_nominal(int covered, int n, const std::string& what) {
  const double rate = static_cast<double>(covered) / n;
  const double sd = std::sqrt(0.95 * 0.05 / n);
  INFO(what << ": coverage " << covered << "/" << n << " = " << rate << ", nominal 0.95 +- "
            << 3.5 * sd);
  CHECK(std::abs(rate - 0.95) <= 3.5 * sd);
}

}  // namespace

TEST_CASE("Sobol' sequence: linear matrix scrambling keeps the net and randomises the points") {
  SobolSequence net(7, 777, true);
  std::vector<double> p(7);
  // The first 2^m points put one point in each interval of length 2^-m of every coordinate,
  // for every m <= 10; coordinates 1 and 2 also one point in each 2^-3 x 2^-3 square of the
  // first 64 points.
  std::vector<std::vector<double>> pts;
  for (int n = 0; n < 1024; ++n) {
    net.next(p.data());
    for (double u : p) REQUIRE((u > 0.0 && u < 1.0));
    pts.push_back(p);
  }
  for (int m = 1; m <= 10; ++m) {
    const std::size_t cells = std::size_t{1} << m;
    for (std::size_t d = 0; d < 7; ++d) {
      std::vector<int> hits(cells, 0);
      for (std::size_t n = 0; n < cells; ++n) ++hits[static_cast<std::size_t>(pts[n][d] * cells)];
      CAPTURE(m);
      CAPTURE(d);
      CHECK(std::all_of(hits.begin(), hits.end(), [](int c) { return c == 1; }));
    }
  }
  std::vector<int> squares(64, 0);
  for (std::size_t n = 0; n < 64; ++n)
    ++squares[static_cast<std::size_t>(pts[n][0] * 8) * 8 +
              static_cast<std::size_t>(pts[n][1] * 8)];
  CHECK(std::all_of(squares.begin(), squares.end(), [](int c) { return c == 1; }));
  // Scrambling changes more than the digital shift: with the same seed (hence the same shift,
  // which is point 0 = L 0 ^ s of both) every later point differs; other seeds differ anywhere.
  SobolSequence shifted(7, 777), other(7, 778, true);
  std::vector<double> q(7), r(7);
  int differ = 0;
  for (int n = 0; n < 64; ++n) {
    shifted.next(q.data());
    other.next(r.data());
    differ += q != pts[static_cast<std::size_t>(n)];
    CHECK(r != pts[static_cast<std::size_t>(n)]);
  }
  CHECK(differ == 63);
  // next_block and discard give the same points as next().
  SobolSequence blocks(7, 777, true), skip(7, 777, true);
  std::vector<double> block(7 * 100);
  blocks.discard(300);
  blocks.next_block(100, block.data(), 100);
  for (std::size_t j = 0; j < 100; ++j)
    for (std::size_t d = 0; d < 7; ++d) REQUIRE(block[d * 100 + j] == pts[300 + j][d]);
  skip.discard(1000);
  skip.next(q.data());
  CHECK(q == pts[1000]);
  CHECK_THROWS_WITH_AS(SobolSequence(3, 0, true), doctest::Contains("seed != 0"),
                       std::invalid_argument);
}

TEST_CASE("Sobol' indices: batched and per-point functions give bit-identical results") {
  const std::vector<InputDistribution> inputs = {
      InputDistribution::normal(0, 1), InputDistribution::uniform(-1, 2),
      InputDistribution::normal(3, 0), InputDistribution::normal(1, 0.5)};
  const auto g = [](const double* x, double* y) {
    y[0] = x[0] * x[1] + std::sin(x[3]) + x[2];
    y[1] = x[0] + 2 * x[3] * x[3];
  };
  for (SobolIntervals iv :
       {SobolIntervals::Replicates, SobolIntervals::Bootstrap, SobolIntervals::None}) {
    SobolOptions o;
    o.samples = 3000;  // not a multiple of 64 or 1024: partial batches and chunks
    o.intervals = iv;
    o.bootstrap = 30;
    o.replicates = 6;
    o.seed = 4;
    const SobolDesign design(inputs, o);
    std::size_t largest = 0;
    const SobolResult a = SobolAnalysis(o).run(
        design, 2, [&](unsigned, std::size_t count, const double* x, double* y) {
          largest = std::max(largest, count);
          for (std::size_t j = 0; j < count; ++j) g(x + 4 * j, y + 2 * j);
        });
    const SobolResult b =
        SobolAnalysis(o).run(design, 2, [&](unsigned, const double* x, double* y) { g(x, y); });
    const std::string method = interval_method_name(iv);
    CAPTURE(method);
    CHECK(largest <= kSobolMaxBatch);
    // A streamed design (rows made block by block) gives the same numbers as a stored one.
    const SobolDesign streamed(inputs, o, false);
    CHECK(streamed.stored() == (iv == SobolIntervals::Bootstrap));
    const SobolResult c = SobolAnalysis(o).run(
        streamed, 2, [&](unsigned, std::size_t count, const double* x, double* y) {
          for (std::size_t j = 0; j < count; ++j) g(x + 4 * j, y + 2 * j);
        });
    for (std::size_t out = 0; out < 2; ++out) {
      CHECK(c.outputs[out].first == a.outputs[out].first);
      CHECK(same(c.outputs[out].total_lo, a.outputs[out].total_lo));
      CHECK(c.outputs[out].mean == a.outputs[out].mean);
    }
    CHECK(a.evaluations == 3000 * 5);
    CHECK(a.replicates == (iv == SobolIntervals::Replicates ? 6u : 1u));
    for (std::size_t out = 0; out < 2; ++out) {
      CHECK(a.outputs[out].first == b.outputs[out].first);
      CHECK(same(a.outputs[out].total_hi, b.outputs[out].total_hi));
      CHECK(a.outputs[out].variance == b.outputs[out].variance);
      CHECK(a.outputs[out].first[2] == 0.0);  // the constant input
    }
  }
}

TEST_CASE("Sobol' replicate intervals: Student t over replicates, nominal coverage, any threads") {
  // f = 10 + 3 X1 + X2 + 0 X3, X ~ N(0, I): S = S_T = (0.9, 0.1, 0).
  const std::vector<InputDistribution> inputs(3, InputDistribution::normal(0, 1));
  const std::vector<double> exact = {0.9, 0.1, 0.0};
  const auto f = [](unsigned, std::size_t count, const double* x, double* y) {
    for (std::size_t j = 0; j < count; ++j) y[j] = 10 + 3 * x[3 * j] + x[3 * j + 1];
  };
  // 400 seeds x 4 intervals (S_1, S_2, S_T1, S_T2), each interval's coverage checked on its
  // own over the seeds (the four of one seed are correlated). QMC with R = 4 (the default) and
  // R = 8 at N = 2^12 (n = 1024 and 512 per replicate) and R = 16 at N = 2^14; MC with R = 8 at
  // N = 2^12.
  struct Case {
    Sampling sampling;
    std::size_t samples, replicates;
  };
  for (const Case& c :
       {Case{Sampling::Qmc, 1u << 12, 4}, Case{Sampling::Qmc, 1u << 12, 8},
        Case{Sampling::Qmc, 1u << 14, 16}, Case{Sampling::MonteCarlo, 1u << 12, 8}}) {
    std::vector<int> covered(4, 0);
    double width = 0, error = 0;
    const int seeds = 400;
    for (int seed = 1; seed <= seeds; ++seed) {
      SobolOptions o;
      o.samples = c.samples;
      o.sampling = c.sampling;
      o.replicates = c.replicates;
      o.seed = static_cast<std::uint64_t>(seed);
      o.threads = 1;
      const SobolDesign design(inputs, o);
      const SobolIndices s = SobolAnalysis(o).run(design, 1, f).outputs[0];
      for (std::size_t i = 0; i < 2; ++i) {
        covered[2 * i] += s.first_lo[i] <= exact[i] && exact[i] <= s.first_hi[i];
        covered[2 * i + 1] += s.total_lo[i] <= exact[i] && exact[i] <= s.total_hi[i];
        width += (s.first_hi[i] - s.first_lo[i]) / (2.0 * seeds);
        error += std::abs(s.first[i] - exact[i]) / (2.0 * seeds);
        CHECK(s.first_lo[i] < s.first[i]);
        CHECK(s.first[i] < s.first_hi[i]);
      }
      // No effect: every replicate gives exactly 0, so does the interval.
      CHECK(s.first[2] == 0.0);
      CHECK(s.first_lo[2] == 0.0);
      CHECK(s.total_hi[2] == 0.0);
    }
    const std::string name = std::string(c.sampling == Sampling::Qmc ? "qmc" : "mc") +
                             " N=" + std::to_string(c.samples) +
                             " R=" + std::to_string(c.replicates);
    const char* labels[] = {"S_1", "S_T1", "S_2", "S_T2"};
    for (std::size_t q = 0; q < 4; ++q) check_nominal(covered[q], seeds, name + " " + labels[q]);
    // The intervals are as wide as the error is large: mean half-width / mean |error| of a
    // t interval is E(t_{R-1} quantile s / sqrt R) / E|mean error| = t c4(R) sqrt(pi/2):
    // 3.7 for R = 4, 2.9 for R = 8, 2.6 for R = 16.
    INFO(name << ": mean width " << width << ", mean error " << error);
    CHECK(width / 2 / error > 2.0);
    CHECK(width / 2 / error < 4.5);
  }
  // Bit-identical for 1, 2 and 3 threads, stored or streamed.
  std::vector<SobolIndices> by_threads;
  for (unsigned threads : {1u, 2u, 3u}) {
    SobolOptions o;
    o.samples = 5000;
    o.replicates = 5;
    o.threads = threads;
    const SobolDesign design(inputs, o, threads != 2);
    by_threads.push_back(SobolAnalysis(o).run(design, 1, f).outputs[0]);
  }
  for (std::size_t t = 1; t < 3; ++t) {
    CHECK(by_threads[t].first == by_threads[0].first);
    CHECK(by_threads[t].first_lo == by_threads[0].first_lo);
    CHECK(by_threads[t].total_hi == by_threads[0].total_hi);
    CHECK(by_threads[t].mean == by_threads[0].mean);
  }
}

TEST_CASE("Sobol' replicate intervals cover the grinder's exact indices at the nominal rate") {
  // The gantry grinder at order 1 is linear in its errors, so S_exact is the exact index.
  // dx at X=0, Y=1500, Z=600 (7 errors act on dx; 14 have index 0). 300 seeds, N = 2^12, R = 4.
  StudyRequest req;
  req.machine = std::string(WEILGEN_MACHINES_DIR) + "/gantry_grinder.yaml";
  req.at = {"X=0,Y=1500,Z=600"};
  req.threads = 1;
  const Study st = open_study(req, false);
  SensitivityOptions so;
  so.local = false;
  so.outputs = {OutputId::Dx};
  so.sobol_options.samples = 1u << 12;
  so.sobol_options.replicates = SobolOptions{}.replicates;  // the default, 4
  std::vector<int> covered(2 * st.model->num_errors(), 0);
  std::vector<char> acting(st.model->num_errors(), 0);
  const int seeds = 300;
  double worst = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    so.sobol_options.seed = static_cast<std::uint64_t>(seed);
    const SensitivityResult r = SensitivityStudy(so).run(st);
    CHECK(r.replicates == 4);
    for (std::size_t i = 0; i < r.errors; ++i) {
      const SensitivityRecord& x = r.at(0, 0, i);
      acting[i] = x.S_exact > 0;
      covered[2 * i] += x.S_lo <= x.S_exact && x.S_exact <= x.S_hi;
      covered[2 * i + 1] += x.ST_lo <= x.S_exact && x.S_exact <= x.ST_hi;
      worst = std::max({worst, std::abs(x.S - x.S_exact), std::abs(x.ST - x.S_exact)});
      if (!acting[i]) CHECK((x.S == 0.0 && x.S_lo == 0.0 && x.ST_hi == 0.0));
    }
  }
  int checked = 0;
  for (std::size_t i = 0; i < acting.size(); ++i) {
    if (!acting[i]) continue;
    const std::string name = st.model->description().errors[i].name;
    check_nominal(covered[2 * i], seeds, name + " S");
    check_nominal(covered[2 * i + 1], seeds, name + " ST");
    checked += 2;
  }
  CHECK(checked == 14);
  // The worst of 300 x 42 errors at n = 512 points per replicate (the 95 % half-widths are
  // about 0.005-0.01 here).
  INFO("worst error " << worst);
  CHECK(worst < 0.03);
}

TEST_CASE("Sobol' replicate options are range-checked with the field named") {
  SobolOptions o;
  o.replicates = 1;
  CHECK_THROWS_WITH_AS(o.validate(), doctest::Contains("replicates must be in [2, 1024]"),
                       std::invalid_argument);
  o.replicates = 1025;
  CHECK_THROWS_AS(o.validate(), std::invalid_argument);
  o.replicates = 3;
  o.samples = 1000;
  CHECK_THROWS_WITH_AS(o.validate(), doctest::Contains("multiple of the replicates"),
                       std::invalid_argument);
  o.samples = 999;
  CHECK_NOTHROW(o.validate());
  o.seed = 0;
  CHECK_THROWS_WITH_AS(o.validate(), doctest::Contains("seed 0"), std::invalid_argument);
  o.sampling = Sampling::MonteCarlo;
  CHECK_NOTHROW(o.validate());
  o.intervals = SobolIntervals::Bootstrap;
  o.sampling = Sampling::Qmc;
  CHECK_NOTHROW(o.validate());  // seed 0 with one design: the unrandomised points
  // A design with replicates cannot be analysed as a single design.
  SobolOptions rep;
  rep.samples = 64;
  const SobolDesign d(std::vector<InputDistribution>(2, InputDistribution::normal(0, 1)), rep);
  CHECK(d.replicates() == 4);
  SobolOptions single = rep;
  single.intervals = SobolIntervals::None;
  CHECK_THROWS_WITH_AS(
      SobolAnalysis(single).run(d, 1, [](unsigned, const double* x, double* y) { *y = x[0]; }),
      doctest::Contains("replicates"), std::invalid_argument);
  // The CLI's interval flags.
  SobolOptions cli;
  const long long r2 = 2, r0 = 0, neg = -3, b50 = 50;
  set_sobol_intervals(cli, nullptr, nullptr);
  CHECK(cli.intervals == SobolIntervals::Replicates);
  CHECK(cli.replicates == 4);
  set_sobol_intervals(cli, &r2, nullptr);
  CHECK(cli.replicates == 2);
  set_sobol_intervals(cli, nullptr, &b50);
  CHECK(cli.intervals == SobolIntervals::Bootstrap);
  CHECK(cli.bootstrap == 50);
  CHECK_THROWS_WITH_AS(set_sobol_intervals(cli, &r2, &b50), doctest::Contains("give one"),
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(set_sobol_intervals(cli, &r0, nullptr),
                       doctest::Contains("--replicates must be in [2, 1024], not 0"),
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(set_sobol_intervals(cli, nullptr, &neg),
                       doctest::Contains("--bootstrap must be in [0, 100000]"),
                       std::invalid_argument);
  cli.samples = 1001;
  CHECK_THROWS_WITH_AS(set_sobol_intervals(cli, &r2, nullptr),
                       doctest::Contains("--samples 1001 must be a multiple of --replicates 2"),
                       std::invalid_argument);
}
