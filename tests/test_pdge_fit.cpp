// Parametric fits of position-dependent errors: bases, least squares with standard errors, the
// Zhang & Chen 2021's Table 4 metrics, order choice by cross-validation, Fourier period search.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "weilgen/machine/pdge_basis.hpp"
#include "weilgen/measure/pdge_fit.hpp"

using namespace weilgen;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::vector<double> grid(double a, double b, int n) {
  std::vector<double> x(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) x[static_cast<std::size_t>(i)] = a + (b - a) * i / (n - 1);
  return x;
}

std::vector<double> expand(const Basis& basis, const std::vector<double>& c,
                           const std::vector<double>& x) {
  std::vector<double> y;
  for (double v : x) y.push_back(basis.value(c.data(), v));
  return y;
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no exception)";
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

}  // namespace

TEST_CASE("pdge basis: names, sizes and term values") {
  const Basis p = Basis::make(BasisKind::Polynomial, 3, 100, 300);
  CHECK(p.name() == "poly:3");
  CHECK(p.size() == 4);
  const Basis f = Basis::make(BasisKind::Fourier, 2, 0, 500);
  CHECK(f.name() == "fourier:2");
  CHECK(f.size() == 5);
  CHECK(f.period() == 500);
  CHECK(Basis::make(BasisKind::Fourier, 2, 0, 500, 20).name() == "fourier:2:20");
  CHECK(Basis::make(BasisKind::Legendre, 4, 0, 1).name() == "legendre:4");
  CHECK(Basis::make(BasisKind::Chebyshev, 4, 0, 1).name() == "chebyshev:4");

  // x = 250 on [100, 300] is u = 0.5.
  double t[8];
  p.evaluate(250, t);
  CHECK(t[0] == 1);
  CHECK(t[1] == doctest::Approx(0.5));
  CHECK(t[3] == doctest::Approx(0.125));
  const Basis l = Basis::make(BasisKind::Legendre, 4, 100, 300);
  l.evaluate(250, t);
  CHECK(t[2] == doctest::Approx((3 * 0.25 - 1) / 2));                 // P2
  CHECK(t[3] == doctest::Approx((5 * 0.125 - 3 * 0.5) / 2));          // P3
  CHECK(t[4] == doctest::Approx((35 * 0.0625 - 30 * 0.25 + 3) / 8));  // P4
  const Basis c = Basis::make(BasisKind::Chebyshev, 4, 100, 300);
  c.evaluate(250, t);
  CHECK(t[3] == doctest::Approx(4 * 0.125 - 3 * 0.5));        // T3
  CHECK(t[4] == doctest::Approx(8 * 0.0625 - 8 * 0.25 + 1));  // T4
  f.evaluate(125, t);                                         // 2πx/L = π/2
  CHECK(t[1] == doctest::Approx(0).epsilon(1e-12));
  CHECK(t[2] == doctest::Approx(1));
  CHECK(t[3] == doctest::Approx(-1));  // cos(π)
  CHECK(std::abs(t[4]) < 1e-12);       // sin(π)
  CHECK(f.term_names()[4] == "sin(2pi*2*x/L)");
}

