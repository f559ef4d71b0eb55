#include "weilgen/uq/distribution.hpp"

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "weilgen/base/constants.hpp"

namespace weilgen {

namespace {
const boost::math::normal_distribution<double> kStdNormal(0.0, 1.0);

std::string number(double v) {
  std::ostringstream s;
  s.precision(12);
  s << v;
  return s.str();
}
}  // namespace

double normal_pdf(double z) { return std::isfinite(z) ? boost::math::pdf(kStdNormal, z) : 0.0; }

double normal_cdf(double z) {
  if (z == kInf) return 1.0;
  if (z == -kInf) return 0.0;
  return boost::math::cdf(kStdNormal, z);
}

InputDistribution::InputDistribution(Kind kind, double a, double b, double lo, double hi)
    : kind_(kind), a_(a), b_(b), lo_(lo), hi_(hi) {
  if (!std::isfinite(a) || !std::isfinite(b)) throw std::invalid_argument("non-finite parameter");
  if (kind == Kind::Uniform && !(hi_ >= lo_ && a_ == lo_ && b_ == hi_))
    throw std::invalid_argument("uniform: hi must be >= lo");
  if (kind != Kind::Uniform && b_ < 0) throw std::invalid_argument("sigma must be >= 0");
  if (kind == Kind::TruncatedNormal) {
    if (!(hi_ > lo_)) throw std::invalid_argument("truncated normal: hi must be > lo");
    if (b_ > 0) {
      z_lo_ = (lo_ - a_) / b_;
      z_hi_ = (hi_ - a_) / b_;
      mass_ = normal_cdf(z_hi_) - normal_cdf(z_lo_);
      if (!(mass_ > 0)) throw std::invalid_argument("truncated normal: no mass in [lo, hi]");
    } else if (a_ < lo_ || a_ > hi_) {
      throw std::invalid_argument("truncated normal: mu outside [lo, hi] with sigma 0");
    }
  }
}

InputDistribution InputDistribution::normal(double mean, double sigma) {
  return InputDistribution(Kind::Normal, mean, sigma, -kInf, kInf);
}
InputDistribution InputDistribution::uniform(double lo, double hi) {
  return InputDistribution(Kind::Uniform, lo, hi, lo, hi);
}
InputDistribution InputDistribution::truncated_normal(double mu, double sigma, double lo,
                                                      double hi) {
  return InputDistribution(Kind::TruncatedNormal, mu, sigma, lo, hi);
}

double InputDistribution::mean() const {
  switch (kind_) {
    case Kind::Normal:
      return a_;
    case Kind::Uniform:
      return 0.5 * (lo_ + hi_);
    case Kind::TruncatedNormal:
      if (b_ == 0) return a_;
      return a_ + b_ * (normal_pdf(z_lo_) - normal_pdf(z_hi_)) / mass_;
  }
  return 0;
}

double InputDistribution::stddev() const {
  switch (kind_) {
    case Kind::Normal:
      return b_;
    case Kind::Uniform:
      return (hi_ - lo_) / std::sqrt(12.0);
    case Kind::TruncatedNormal: {
      if (b_ == 0) return 0;
      const double pl = normal_pdf(z_lo_), ph = normal_pdf(z_hi_);
      const double tl = std::isfinite(z_lo_) ? z_lo_ * pl : 0.0;
      const double th = std::isfinite(z_hi_) ? z_hi_ * ph : 0.0;
      const double r = (pl - ph) / mass_;
      return b_ * std::sqrt(std::max(0.0, 1 + (tl - th) / mass_ - r * r));
    }
  }
  return 0;
}

double InputDistribution::pdf(double x) const {
  switch (kind_) {
    case Kind::Normal:
      return b_ > 0 ? normal_pdf((x - a_) / b_) / b_ : 0.0;
    case Kind::Uniform:
      return (hi_ > lo_ && x >= lo_ && x <= hi_) ? 1 / (hi_ - lo_) : 0.0;
    case Kind::TruncatedNormal:
      if (b_ == 0 || x < lo_ || x > hi_) return 0.0;
      return normal_pdf((x - a_) / b_) / (b_ * mass_);
  }
  return 0;
}

double InputDistribution::cdf(double x) const {
  switch (kind_) {
    case Kind::Normal:
      return b_ > 0 ? normal_cdf((x - a_) / b_) : (x >= a_ ? 1.0 : 0.0);
    case Kind::Uniform:
      if (x >= hi_) return 1.0;
      if (x < lo_) return 0.0;
      return (x - lo_) / (hi_ - lo_);
    case Kind::TruncatedNormal:
      if (b_ == 0) return x >= a_ ? 1.0 : 0.0;
      if (x <= lo_) return 0.0;
      if (x >= hi_) return 1.0;
      return (normal_cdf((x - a_) / b_) - normal_cdf(z_lo_)) / mass_;
  }
  return 0;
}

double InputDistribution::quantile(double p) const {
  if (is_constant()) return mean();
  switch (kind_) {
    case Kind::Normal:
      return a_ + b_ * normal_quantile(p);
    case Kind::Uniform:
      return lo_ + (hi_ - lo_) * std::min(1.0, std::max(0.0, p));
    case Kind::TruncatedNormal: {
      const double q = normal_cdf(z_lo_) + std::min(1.0, std::max(0.0, p)) * mass_;
      return std::min(hi_, std::max(lo_, a_ + b_ * normal_quantile(q)));
    }
  }
  return 0;
}

void InputDistribution::quantiles(const double* p, double* x, std::size_t n) const {
  if (is_constant()) {
    std::fill(x, x + n, mean());
    return;
  }
  switch (kind_) {
    case Kind::Normal:
      normal_quantiles(p, x, n);
      for (std::size_t j = 0; j < n; ++j) x[j] = a_ + b_ * x[j];
      return;
    case Kind::Uniform:
      for (std::size_t j = 0; j < n; ++j)
        x[j] = lo_ + (hi_ - lo_) * std::min(1.0, std::max(0.0, p[j]));
      return;
    case Kind::TruncatedNormal:
      for (std::size_t j = 0; j < n; ++j) x[j] = quantile(p[j]);
      return;
  }
}

double InputDistribution::from_standard_normal(double u) const {
  if (is_constant()) return mean();
  if (kind_ == Kind::Normal) return a_ + b_ * u;
  // Upper tail through the complement keeps precision for u >> 0.
  if (u > 0) {
    const double pc = normal_cdf(-u);
    if (kind_ == Kind::Uniform) return hi_ - (hi_ - lo_) * pc;
    const double q = normal_cdf(-z_hi_) + pc * mass_;  // P(Z > z) of the parent
    return std::min(hi_, std::max(lo_, a_ - b_ * normal_quantile(q)));
  }
  return quantile(normal_cdf(u));
}

double InputDistribution::to_standard_normal(double x) const {
  if (is_constant()) return 0.0;
  if (kind_ == Kind::Normal) return (x - a_) / b_;
  const double m = mean();
  if (x > m) return -normal_quantile(1.0 - cdf(x));
  return normal_quantile(cdf(x));
}

double InputDistribution::dx_du(double u) const {
  if (is_constant()) return 0.0;
  if (kind_ == Kind::Normal) return b_;
  const double x = from_standard_normal(u);
  const double f = pdf(x);
  return f > 0 ? normal_pdf(u) / f : 0.0;
}

InputDistribution InputDistribution::with_mean_stddev(double mean_new, double sd_new) const {
  if (sd_new < 0) throw std::invalid_argument("standard deviation must be >= 0");
  const double sd = stddev(), m = mean();
  switch (kind_) {
    case Kind::Normal:
      return normal(mean_new, sd_new);
    case Kind::Uniform: {
      const double h = sd_new * std::sqrt(3.0);
      return uniform(mean_new - h, mean_new + h);
    }
    case Kind::TruncatedNormal: {
      if (sd == 0) throw std::invalid_argument("cannot rescale a constant truncated normal");
      if (sd_new == 0) return normal(mean_new, 0.0);  // a constant
      const double k = sd_new / sd;
      // Affine map x -> mean_new + k (x - m) applied to the whole family.
      return truncated_normal(mean_new + k * (a_ - m), k * b_, mean_new + k * (lo_ - m),
                              mean_new + k * (hi_ - m));
    }
  }
  return *this;
}

InputDistribution InputDistribution::scaled(double f) const {
  if (!(f > 0)) throw std::invalid_argument("scale factor must be > 0");
  return InputDistribution(kind_, a_ * f, b_ * f, lo_ * f, hi_ * f);
}

std::string InputDistribution::str() const {
  switch (kind_) {
    case Kind::Normal:
      return "normal(" + number(a_) + ", " + number(b_) + ")";
    case Kind::Uniform:
      return "uniform(" + number(lo_) + ", " + number(hi_) + ")";
    case Kind::TruncatedNormal:
      return "truncnormal(" + number(a_) + ", " + number(b_) + ", " + number(lo_) + ", " +
             number(hi_) + ")";
  }
  return "";
}

}  // namespace weilgen
