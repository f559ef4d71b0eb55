// Exact reliability of a linear response of Normal inputs: r ~ N(m, s^2) with
// m = c0 + sum c_i mu_i and s^2 = sum c_i^2 sigma_i^2, and its analytic sensitivities.
#include <cmath>

#include "reliability_detail.hpp"
#include "weilgen/uq/reliability.hpp"

namespace weilgen::reliability_detail {

ReliabilityResult exact_reliability(const ReliabilityProblem& problem) {
  const LinearForm& f = *problem.linear;
  const std::size_t n = problem.inputs.size();
  const double t = problem.tolerance;
  double m = f.constant, s2 = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double c = f.coefficients[i], sd = problem.inputs[i].stddev();
    m += c * problem.inputs[i].mean();
    s2 += c * c * sd * sd;
  }
  const double s = std::sqrt(s2);
  const bool two_sided = problem.limit == LimitKind::TwoSided;

  ReliabilityResult res;
  res.method = ReliabilityMethod::Exact;
  res.dR_dmu.assign(n, 0.0);
  res.dR_dsigma.assign(n, 0.0);
  if (!(s > 0)) {
    const bool safe = two_sided ? std::abs(m) <= t : m <= t;
    res.reliability = safe ? 1.0 : 0.0;
    res.failure = 1.0 - res.reliability;
    res.note = "exact: zero spread, the response is the constant " + std::to_string(m);
  } else {
    const double a = (t - m) / s;   // upper bound in standard units
    const double b = (-t - m) / s;  // lower bound in standard units
    double dR_dm, dR_ds;            // derivatives with respect to m and s
    if (two_sided) {
      res.reliability = normal_cdf(a) - normal_cdf(b);
      res.failure = normal_cdf(-a) + normal_cdf(b);
      dR_dm = (normal_pdf(b) - normal_pdf(a)) / s;
      dR_ds = (b * normal_pdf(b) - a * normal_pdf(a)) / s;
    } else {
      res.reliability = normal_cdf(a);
      res.failure = normal_cdf(-a);
      dR_dm = -normal_pdf(a) / s;
      dR_ds = -a * normal_pdf(a) / s;
    }
    for (std::size_t i = 0; i < n; ++i) {
      const double c = f.coefficients[i];
      res.dR_dmu[i] = dR_dm * c;
      res.dR_dsigma[i] = dR_ds * c * c * problem.inputs[i].stddev() / s;  // ds/dsigma_i
    }
    res.note = "exact: linear response of normal inputs";
  }
  res.ci_lo = res.ci_hi = res.reliability;
  return res;
}

}  // namespace weilgen::reliability_detail