TEST_CASE("pdge basis: Legendre, Chebyshev and Fourier orthogonality") {
  // Legendre: ∫_{-1}^{1} P_m P_n du = 2/(2n+1) δ_mn (composite Simpson, 4000 intervals, in x).
  const Basis l = Basis::make(BasisKind::Legendre, 6, -50, 150);
  const int N = 4000;
  std::vector<double> gram(49, 0.0);
  double t[7];
  for (int i = 0; i <= N; ++i) {
    const double x = -50 + 200.0 * i / N;
    const double w = (i == 0 || i == N ? 1 : i % 2 ? 4 : 2) * (2.0 / N) / 3;  // du = dx/100
    l.evaluate(x, t);
    for (int m = 0; m < 7; ++m)
      for (int n = 0; n < 7; ++n) gram[static_cast<std::size_t>(7 * m + n)] += w * t[m] * t[n];
  }
  for (int m = 0; m < 7; ++m)
    for (int n = 0; n < 7; ++n)
      CHECK(gram[static_cast<std::size_t>(7 * m + n)] ==
            doctest::Approx(m == n ? 2.0 / (2 * n + 1) : 0.0).epsilon(1e-9).scale(1));

  // Chebyshev: Gauss-Chebyshev quadrature (exact for degree < 2M) of ∫ T_m T_n / sqrt(1-u²).
  const Basis c = Basis::make(BasisKind::Chebyshev, 6, 0, 2);
  const int M = 16;
  for (int m = 0; m < 7; ++m) {
    for (int n = 0; n < 7; ++n) {
      double s = 0;
      for (int j = 1; j <= M; ++j) {
        const double u = std::cos((2 * j - 1) * kPi / (2 * M));
        c.evaluate(u + 1, t);  // x = u + 1 on [0, 2]
        s += kPi / M * t[m] * t[n];
      }
      const double expected = m != n ? 0.0 : m == 0 ? kPi : kPi / 2;
      CHECK(s == doctest::Approx(expected).epsilon(1e-12).scale(1));
    }
  }

  // Fourier: discrete orthogonality over one period sampled at 64 points.
  const Basis f = Basis::make(BasisKind::Fourier, 3, 0, 64);
  std::vector<double> fg(49, 0.0);
  for (int i = 0; i < 64; ++i) {
    f.evaluate(i, t);
    for (int m = 0; m < 7; ++m)
      for (int n = 0; n < 7; ++n) fg[static_cast<std::size_t>(7 * m + n)] += t[m] * t[n];
  }
  for (int m = 0; m < 7; ++m)
    for (int n = 0; n < 7; ++n)
      CHECK(fg[static_cast<std::size_t>(7 * m + n)] == doctest::Approx(m != n   ? 0.0
                                                                       : m == 0 ? 64
                                                                                : 32)
                                                           .scale(1));
}

TEST_CASE("pdge basis: the parser and its errors") {
  BasisSpec s = parse_basis("fourier:3");
  CHECK(s.kind == BasisKind::Fourier);
  CHECK(s.order == 3);
  CHECK(std::isnan(s.period_mm));
  s = parse_basis("poly:7");
  CHECK(s.kind == BasisKind::Polynomial);
  CHECK(s.order == 7);
  CHECK(parse_basis("Legendre:4").kind == BasisKind::Legendre);
  CHECK(parse_basis("cheb:2").kind == BasisKind::Chebyshev);
  s = parse_basis("fourier:2:20mm");
  CHECK(s.period_mm == 20);
  CHECK(s.str() == "fourier:2:20");
  s = parse_basis("fourier:auto:auto", true);
  CHECK(s.auto_order());
  CHECK(s.period_search);
  CHECK(parse_basis("poly", true).auto_order());

  CHECK(message_of([] { parse_basis("foo:3"); }) ==
        "basis \"foo:3\": unknown kind \"foo\" (expected poly, fourier, legendre or chebyshev, "
        "e.g. poly:3)");
  CHECK(message_of([] { parse_basis("poly"); }) ==
        "basis \"poly\": the order is missing: give a whole number (e.g. poly:3)");
  CHECK(message_of([] { parse_basis("legendre:auto"); }) ==
        "basis \"legendre:auto\": order auto is not allowed here: give a whole number (e.g. "
        "legendre:3)");
  CHECK(contains(message_of([] { parse_basis("fourier:2:auto", true).on(0, 100); }),
                 "the period is to be searched"));
  CHECK(parse_basis("fourier:2:25").on(0, 100).period() == 25);
  CHECK(
      contains(message_of([] { parse_basis("poly:-1"); }), "order \"-1\" must be a whole number"));
  CHECK(contains(message_of([] { parse_basis("poly:3:20"); }), "only fourier takes a period"));
  CHECK(contains(message_of([] { parse_basis("fourier:3:-5"); }), "period \"-5\" must be"));
  CHECK(contains(message_of([] { parse_basis("fourier:3:20:1"); }), "too many fields"));

  CHECK(message_of([] { Basis::make(BasisKind::Polynomial, 3, 100, 100); }) ==
        "travel [100, 100] mm has zero length: a basis needs a travel a < b");
  CHECK(contains(message_of([] { Basis::make(BasisKind::Fourier, 3, 0, 1, 0); }),
                 "period 0 mm must be"));
}

