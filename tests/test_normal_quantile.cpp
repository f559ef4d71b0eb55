// The standard normal quantile (AS 241) against an independent long-double reference over the
// whole range of doubles, including the far tails and the ends of the QMC range.
#include <doctest/doctest.h>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "weilgen/uq/distribution.hpp"

using namespace weilgen;

namespace {

// Reference for p <= 1/2: Halley's iteration on Phi(z) = p in long double (64-bit mantissa),
// from a start independent of AS 241 (the asymptotic tail formula or the central Taylor term),
// iterated to convergence. Near the centre the residual is taken as erf(z / sqrt 2) / 2 - q with
// q = p - 1/2 (exact in double for p >= 1/4), so that it keeps its relative precision as z -> 0;
// in the tail as erfc(-z / sqrt 2) / 2 - p.
long double reference_lower(double p) {
  const long double kSqrt2 = 1.41421356237309504880168872420969808L;
  const long double kSqrt2Pi = 2.50662827463100050241576528481104525L;
  long double z;
  if (p > 0.1) {
    z = (static_cast<long double>(p) - 0.5L) * kSqrt2Pi;
  } else {
    const long double t = std::sqrt(-2.0L * std::log(static_cast<long double>(p)));
    z = -(t - (2.515517L + 0.802853L * t + 0.010328L * t * t) /
                  (1 + 1.432788L * t + 0.189269L * t * t + 0.001308L * t * t * t));
  }
  for (int it = 0; it < 50; ++it) {
    const long double residual =
        p >= 0.25 ? 0.5L * std::erf(z / kSqrt2) - static_cast<long double>(p - 0.5)
                  : 0.5L * std::erfc(-z / kSqrt2) - static_cast<long double>(p);
    const long double pdf = std::exp(-0.5L * z * z) / kSqrt2Pi;
    const long double d = residual / pdf;
    const long double step = d / (1 + 0.5L * z * d);
    z -= step;
    if (std::fabs(step) <= 1e-19L * (1 + std::fabs(z))) break;
  }
  return z;
}

// Phi^-1(p) = -Phi^-1(1 - p); 1 - p is exact in double for p >= 1/2.
long double reference(double p) { return p <= 0.5 ? reference_lower(p) : -reference_lower(1 - p); }

double relative_error(double p) {
  const long double r = reference(p);
  const double z = normal_quantile(p);
  if (r == 0) return std::abs(z);
  return static_cast<double>(std::fabs((static_cast<long double>(z) - r) / r));
}

}  // namespace

TEST_CASE("normal quantile: relative error below 1e-15 over (0, 1), tails included") {
  double worst = 0, worst_p = 0;
  const auto check = [&](double p) {
    const double e = relative_error(p);
    if (e > worst) worst = e, worst_p = p;
  };
  // Log-spaced over the lower and upper tails, from the smallest normal double (and subnormals)
  // to 1/2: every branch of AS 241 (r <= 5 and r > 5 in the tails, the central region).
  for (double p = DBL_MIN; p < 0.5; p *= 1.07) {
    check(p);
    check(1 - p);
  }
  for (double p : {DBL_TRUE_MIN, 0x1p-1060, 0x1p-1030}) check(p);
  // The ends of the QMC range (coordinates are multiples of 2^-53; 0 is returned as 2^-54).
  for (double p : {0x1p-54, 0x1p-53, 1 - 0x1p-53, 0.5, 0.5 + 0x1p-53, 0.075, 0.925}) check(p);
  // Around the branch points |p - 1/2| = 0.425 and r = 5 (p = e^-25).
  for (double c : {0.075, 0.925, std::exp(-25.0)})
    for (int k = -40; k <= 40; ++k) check(c * (1 + k * 1e-14));
  // Uniform random p on the 2^-53 grid (the QMC points' values).
  std::mt19937_64 rng(20261124);
  for (int i = 0; i < 200000; ++i) check((static_cast<double>(rng() >> 11) + 0.5) * 0x1p-53);
  INFO("worst relative error " << worst << " at p = " << worst_p);
  CHECK(worst < 1e-15);
}

TEST_CASE("normal quantile: ends, symmetry, the array form and distributions' quantiles") {
  CHECK(normal_quantile(0.0) == -std::numeric_limits<double>::infinity());
  CHECK(normal_quantile(1.0) == std::numeric_limits<double>::infinity());
  CHECK(normal_quantile(-0.5) == -std::numeric_limits<double>::infinity());
  CHECK(normal_quantile(1.5) == std::numeric_limits<double>::infinity());
  CHECK(std::isnan(normal_quantile(std::nan(""))));
  CHECK(normal_quantile(0.5) == 0.0);
  // Literal values from mpmath (50 digits, root of ncdf(z) = p for the double p).
  CHECK(normal_quantile(0.975) == doctest::Approx(1.959963984540054).epsilon(1e-15));
  CHECK(normal_quantile(1e-300) == doctest::Approx(-37.04709629936120).epsilon(1e-15));
  CHECK(normal_quantile(0x1p-54) == doctest::Approx(-8.292361075813596).epsilon(1e-15));
  // Round trip through the CDF (Boost.Math's); z <= 2, where p itself keeps z's precision.
  for (double z : {-8.0, -3.0, -0.5, 0.1, 2.0})
    CHECK(normal_quantile(normal_cdf(z)) == doctest::Approx(z).epsilon(1e-13));
  // The array form gives exactly the scalar values, in place as well.
  std::vector<double> p = {0x1p-54, 1e-300, 0.01, 0.074, 0.075,       0.3, 0.5,
                           0.7,     0.925,  0.93, 0.999, 1 - 0x1p-53, 0.0, 1.0};
  std::vector<double> z(p.size());
  normal_quantiles(p.data(), z.data(), p.size());
  for (std::size_t j = 0; j < p.size(); ++j) CHECK(z[j] == normal_quantile(p[j]));
  std::vector<double> in_place = p;
  normal_quantiles(in_place.data(), in_place.data(), in_place.size());
  CHECK(in_place == z);
  // InputDistribution::quantiles equals quantile for every kind.
  const std::vector<double> q = {1e-9, 0.02, 0.25, 0.5, 0.8, 0.999999};
  for (const InputDistribution& d :
       {InputDistribution::normal(1.5, 0.25), InputDistribution::uniform(-2, 3),
        InputDistribution::truncated_normal(0, 1, -0.5, 2), InputDistribution::normal(4, 0)}) {
    std::vector<double> x(q.size());
    d.quantiles(q.data(), x.data(), q.size());
    for (std::size_t j = 0; j < q.size(); ++j) CHECK(x[j] == d.quantile(q[j]));
  }
}
