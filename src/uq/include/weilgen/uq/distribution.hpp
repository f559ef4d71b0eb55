// The probability distribution of one uncertain input (an error component). Values are in
// whatever unit the caller chose (the runtime uses base units: mm, rad); `scaled` converts.
//
// Every kind is a location-scale family, so "the mean" and "the spread" can be moved
// independently (reliability sensitivities d/dmu, d/dsigma; tolerance allocation). The map
// to a standard normal variable u, x = F^-1(Phi(u)), is what FORM and importance sampling
// work through.
#pragma once

#include <cstddef>
#include <string>

namespace weilgen {

class InputDistribution {
 public:
  enum class Kind { Normal, Uniform, TruncatedNormal };

  // Normal(mean, sigma); sigma == 0 is a constant input.
  static InputDistribution normal(double mean, double sigma);
  // Uniform on [lo, hi]; lo == hi is a constant input.
  static InputDistribution uniform(double lo, double hi);
  // A Normal(mu, sigma) restricted to [lo, hi] (mu and sigma are the parent's parameters).
  static InputDistribution truncated_normal(double mu, double sigma, double lo, double hi);

  Kind kind() const { return kind_; }
  // Kind-specific parameters as given: normal (mean, sigma), uniform (lo, hi),
  // truncated normal (mu, sigma) with bounds lo(), hi().
  double a() const { return a_; }
  double b() const { return b_; }
  double lo() const { return lo_; }
  double hi() const { return hi_; }

  double mean() const;
  double stddev() const;
  bool is_constant() const { return stddev() == 0.0; }

  double pdf(double x) const;
  double cdf(double x) const;
  // Inverse CDF for p in [0, 1]; infinite at the ends of a normal.
  double quantile(double p) const;
  // quantile(p[j]) for j < n into x (may alias p): one pass per call, vectorised for normal
  // and uniform inputs (the Sobol' design maps millions of points through it).
  void quantiles(const double* p, double* x, std::size_t n) const;

  // x = F^-1(Phi(u)) and its inverse u = Phi^-1(F(x)).
  double from_standard_normal(double u) const;
  double to_standard_normal(double x) const;
  // dx/du of from_standard_normal at u (>= 0).
  double dx_du(double u) const;

  // Location-scale moves: the same shape with a new mean and standard deviation (a truncated
  // normal keeps its bounds at the same number of parent sigmas from mu).
  InputDistribution with_mean_stddev(double mean, double stddev) const;
  // Unit conversion: every location and scale multiplied by `factor` (> 0).
  InputDistribution scaled(double factor) const;

  // "normal(0, 0.005)", "uniform(-0.01, 0.01)", "truncnormal(0, 0.005, -0.01, 0.01)".
  std::string str() const;

 private:
  InputDistribution(Kind kind, double a, double b, double lo, double hi);
  Kind kind_;
  double a_, b_, lo_, hi_;
  double z_lo_ = 0, z_hi_ = 0;  // truncated normal: standardized bounds
  double mass_ = 1;             // truncated normal: Phi(z_hi) - Phi(z_lo)
};

// Standard normal pdf and cdf (Boost.Math underneath).
double normal_pdf(double z);
double normal_cdf(double z);
// Standard normal quantile Phi^-1(p) (Wichura's AS 241, relative error < 1e-15 over (0, 1));
// -inf for p <= 0, +inf for p >= 1, NaN for NaN. The array form computes z[j] for j < n (z may
// alias p), vectorising the central region.
double normal_quantile(double p);
void normal_quantiles(const double* p, double* z, std::size_t n);

}  // namespace weilgen
