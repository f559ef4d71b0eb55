// Standard normal deviates for the synthetic-data programs: Box-Muller on std::mt19937_64, so a
// seed gives the same file with any standard library (std::normal_distribution is not portable).
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace weilgen::bench {

class NormalDeviates {
 public:
  explicit NormalDeviates(std::uint64_t seed) : g_(seed) {}
  double operator()() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = (static_cast<double>(g_() >> 11) + 1.0) * 0x1.0p-53;
    const double u2 = static_cast<double>(g_() >> 11) * 0x1.0p-53;
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2 * M_PI * u2);
    has_spare_ = true;
    return r * std::cos(2 * M_PI * u2);
  }
  double operator()(double sigma) { return sigma * (*this)(); }
  double uniform() { return static_cast<double>(g_() >> 11) * 0x1.0p-53; }  // [0, 1)

 private:
  std::mt19937_64 g_;
  double spare_ = 0;
  bool has_spare_ = false;
};

}  // namespace weilgen::bench
