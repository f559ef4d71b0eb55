// Residuals summarised per output (dx … dc, dr) and over all: sum of squares, count, largest
// magnitude and RMS. The one accumulator of identify, prediction and the gap diagnosis.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "weilgen/base/constants.hpp"

namespace weilgen {

template <std::size_t K>
class PerOutputRms {
 public:
  // A residual `v` (µm, µrad) of output `o`.
  void add(std::size_t o, double v) {
    add_square(o, v * v);
    max_[o] = std::max(max_[o], std::abs(v));
  }
  // A squared value (an expected variance, µm²) of output `o`; its RMS is that of the values.
  void add_square(std::size_t o, double v2) {
    ss_[o] += v2;
    ++n_[o];
    ss_all_ += v2;
    ++n_all_;
  }
  std::size_t count(std::size_t o) const { return n_[o]; }
  std::size_t count() const { return n_all_; }
  double sum_of_squares() const { return ss_all_; }
  // NaN for an output without residuals.
  double rms(std::size_t o) const {
    return n_[o] ? std::sqrt(ss_[o] / static_cast<double>(n_[o])) : kNaN;
  }
  double max_abs(std::size_t o) const { return n_[o] ? max_[o] : kNaN; }
  double rms() const { return n_all_ ? std::sqrt(ss_all_ / static_cast<double>(n_all_)) : kNaN; }
  std::array<double, K> rms_per_output() const {
    std::array<double, K> r{};
    for (std::size_t o = 0; o < K; ++o) r[o] = rms(o);
    return r;
  }
  std::array<double, K> max_per_output() const {
    std::array<double, K> r{};
    for (std::size_t o = 0; o < K; ++o) r[o] = max_abs(o);
    return r;
  }

 private:
  std::array<double, K> ss_{}, max_{};
  std::array<std::size_t, K> n_{};
  double ss_all_ = 0;
  std::size_t n_all_ = 0;
};

}  // namespace weilgen