TEST_CASE("pdge fit: exact data gives back the coefficients of every basis") {
  const std::vector<double> x = grid(-200, 300, 41);
  for (BasisKind kind : {BasisKind::Polynomial, BasisKind::Legendre, BasisKind::Chebyshev}) {
    const Basis basis = Basis::make(kind, 5, -200, 300);
    const std::vector<double> c = {1.5, -2.0, 0.75, 3.0, -1.25, 0.5};
    const FitResult r = LeastSquaresFit().run(x, expand(basis, c, x), basis);
    REQUIRE(r.coefficients.size() == 6);
    for (std::size_t k = 0; k < 6; ++k) CHECK(std::abs(r.coefficients[k] - c[k]) < 1e-9);
    CHECK(r.metrics.e_max < 1e-9);
    CHECK(r.metrics.r2 == doctest::Approx(1));
  }
  const Basis fb = Basis::make(BasisKind::Fourier, 3, 0, 500);
  const std::vector<double> cf = {0.5, 2.0, -1.0, 0.25, 0.75, -0.4, 0.1};
  const FitResult rf = LeastSquaresFit().run(x, expand(fb, cf, x), fb);
  for (std::size_t k = 0; k < cf.size(); ++k) CHECK(std::abs(rf.coefficients[k] - cf[k]) < 1e-9);
  const Basis fp = Basis::make(BasisKind::Fourier, 2, 0, 500, 37.5);
  const std::vector<double> cp = {-1, 0.5, 1.5, -0.25, 0.3};
  const std::vector<double> xd = grid(0, 500, 201);
  const FitResult rp = LeastSquaresFit().run(xd, expand(fp, cp, xd), fp);
  for (std::size_t k = 0; k < cp.size(); ++k) CHECK(std::abs(rp.coefficients[k] - cp[k]) < 1e-9);
}

TEST_CASE("pdge fit: power-series coefficients in physical units (um/mm^k)") {
  // f(x) = 1 + 0.02 x - 3e-4 x² + 1e-6 x³ (µm, x in mm) on [100, 300].
  const std::vector<double> d = {1, 0.02, -3e-4, 1e-6};
  const std::vector<double> x = grid(100, 300, 21);
  std::vector<double> y;
  for (double v : x) y.push_back(d[0] + d[1] * v + d[2] * v * v + d[3] * v * v * v);
  for (BasisKind kind : {BasisKind::Polynomial, BasisKind::Legendre, BasisKind::Chebyshev}) {
    const FitResult r = LeastSquaresFit().run(x, y, Basis::make(kind, 3, 100, 300));
    const std::vector<double> got = r.basis.power_coefficients(r.coefficients);
    REQUIRE(got.size() == 4);
    for (std::size_t k = 0; k < 4; ++k) CHECK(got[k] == doctest::Approx(d[k]).epsilon(1e-8));
  }
  CHECK_THROWS_AS(Basis::make(BasisKind::Fourier, 1, 0, 1).power_coefficients({0, 0, 0}),
                  std::invalid_argument);
}

TEST_CASE("pdge fit: metrics of Table 4 on hand-computed cases") {
  const FitMetrics m = fit_metrics({1, 2, 3, 5}, {1, 2.5, 2.5, 5});
  CHECK(m.n == 4);
  CHECK(m.sse == doctest::Approx(0.5));
  CHECK(m.e_max == doctest::Approx(0.5));
  CHECK(m.rmse == doctest::Approx(std::sqrt(0.125)));
  CHECK(m.r2 == doctest::Approx(1 - 0.5 / 8.75));
  CHECK(std::isnan(fit_metrics({2, 2}, {2, 2}).r2));  // no variance to explain

  // A line through (0,0), (1,1), (2,1): c0 = 2/3 at u = 0, slope 1/2; residuals -1/6, 1/3, -1/6.
  const FitResult r =
      LeastSquaresFit().run({0, 1, 2}, {0, 1, 1}, Basis::make(BasisKind::Polynomial, 1, 0, 2));
  CHECK(r.coefficients[0] == doctest::Approx(2.0 / 3));
  CHECK(r.coefficients[1] == doctest::Approx(0.5));
  CHECK(r.metrics.sse == doctest::Approx(1.0 / 6));
  CHECK(r.metrics.e_max == doctest::Approx(1.0 / 3));
  CHECK(r.metrics.rmse == doctest::Approx(std::sqrt(1.0 / 18)));
  CHECK(r.metrics.r2 == doctest::Approx(1 - (1.0 / 6) / (2.0 / 3)));
  // sigma² = SSE / (n - p) = 1/6; (XᵀX)⁻¹ = diag(1/3, 1/2) in u = x - 1.
  CHECK(r.sigma == doctest::Approx(std::sqrt(1.0 / 6)));
  CHECK(r.std_errors[0] == doctest::Approx(std::sqrt(1.0 / 18)));
  CHECK(r.std_errors[1] == doctest::Approx(std::sqrt(1.0 / 12)));
  CHECK(r.predict(2) == doctest::Approx(2.0 / 3 + 0.5));
}

