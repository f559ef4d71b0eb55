// The reliability engine: exact, FORM, importance sampling and Monte Carlo against closed forms,
// quadratures and long simulations.
#include <doctest/doctest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "weilgen/base/parallel.hpp"
#include "weilgen/uq/reliability.hpp"

using namespace weilgen;

namespace {

double Phi(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }
double phi(double z) { return std::exp(-0.5 * z * z) / std::sqrt(2 * M_PI); }

// Five normal inputs of mixed means and spreads and a linear response.
struct LinearCase {
  std::vector<double> mu{0.004, -0.002, 0.0, 0.001, 0.003};
  std::vector<double> sigma{0.006, 0.004, 0.010, 0.002, 0.005};
  std::vector<double> c{1.0, -2.0, 0.5, 3.0, -1.5};
  double c0 = 0.002;

  ReliabilityProblem problem(LimitKind kind, double t) const {
    ReliabilityProblem p;
    for (std::size_t i = 0; i < mu.size(); ++i)
      p.inputs.push_back(InputDistribution::normal(mu[i], sigma[i]));
    p.linear = LinearForm{c0, c};
    p.limit = kind;
    p.tolerance = t;
    return p;
  }
  // The same response through a callback (no linear form: gradients by central differences).
  ReliabilityProblem callback_problem(LimitKind kind, double t) const {
    ReliabilityProblem p = problem(kind, t);
    p.linear.reset();
    const auto cc = c;
    const double k0 = c0;
    p.response = [cc, k0](unsigned, const double* x) {
      double r = k0;
      for (std::size_t i = 0; i < cc.size(); ++i) r += cc[i] * x[i];
      return r;
    };
    return p;
  }
  // The closed form, independently of the engine.
  static double closed_form(const std::vector<double>& m_, const std::vector<double>& s_,
                            const std::vector<double>& c_, double k0, LimitKind kind, double t) {
    double m = k0, s2 = 0;
    for (std::size_t i = 0; i < m_.size(); ++i) {
      m += c_[i] * m_[i];
      s2 += c_[i] * c_[i] * s_[i] * s_[i];
    }
    const double s = std::sqrt(s2);
    return kind == LimitKind::TwoSided ? Phi((t - m) / s) - Phi((-t - m) / s) : Phi((t - m) / s);
  }
  double closed_form(LimitKind kind, double t) const {
    return closed_form(mu, sigma, c, c0, kind, t);
  }
};

ReliabilityOptions with_method(ReliabilityMethod m, std::size_t samples = 1u << 14) {
  ReliabilityOptions o;
  o.method = m;
  o.samples = samples;
  return o;
}

// P(x1 + kappa x2^2 > t) for standard normal x1, x2: the integral over x2 of Phi(kappa x2^2 - t)
// phi(x2), by the trapezoidal rule on [-12, 12] (spectrally accurate for this integrand).
double curved_exact(double kappa, double t) {
  const int n = 48000;
  const double a = -12, h = 24.0 / n;
  double s = 0;
  for (int i = 0; i <= n; ++i) {
    const double p = a + i * h;
    s += (i == 0 || i == n ? 0.5 : 1.0) * Phi(kappa * p * p - t) * phi(p);
  }
  return s * h;
}

// The same with x1 ~ N(m1, s1), x2 ~ N(m2, s2): integral of Phi((m1 + kappa x2^2 - t) / s1) over
// x2 = m2 + s2 p.
double curved_exact(double kappa, double t, double m1, double s1, double m2, double s2) {
  const int n = 48000;
  const double a = -12, h = 24.0 / n;
  double s = 0;
  for (int i = 0; i <= n; ++i) {
    const double p = a + i * h, x2 = m2 + s2 * p;
    s += (i == 0 || i == n ? 0.5 : 1.0) * Phi((m1 + kappa * x2 * x2 - t) / s1) * phi(p);
  }
  return s * h;
}

ReliabilityProblem curved_problem(double kappa, double t) {
  ReliabilityProblem p;
  p.inputs = {InputDistribution::normal(0, 1), InputDistribution::normal(0, 1)};
  p.response = [kappa](unsigned, const double* x) { return x[0] + kappa * x[1] * x[1]; };
  p.limit = LimitKind::Upper;
  p.tolerance = t;
  return p;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST_CASE(
    "reliability: exact linear Gaussian equals the closed form, with analytic sensitivities") {
  const LinearCase lc;
  for (LimitKind kind : {LimitKind::TwoSided, LimitKind::Upper}) {
    for (double t : {0.01, 0.03, 0.06}) {
      CAPTURE(std::string(to_string(kind)));
      CAPTURE(t);
      const auto res = ReliabilityAnalysis(ReliabilityOptions{}).run(lc.problem(kind, t));
      CHECK(res.method == ReliabilityMethod::Exact);
      const double R = lc.closed_form(kind, t);
      CHECK(res.reliability == doctest::Approx(R).epsilon(1e-13));
      CHECK(res.failure == doctest::Approx(1 - R).epsilon(1e-12));
      CHECK(res.ci_lo == res.reliability);
      CHECK(res.ci_hi == res.reliability);
      CHECK(res.cov == 0);
      CHECK(res.evaluations == 0);
      // Central differences of the closed form in each mean and each sigma.
      for (std::size_t i = 0; i < lc.mu.size(); ++i) {
        const double hm = 1e-6, hs = 1e-6;
        auto mp = lc.mu, mm = lc.mu, sp = lc.sigma, sm = lc.sigma;
        mp[i] += hm;
        mm[i] -= hm;
        sp[i] += hs;
        sm[i] -= hs;
        const double dmu = (LinearCase::closed_form(mp, lc.sigma, lc.c, lc.c0, kind, t) -
                            LinearCase::closed_form(mm, lc.sigma, lc.c, lc.c0, kind, t)) /
                           (2 * hm);
        const double dsg = (LinearCase::closed_form(lc.mu, sp, lc.c, lc.c0, kind, t) -
                            LinearCase::closed_form(lc.mu, sm, lc.c, lc.c0, kind, t)) /
                           (2 * hs);
        CAPTURE(i);
        CHECK(res.dR_dmu[i] == doctest::Approx(dmu).epsilon(1e-6));
        CHECK(res.dR_dsigma[i] == doctest::Approx(dsg).epsilon(1e-6));
      }
    }
  }
}

TEST_CASE("reliability: FORM and IS are exact for a linear Gaussian limit state") {
  const LinearCase lc;
  for (LimitKind kind : {LimitKind::TwoSided, LimitKind::Upper}) {
    for (bool callback : {false, true}) {
      CAPTURE(std::string(to_string(kind)));
      CAPTURE(callback);
      const double t = 0.03;
      const auto p = callback ? lc.callback_problem(kind, t) : lc.problem(kind, t);
      const auto ex =
          ReliabilityAnalysis(with_method(ReliabilityMethod::Exact)).run(lc.problem(kind, t));
      const auto form = ReliabilityAnalysis(with_method(ReliabilityMethod::Form)).run(p);
      const auto is =
          ReliabilityAnalysis(with_method(ReliabilityMethod::ImportanceSampling)).run(p);
      ReliabilityOptions so = with_method(ReliabilityMethod::ImportanceSampling);
      so.sensitivities = SensitivityMethod::Sampling;
      const auto is_s = ReliabilityAnalysis(so).run(p);
      CHECK(form.method == ReliabilityMethod::Form);
      CHECK(is.method == ReliabilityMethod::ImportanceSampling);
      const std::size_t sides = kind == LimitKind::TwoSided ? 2 : 1;
      REQUIRE(form.design_points.size() == sides);
      for (const auto& dp : form.design_points) {
        CHECK(dp.converged);
        CHECK(dp.iterations <= 4);
      }
      // Both design points of a two-sided limit: P_f = Phi(-beta1) + Phi(-beta2) is exact.
      const double tol = callback ? 1e-7 : 1e-11;
      CHECK(form.failure == doctest::Approx(ex.failure).epsilon(tol));
      CHECK(is.failure == doctest::Approx(ex.failure).epsilon(tol));
      CHECK(is.cov < 1e-12);  // every line has the same root: zero variance
      CHECK(is.ci_lo == doctest::Approx(ex.reliability).epsilon(1e-9));
      CHECK(is.ci_hi == doctest::Approx(ex.reliability).epsilon(1e-9));
      // beta of side +1 is (t - m) / s.
      double m = lc.c0, s2 = 0;
      for (std::size_t i = 0; i < 5; ++i) {
        m += lc.c[i] * lc.mu[i];
        s2 += lc.c[i] * lc.c[i] * lc.sigma[i] * lc.sigma[i];
      }
      CHECK(form.design_points[0].beta == doctest::Approx((t - m) / std::sqrt(s2)).epsilon(tol));
      if (sides == 2)
        CHECK(form.design_points[1].beta == doctest::Approx((t + m) / std::sqrt(s2)).epsilon(tol));
      // FORM-based sensitivities equal the analytic ones.
      for (std::size_t i = 0; i < 5; ++i) {
        CAPTURE(i);
        const double stol = callback ? 1e-5 : 1e-9;
        CHECK(form.dR_dmu[i] == doctest::Approx(ex.dR_dmu[i]).epsilon(stol));
        CHECK(form.dR_dsigma[i] == doctest::Approx(ex.dR_dsigma[i]).epsilon(stol));
        CHECK(is.dR_dsigma[i] == doctest::Approx(ex.dR_dsigma[i]).epsilon(stol));
        // The differentiated IS estimate: exact in the means (every line's root moves alike);
        // unbiased but noisy in the stddevs (the root's offset along each input varies by line).
        CHECK(is_s.dR_dmu[i] == doctest::Approx(ex.dR_dmu[i]).epsilon(stol));
        CHECK(is_s.dR_dsigma[i] == doctest::Approx(ex.dR_dsigma[i]).epsilon(0.03));
      }
      MESSAGE(std::string(to_string(kind))
              << std::string(callback ? " callback" : " linear form") << ": FORM evaluations "
              << form.evaluations << ", IS evaluations " << is.evaluations);
    }
  }
}

TEST_CASE("reliability: non-Gaussian inputs, FORM and IS against a long Monte Carlo") {
  ReliabilityProblem p;
  p.inputs = {InputDistribution::uniform(-0.01, 0.02),
              InputDistribution::truncated_normal(0.0, 0.01, -0.015, 0.02),
              InputDistribution::normal(0.002, 0.004), InputDistribution::uniform(-0.005, 0.005),
              InputDistribution::normal(0.0, 0.003)};
  p.linear = LinearForm{0.0, {1.0, -2.0, 0.5, 3.0, 1.0}};
  for (LimitKind kind : {LimitKind::TwoSided, LimitKind::Upper}) {
    CAPTURE(std::string(to_string(kind)));
    p.limit = kind;
    p.tolerance = 0.04;
    CHECK_THROWS_AS(ReliabilityAnalysis(with_method(ReliabilityMethod::Exact)).run(p),
                    std::invalid_argument);
    const auto mc =
        ReliabilityAnalysis(with_method(ReliabilityMethod::MonteCarlo, 1u << 22)).run(p);
    const auto is = ReliabilityAnalysis(ReliabilityOptions{}).run(p);  // Auto: IS
    const auto form = ReliabilityAnalysis(with_method(ReliabilityMethod::Form)).run(p);
    CHECK(is.method == ReliabilityMethod::ImportanceSampling);
    const double se_mc = mc.cov * mc.failure, se_is = is.cov * is.failure;
    MESSAGE(std::string(to_string(kind))
            << ": MC P_f " << mc.failure << " (CoV " << mc.cov << "), IS " << is.failure << " (CoV "
            << is.cov << ", " << is.evaluations << " evaluations), FORM " << form.failure);
    CHECK(std::abs(is.failure - mc.failure) < 4 * std::hypot(se_mc, se_is));
    CHECK(is.cov < 0.02);
    // FORM linearises a limit state that the bounded uniforms curve in u-space: it overestimates
    // P_f here by about 70 %.
    CHECK(form.failure > 1.5 * mc.failure);
    CHECK(form.failure < 2.0 * mc.failure);
    for (const auto& dp : form.design_points) CHECK(dp.converged);
  }
}

TEST_CASE("reliability: a curved limit state where FORM is wrong and IS converges") {
  // r = x1 + kappa x2^2 <= t: the design point is (t, 0) with beta = t (for kappa < 1/(2t)), the
  // failure surface curves around the origin, FORM underestimates P_f by about a factor
  // sqrt(1 - 2 kappa t).
  const double kappa = 0.15, t = 3.0;
  const double exact = curved_exact(kappa, t);
  const ReliabilityProblem p = curved_problem(kappa, t);
  const auto form = ReliabilityAnalysis(with_method(ReliabilityMethod::Form)).run(p);
  REQUIRE(form.design_points.size() == 1);
  CHECK(form.design_points[0].converged);
  CHECK(form.design_points[0].beta == doctest::Approx(t).epsilon(1e-8));
  const double form_err = std::abs(form.failure - exact) / exact;
  MESSAGE("curved: exact P_f " << exact << ", FORM " << form.failure << " (relative error "
                               << form_err << ")");
  CHECK(form_err > 0.2);
  // Error against N (one seed). The per-line values Phi(kappa p^2 - t) are skewed (CoV 2.24 per
  // line), so the error at N lines is about 2.24 / sqrt(N) relative.
  for (std::size_t n : {std::size_t(1) << 10, std::size_t(1) << 12, std::size_t(1) << 14,
                        std::size_t(1) << 16, std::size_t(1) << 18}) {
    const auto is =
        ReliabilityAnalysis(with_method(ReliabilityMethod::ImportanceSampling, n)).run(p);
    const double err = std::abs(is.failure - exact) / exact;
    MESSAGE("curved IS N=" << n << ": P_f " << is.failure << " relative error " << err << " CoV "
                           << is.cov << " evaluations " << is.evaluations);
    CHECK(err < 5 * 2.24 / std::sqrt(static_cast<double>(n)));
    if (n >= (1u << 16)) CHECK(err < 0.02);
  }
  // Unbiased, and the 95 % interval covers the exact value for most seeds (the sample CoV
  // underestimates the skewed estimator's spread at small N, so coverage is a little below 95 %).
  double mean = 0;
  int covered = 0;
  const int seeds = 100;
  for (int seed = 1; seed <= seeds; ++seed) {
    ReliabilityOptions o = with_method(ReliabilityMethod::ImportanceSampling, 4096);
    o.seed = static_cast<std::uint64_t>(seed);
    const auto is = ReliabilityAnalysis(o).run(p);
    mean += is.failure / seeds;
    if (is.ci_lo <= 1 - exact && is.ci_hi >= 1 - exact) ++covered;
  }
  MESSAGE("curved IS N=4096 over " << seeds << " seeds: mean P_f " << mean << ", interval covers "
                                   << covered << " times");
  CHECK(mean == doctest::Approx(exact).epsilon(0.01));
  CHECK(covered >= 85);
  // Sensitivities: central differences of the exact P_f in each mean and stddev, against the
  // differentiated IS estimate (consistent) and FORM's (off like FORM's P_f).
  ReliabilityOptions so = with_method(ReliabilityMethod::ImportanceSampling, 1u << 16);
  so.sensitivities = SensitivityMethod::Sampling;
  const auto is_s = ReliabilityAnalysis(so).run(p);
  const double h = 1e-4;
  const double ref_dmu[2] = {
      -(curved_exact(kappa, t, h, 1, 0, 1) - curved_exact(kappa, t, -h, 1, 0, 1)) / (2 * h),
      -(curved_exact(kappa, t, 0, 1, h, 1) - curved_exact(kappa, t, 0, 1, -h, 1)) / (2 * h)};
  const double ref_dsigma[2] = {
      -(curved_exact(kappa, t, 0, 1 + h, 0, 1) - curved_exact(kappa, t, 0, 1 - h, 0, 1)) / (2 * h),
      -(curved_exact(kappa, t, 0, 1, 0, 1 + h) - curved_exact(kappa, t, 0, 1, 0, 1 - h)) / (2 * h)};
  MESSAGE("curved sensitivities: exact dR/dmu "
          << ref_dmu[0] << " " << ref_dmu[1] << ", dR/dsigma " << ref_dsigma[0] << " "
          << ref_dsigma[1] << "; IS (sampling) dR/dmu " << is_s.dR_dmu[0] << " " << is_s.dR_dmu[1]
          << ", dR/dsigma " << is_s.dR_dsigma[0] << " " << is_s.dR_dsigma[1] << "; FORM dR/dmu "
          << form.dR_dmu[0] << " " << form.dR_dmu[1] << ", dR/dsigma " << form.dR_dsigma[0] << " "
          << form.dR_dsigma[1]);
  CHECK(is_s.dR_dmu[0] == doctest::Approx(ref_dmu[0]).epsilon(0.03));
  CHECK(std::abs(is_s.dR_dmu[1]) < 0.03 * std::abs(ref_dmu[0]));  // zero by symmetry
  CHECK(is_s.dR_dsigma[0] == doctest::Approx(ref_dsigma[0]).epsilon(0.03));
  CHECK(is_s.dR_dsigma[1] == doctest::Approx(ref_dsigma[1]).epsilon(0.05));
  CHECK(std::abs(form.dR_dmu[0] - ref_dmu[0]) > 0.2 * std::abs(ref_dmu[0]));
  CHECK(form.dR_dsigma[1] == 0);  // the design point has x2 = 0: FORM sees no effect of sigma2
  // Monte Carlo agrees too.
  const auto mc = ReliabilityAnalysis(with_method(ReliabilityMethod::MonteCarlo, 1u << 22)).run(p);
  CHECK(mc.ci_lo <= 1 - exact);
  CHECK(mc.ci_hi >= 1 - exact);
}

TEST_CASE("reliability: radial limit (upper on a norm of zero-mean inputs)") {
  // ||x|| <= t for n standard normals: P_f = P(chi2_n > t^2). The gradient vanishes at the
  // origin (FORM restarts), there are design points in every direction (FORM finds one and its
  // mirror), and every IS line crosses the limit twice.
  const double t = 3.0;
  for (int n : {2, 3}) {
    CAPTURE(n);
    ReliabilityProblem p;
    for (int i = 0; i < n; ++i) p.inputs.push_back(InputDistribution::normal(0, 0.01));
    p.response = [n](unsigned, const double* x) {
      double s = 0;
      for (int i = 0; i < n; ++i) s += x[i] * x[i];
      return std::sqrt(s) / 0.01;
    };
    p.limit = LimitKind::Upper;
    p.tolerance = t;
    const double exact = n == 2 ? std::exp(-t * t / 2) : 2 * Phi(-t) + 2 * t * phi(t);
    const auto form = ReliabilityAnalysis(with_method(ReliabilityMethod::Form)).run(p);
    const auto is = ReliabilityAnalysis(with_method(ReliabilityMethod::ImportanceSampling)).run(p);
    MESSAGE("radial n=" << n << ": exact P_f " << exact << ", FORM " << form.failure << ", IS "
                        << is.failure << " (CoV " << is.cov << ")");
    REQUIRE(form.design_points.size() == 2);  // a design point and its mirror
    CHECK(form.design_points[0].beta == doctest::Approx(t).epsilon(1e-6));
    CHECK(form.design_points[1].beta == doctest::Approx(t).epsilon(1e-6));
    CHECK(form.failure == doctest::Approx(2 * Phi(-t)).epsilon(1e-6));
    CHECK(is.failure == doctest::Approx(exact).epsilon(0.02));
    CHECK(is.ci_lo <= 1 - exact);
    CHECK(is.ci_hi >= 1 - exact);
    // d P_f / d sigma_i for isotropic spreads: P_f depends on t sigma_0 / sigma only, so the
    // derivative of P(chi2_n > (t sigma_0 / sigma)^2) divided equally among the n inputs.
    // n = 2: dP/dsigma = P t^2 / sigma; n = 3: the chi(3) density 2 t^2 phi(t) times t / sigma.
    const double sigma = 0.01;
    const double dP_dsigma = (n == 2 ? exact * t * t : 2 * t * t * phi(t) * t) / sigma / n;
    ReliabilityOptions so = with_method(ReliabilityMethod::ImportanceSampling);
    so.sensitivities = SensitivityMethod::Sampling;
    const auto is_s = ReliabilityAnalysis(so).run(p);
    for (int i = 0; i < n; ++i) {
      CAPTURE(i);
      CHECK(is_s.dR_dsigma[i] == doctest::Approx(-dP_dsigma).epsilon(0.08));
      CHECK(std::abs(is_s.dR_dmu[i]) < 0.1 * dP_dsigma);
    }
    MESSAGE("radial n=" << n << ": dR/dsigma_0 exact " << -dP_dsigma << ", IS (sampling) "
                        << is_s.dR_dsigma[0] << ", FORM " << is.dR_dsigma[0]);
  }
}

TEST_CASE("reliability: Monte Carlo interval covers the exact value and reports the CoV") {
  const LinearCase lc;
  const auto p = lc.problem(LimitKind::TwoSided, 0.03);
  const double R = lc.closed_form(LimitKind::TwoSided, 0.03);
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    ReliabilityOptions o = with_method(ReliabilityMethod::MonteCarlo, 200000);
    o.seed = seed;
    const auto mc = ReliabilityAnalysis(o).run(p);
    CAPTURE(seed);
    CHECK(mc.method == ReliabilityMethod::MonteCarlo);
    CHECK(mc.ci_lo <= R);
    CHECK(mc.ci_hi >= R);
    CHECK(mc.ci_lo < mc.reliability);
    CHECK(mc.ci_hi > mc.reliability);
    CHECK(mc.cov == doctest::Approx(std::sqrt(mc.reliability / (200000 * mc.failure))));
    CHECK(mc.evaluations >= 200000);
    CHECK(std::abs(mc.failure - (1 - R)) < 4 * mc.cov * mc.failure);
  }
}

TEST_CASE("reliability: bit-identical results for any thread count") {
  ReliabilityProblem curved = curved_problem(0.15, 3.0);
  ReliabilityProblem nongauss;
  nongauss.inputs = {InputDistribution::uniform(-1, 1),
                     InputDistribution::truncated_normal(0, 1, -2, 2.5),
                     InputDistribution::normal(0.1, 0.5)};
  std::atomic<unsigned> max_thread{0};
  nongauss.response = [&max_thread](unsigned thread, const double* x) {
    unsigned m = max_thread.load();
    while (thread > m && !max_thread.compare_exchange_weak(m, thread)) {
    }
    return x[0] + x[1] * x[2] + 0.3 * x[2] * x[2];
  };
  nongauss.tolerance = 2.2;
  for (ReliabilityProblem* p : {&curved, &nongauss}) {
    for (ReliabilityMethod m :
         {ReliabilityMethod::ImportanceSampling, ReliabilityMethod::MonteCarlo}) {
      CAPTURE(std::string(to_string(m)));
      ReliabilityOptions o = with_method(m, m == ReliabilityMethod::MonteCarlo ? 50000 : 5000);
      o.threads = 1;
      const auto ref = ReliabilityAnalysis(o).run(*p);
      for (unsigned th : {2u, 3u, 8u}) {
        max_thread = 0;
        o.threads = th;
        const auto r = ReliabilityAnalysis(o).run(*p);
        CAPTURE(th);
        CHECK(same_bits(r.reliability, ref.reliability));
        CHECK(same_bits(r.cov, ref.cov));
        CHECK(same_bits(r.ci_lo, ref.ci_lo));
        CHECK(r.evaluations == ref.evaluations);
        for (std::size_t i = 0; i < ref.dR_dsigma.size(); ++i)
          CHECK(same_bits(r.dR_dsigma[i], ref.dR_dsigma[i]));
        if (p == &nongauss) CHECK(max_thread.load() < th);
      }
      o.seed = 2;
      o.threads = 2;
      CHECK(!same_bits(ReliabilityAnalysis(o).run(*p).reliability, ref.reliability));
    }
  }
}

TEST_CASE("reliability: constant inputs are fixed at their mean and keep a mean sensitivity") {
  const LinearCase lc;
  ReliabilityProblem p = lc.problem(LimitKind::TwoSided, 0.03);
  // A constant input of coefficient 2 at 0.001: same as c0 += 0.002.
  p.inputs.push_back(InputDistribution::normal(0.001, 0.0));
  p.linear->coefficients.push_back(2.0);
  LinearCase shifted = lc;
  shifted.c0 += 0.002;
  const double R = shifted.closed_form(LimitKind::TwoSided, 0.03);
  const auto ex = ReliabilityAnalysis(ReliabilityOptions{}).run(p);
  CHECK(ex.reliability == doctest::Approx(R).epsilon(1e-13));
  CHECK(ex.dR_dsigma[5] == 0);
  CHECK(ex.dR_dmu[5] == doctest::Approx(2 * ex.dR_dmu[0] / lc.c[0]).epsilon(1e-12));
  // Through a callback (differences also for the constant input) and FORM.
  ReliabilityProblem q = p;
  q.linear.reset();
  q.response = [](unsigned, const double* x) {
    return 0.002 + x[0] - 2 * x[1] + 0.5 * x[2] + 3 * x[3] - 1.5 * x[4] + 2 * x[5];
  };
  const auto form = ReliabilityAnalysis(with_method(ReliabilityMethod::Form)).run(q);
  CHECK(form.reliability == doctest::Approx(R).epsilon(1e-8));
  CHECK(form.dR_dmu[5] == doctest::Approx(ex.dR_dmu[5]).epsilon(1e-5));
  CHECK(form.design_points[0].u.size() == 6);
  CHECK(form.design_points[0].u[5] == 0);
  CHECK(form.design_points[0].x[5] == 0.001);
  // Every input constant: deterministic.
  ReliabilityProblem d;
  d.inputs = {InputDistribution::normal(0.01, 0), InputDistribution::uniform(0.02, 0.02)};
  d.response = [](unsigned, const double* x) { return x[0] + x[1]; };
  d.tolerance = 0.025;
  CHECK(ReliabilityAnalysis(ReliabilityOptions{}).run(d).reliability == 0.0);
  d.tolerance = 0.035;
  CHECK(ReliabilityAnalysis(ReliabilityOptions{}).run(d).reliability == 1.0);
  // Zero spread in the exact method.
  ReliabilityProblem z = lc.problem(LimitKind::Upper, 0.03);
  for (auto& in : z.inputs) in = in.with_mean_stddev(in.mean(), 0.0);
  CHECK(ReliabilityAnalysis(ReliabilityOptions{}).run(z).reliability == 1.0);
}

TEST_CASE("reliability: bad problems throw std::invalid_argument") {
  const LinearCase lc;
  const ReliabilityOptions o;
  auto p = lc.problem(LimitKind::TwoSided, 0.0);
  CHECK_THROWS_AS(ReliabilityAnalysis(o).run(p), std::invalid_argument);
  p.tolerance = -0.01;
  CHECK_THROWS_AS(ReliabilityAnalysis(o).run(p), std::invalid_argument);
  p.tolerance = std::nan("");
  CHECK_THROWS_AS(ReliabilityAnalysis(o).run(p), std::invalid_argument);
  p.tolerance = 0.03;
  ReliabilityProblem empty = p;
  empty.inputs.clear();
  empty.linear->coefficients.clear();
  CHECK_THROWS_AS(ReliabilityAnalysis(o).run(empty), std::invalid_argument);
  ReliabilityProblem wrong = p;
  wrong.linear->coefficients.pop_back();
  CHECK_THROWS_AS(ReliabilityAnalysis(o).run(wrong), std::invalid_argument);
  ReliabilityProblem none = p;
  none.linear.reset();
  CHECK_THROWS_AS(ReliabilityAnalysis(o).run(none), std::invalid_argument);
  // Exact on a non-Gaussian input or a non-linear response.
  ReliabilityProblem ng = p;
  ng.inputs[2] = InputDistribution::uniform(-0.01, 0.01);
  CHECK_THROWS_WITH_AS(ReliabilityAnalysis(with_method(ReliabilityMethod::Exact)).run(ng),
                       doctest::Contains("input 2 is uniform"), std::invalid_argument);
  CHECK_THROWS_WITH_AS(
      ReliabilityAnalysis(with_method(ReliabilityMethod::Exact)).run(curved_problem(0.1, 3)),
      doctest::Contains("linear"), std::invalid_argument);
  CHECK_THROWS_AS(ReliabilityAnalysis(with_method(ReliabilityMethod::MonteCarlo, 0)).run(p),
                  std::invalid_argument);
  ReliabilityOptions bad_conf;
  bad_conf.confidence = 1.0;
  CHECK_THROWS_AS(ReliabilityAnalysis(bad_conf).run(p), std::invalid_argument);
}

TEST_CASE("reliability: method names") {
  for (ReliabilityMethod m :
       {ReliabilityMethod::Auto, ReliabilityMethod::Exact, ReliabilityMethod::Form,
        ReliabilityMethod::ImportanceSampling, ReliabilityMethod::MonteCarlo})
    CHECK(parse_reliability_method(to_string(m)) == m);
  CHECK(parse_reliability_method("Importance-Sampling") == ReliabilityMethod::ImportanceSampling);
  CHECK(parse_reliability_method("monte-carlo") == ReliabilityMethod::MonteCarlo);
  CHECK_THROWS_WITH_AS(parse_reliability_method("sorm"), doctest::Contains("expected auto"),
                       std::invalid_argument);
  CHECK(std::string(to_string(LimitKind::TwoSided)) == "two-sided");
}
