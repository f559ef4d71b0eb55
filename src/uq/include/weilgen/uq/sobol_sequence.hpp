// Sobol' low-discrepancy points in (0, 1)^d: the Joe–Kuo (new-joe-kuo-6.21201) direction
// numbers of boost::random::sobol (up to 3667 dimensions), Gray-code order, 64-bit words.
//
// Numbering: x_0 = 0 is the all-zero point, x_n = XOR of the direction numbers v_k over the set
// bits k of gray(n) = n ^ (n >> 1) (Antonov–Saleev). Boost's engine starts at x_1 (it never
// returns the origin). Coordinates are converted by their leading 53 bits: u = floor(x 2^53) 2^-53.
//
// seed == 0: no shift; the points returned are x_1, x_2, ... (the origin, whose normal quantile
//   is -inf, is skipped). Every coordinate of x_n, 1 <= n < 2^52, is a non-zero dyadic rational.
// seed != 0: random digital shift: every coordinate's 64-bit word is XORed with its own word
//   drawn from `seed` (splitmix64). The points returned are x_0 ^ s, x_1 ^ s, ...: a digitally
//   shifted net keeps its net structure (any 2^m consecutive points starting at a multiple of
//   2^m form a (t, m, d)-net), each point is uniform on (0,1)^d, and the origin is no longer
//   special. A coordinate that would round to exactly 0 (probability 2^-53 per point) is
//   returned as 2^-54, so every coordinate lies in the open interval (0, 1).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace weilgen {

class SobolSequence {
 public:
  // dimensions in [1, max_dimensions()]; throws std::invalid_argument otherwise.
  SobolSequence(std::size_t dimensions, std::uint64_t seed);
  ~SobolSequence();
  SobolSequence(SobolSequence&&) noexcept;
  SobolSequence& operator=(SobolSequence&&) noexcept;
  SobolSequence(const SobolSequence&) = delete;
  SobolSequence& operator=(const SobolSequence&) = delete;

  std::size_t dimensions() const { return shift_.size(); }
  // Fills `dimensions()` coordinates with the next point.
  void next(double* point);
  // Skips `points` points in O(64 dimensions) operations (not O(points)).
  void discard(std::uint64_t points);

  // The largest dimension the Boost table supports (3667).
  static std::size_t max_dimensions();

 private:
  struct Engine;
  std::unique_ptr<Engine> engine_;
  std::vector<std::uint64_t> shift_;  // all zero when seed == 0
  bool at_origin_;                    // seed != 0 and x_0 not yet returned
};

}  // namespace weilgen