TEST_CASE("pdge fit: noisy data, coefficients within their standard errors") {
  // 400 replicates of cubic + N(0, 0.5²) on 60 points: the ±1.96 se intervals cover the true
  // coefficients about 95 % of the time (t with 56 degrees of freedom: 94.5 %).
  const std::vector<double> x = grid(0, 500, 60);
  const std::vector<double> c = {2, -3, 1.5, 4};
  const Basis basis = Basis::make(BasisKind::Legendre, 3, 0, 500);
  const std::vector<double> clean = expand(basis, c, x);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0, 0.5);
  std::vector<int> covered(4, 0);
  const int reps = 400;
  for (int rep = 0; rep < reps; ++rep) {
    std::vector<double> y(clean);
    for (double& v : y) v += noise(rng);
    const FitResult r = LeastSquaresFit().run(x, y, basis);
    for (std::size_t k = 0; k < 4; ++k) {
      CHECK(std::abs(r.coefficients[k] - c[k]) < 5 * r.std_errors[k]);
      covered[k] += std::abs(r.coefficients[k] - c[k]) < 1.96 * r.std_errors[k];
    }
    CHECK(r.sigma == doctest::Approx(0.5).epsilon(0.35));
  }
  for (int k = 0; k < 4; ++k) {
    const double coverage = covered[static_cast<std::size_t>(k)] / double(reps);
    CHECK(coverage > 0.91);
    CHECK(coverage < 0.98);
  }
}

TEST_CASE("pdge fit: cross-validation picks the true order where training error keeps falling") {
  // 40 data sets of a cubic (and of an order-2 Fourier series) + N(0, 0.3²) on 61 points. The
  // training RMSE falls with every order, so choosing by training error would take the largest
  // order every time; 10-fold block CV with the one-standard-error rule finds the true order in
  // most data sets and never goes below it.
  std::normal_distribution<double> noise(0, 0.3);
  const std::vector<double> x = grid(0, 600, 61);
  int poly_hits = 0, fourier_hits = 0, poly_min_rule_hits = 0;
  const int sets = 40;
  for (int seed = 0; seed < sets; ++seed) {
    std::mt19937 rng(static_cast<unsigned>(100 + seed));
    const Basis truth = Basis::make(BasisKind::Legendre, 3, 0, 600);
    std::vector<double> y = expand(truth, {1, 4, -3, 2}, x);
    for (double& v : y) v += noise(rng);
    PdgeFitOptions o;
    o.max_order = 12;
    int chosen = -1;
    for (const char* kind : {"poly", "legendre", "chebyshev"}) {
      const PdgeFitResult r = PdgeFit(o).run(x, y, {}, parse_basis(kind, true), 0, 600);
      REQUIRE(r.curve.size() == 13);
      for (std::size_t i = 1; i < r.curve.size(); ++i)  // training error never rises
        CHECK(r.curve[i].train_rmse <= r.curve[i - 1].train_rmse + 1e-12);
      CHECK(r.curve.back().train_rmse < r.curve[3].train_rmse);  // training would pick 12
      CHECK(r.order_choice == "1se");
      CHECK(r.fit.basis.order >= 3);
      CHECK(r.fit.basis.order <= 5);
      CHECK(r.cv.rmse > r.fit.metrics.rmse);                // held-out error exceeds training error
      if (chosen >= 0) CHECK(r.fit.basis.order == chosen);  // same span, same choice
      chosen = r.fit.basis.order;
    }
    poly_hits += chosen == 3;
    o.rule = OrderRule::Minimum;
    poly_min_rule_hits +=
        PdgeFit(o).run(x, y, {}, parse_basis("poly", true), 0, 600).fit.basis.order == 3;

    const Basis ft = Basis::make(BasisKind::Fourier, 2, 0, 600);
    std::vector<double> yf = expand(ft, {0.5, 3, -2, 1.5, 1}, x);
    for (double& v : yf) v += noise(rng);
    PdgeFitOptions of;
    of.max_order = 8;
    const PdgeFitResult rf = PdgeFit(of).run(x, yf, {}, parse_basis("fourier", true), 0, 600);
    CHECK(rf.curve.back().train_rmse < rf.curve[2].train_rmse);
    CHECK(rf.fit.basis.order >= 2);
    CHECK(rf.period_choice == "travel");
    fourier_hits += rf.fit.basis.order == 2;
  }
  MESSAGE("true order chosen: poly ", poly_hits, ", fourier ", fourier_hits,
          ", poly by minimum CV ", poly_min_rule_hits, " of ", sets);
  CHECK(poly_hits >= 32);                 // 38 measured
  CHECK(fourier_hits >= 32);              // 38 measured
  CHECK(poly_min_rule_hits < poly_hits);  // the plain minimum over-fits more often
}

TEST_CASE("pdge fit: cross-validation folds") {
  const std::vector<double> x = {0, 10, 20, 30, 40, 50, 60, 0, 10, 20, 30, 40, 50, 60};
  const std::vector<int> cyc = {1, 1, 1, 1, 1, 1, 1, 2, 2, 2, 2, 2, 2, 2};
  // The 5 interior positions in 3 contiguous blocks {10,20} {30,40} {50}, both cycles alike; the
  // end positions 0 and 60 are always trained on (fold -1).
  CHECK(cv_folds(x, cyc, {CvScheme::Blocks, 3}) ==
        std::vector<int>{-1, 0, 0, 1, 1, 2, -1, -1, 0, 0, 1, 1, 2, -1});
  // Without keep_ends: 7 positions in {0,10,20} {30,40} {50,60}.
  CHECK(cv_folds(x, cyc, {CvScheme::Blocks, 3, false}) ==
        std::vector<int>{0, 0, 0, 1, 1, 2, 2, 0, 0, 0, 1, 1, 2, 2});
  CHECK(cv_folds(x, cyc, {CvScheme::Cycles, 3}) ==
        std::vector<int>{0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1});
  CHECK(message_of([&] {
          cv_folds(x, cyc, {CvScheme::Blocks, 6});
        }) ==
        "6-fold cross-validation needs at least 8 distinct positions (the two end positions are "
        "never held out); the data has 7");
  CHECK(message_of([&] {
          cv_folds(x, cyc, {CvScheme::Blocks, 1});
        }) == "cross-validation needs at least 2 folds, not 1");
  CHECK(contains(message_of([&] { cv_folds(x, {}, {CvScheme::Cycles, 3}); }), "a `cycle` column"));
  CHECK(contains(message_of([&] {
                   cv_folds(x, std::vector<int>(14, 1), {CvScheme::Cycles, 3});
                 }),
                 "at least two cycles"));

  // Leave-one-cycle-out on three noisy repeats of a quadratic.
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.2);
  std::vector<double> xs, ys;
  std::vector<int> cs;
  for (int c = 1; c <= 3; ++c)
    for (double v : grid(0, 300, 31)) {
      xs.push_back(v);
      ys.push_back(2 - 5 * (v / 300) * (v / 300) + noise(rng));
      cs.push_back(c);
    }
  PdgeFitOptions o;
  o.cv.scheme = CvScheme::Cycles;
  const PdgeFitResult r = PdgeFit(o).run(xs, ys, cs, parse_basis("poly", true), 0, 300);
  CHECK(r.cv.fold_mse.size() == 3);
  CHECK(r.fit.basis.order == 2);
}

TEST_CASE("pdge fit: Fourier period search recovers a 20 mm pitch error on a 500 mm travel") {
  const std::vector<double> x = grid(0, 500, 201);  // 2.5 mm spacing
  std::vector<double> y;
  for (double v : x) y.push_back(0.5 + 3 * std::sin(2 * kPi * v / 20 + 0.3));
  {
    const PeriodSearchResult r = PeriodSearch().run(x, y, 1, 0, 500);
    CHECK(r.period_mm == doctest::Approx(20).epsilon(1e-7));
    CHECK(r.fit.metrics.e_max < 1e-5);
    CHECK(r.grid_period_mm.size() > 100);
  }
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 0.3);
  for (double& v : y) v += noise(rng);
  const PeriodSearchResult sse = PeriodSearch().run(x, y, 1, 0, 500);
  CHECK(sse.period_mm == doctest::Approx(20).epsilon(1e-3));
  CHECK(sse.min_mm == doctest::Approx(5));     // 2 * order * spacing
  CHECK(sse.max_mm == doctest::Approx(1000));  // 2 * travel
  CHECK_FALSE(sse.at_bound);
  const double amplitude = std::hypot(sse.fit.coefficients[1], sse.fit.coefficients[2]);
  CHECK(amplitude == doctest::Approx(3).epsilon(0.03));
  PeriodSearchOptions po;
  po.objective = PeriodObjective::Cv;
  const PeriodSearchResult cv =
      PeriodSearch(po).run(x, y, 1, 0, 500, cv_folds(x, {}, {CvScheme::Blocks, 5}));
  CHECK(cv.period_mm == doctest::Approx(20).epsilon(1e-3));
  CHECK(cv.evaluations > 100);

  // Through PdgeFit: fourier:1:auto, and fourier:auto:auto (order by CV, period nested).
  const PdgeFitResult f1 = PdgeFit().run(x, y, {}, parse_basis("fourier:1:auto"), 0, 500);
  CHECK(f1.period_choice == "search");
  CHECK(f1.fit.basis.period() == doctest::Approx(20).epsilon(1e-3));
  CHECK(f1.fit.metrics.rmse == doctest::Approx(0.3).epsilon(0.15));
  CHECK(f1.cv.rmse < 0.4);
  // The travel as period cannot represent a 20 mm wave with few harmonics.
  const PdgeFitResult travel = PdgeFit().run(x, y, {}, parse_basis("fourier:3"), 0, 500);
  CHECK(travel.fit.metrics.rmse > 2);
  PdgeFitOptions o;
  o.max_order = 3;
  const PdgeFitResult fa = PdgeFit(o).run(x, y, {}, parse_basis("fourier:auto:auto", true), 0, 500);
  CHECK(fa.fit.basis.order >= 1);
  CHECK(fa.fit.metrics.rmse < 0.35);
  CHECK(std::fmod(fa.fit.basis.period() + 1, 20) < 2.1);  // a multiple of 20 mm
}

TEST_CASE("pdge fit: data that cannot support the order gives a clear message") {
  const std::vector<double> x = grid(0, 80, 9), y(9, 1.0);
  CHECK(message_of(
            [&] { LeastSquaresFit().run(x, y, Basis::make(BasisKind::Polynomial, 12, 0, 80)); }) ==
        "poly:12 has 13 coefficients but the data has 9 distinct positions: the data cannot "
        "support this order (use order <= 8)");
  CHECK(contains(
      message_of([&] { LeastSquaresFit().run(x, y, Basis::make(BasisKind::Fourier, 5, 0, 80)); }),
      "(use order <= 4)"));
  // A 20 mm period sampled every 10 mm: the sine column vanishes (aliasing).
  const std::vector<double> x11 = grid(0, 100, 11), y11(11, 0.0);
  CHECK(contains(message_of([&] {
                   LeastSquaresFit().run(x11, y11, Basis::make(BasisKind::Fourier, 1, 0, 100, 20));
                 }),
                 "design matrix has numerical rank 2 (relative tolerance 1e-09): the data cannot "
                 "support this order (positions too few or aliased at period 20 mm)"));
  CHECK(contains(
      message_of([&] {
        LeastSquaresFit().run({0, 1}, {1, 2, 3}, Basis::make(BasisKind::Polynomial, 1, 0, 1));
      }),
      "2 positions but 3 values"));
  CHECK(contains(
      message_of([&] {
        LeastSquaresFit().run({0, 1, NAN}, {1, 2, 3}, Basis::make(BasisKind::Polynomial, 1, 0, 1));
      }),
      "row 3 is not finite"));
  // A fixed order beyond the data; auto orders beyond the data are skipped on the curve.
  CHECK(contains(message_of([&] { PdgeFit().run(x, y, {}, parse_basis("poly:12"), 0, 80); }),
                 "9 distinct positions"));
  std::vector<double> yq;
  for (double v : x) yq.push_back(v * v / 1000);
  PdgeFitOptions o;
  o.max_order = 12;
  const PdgeFitResult r = PdgeFit(o).run(x, yq, {}, parse_basis("poly", true), 0, 80);
  CHECK(r.fit.basis.order == 2);
  CHECK_FALSE(r.curve.back().feasible);
  CHECK(contains(r.curve.back().reason, "9 distinct positions"));
  CHECK(r.folds == 7);         // 10 folds asked, 7 interior positions: leave-one-position-out
  CHECK(r.curve[7].feasible);  // 8 coefficients, 8 training positions
  CHECK(contains(r.curve[8].reason, "fold"));  // 9 coefficients, 8 training positions
  CHECK(message_of([&] { PdgeFit().run(x, y, {}, parse_basis("poly:2"), 5, 5); }) ==
        "travel [5, 5] mm has zero length: a basis needs a travel a < b");
}
