// Sobol' low-discrepancy points in (0, 1)^d: the Joe–Kuo (new-joe-kuo-6.21201) direction
// numbers of Boost.Random's table (up to 3667 dimensions), Gray-code order, 64-bit words.
//
// Numbering: x_0 = 0 is the all-zero point, x_n = XOR of the direction numbers v_k over the set
// bits k of gray(n) = n ^ (n >> 1) (Antonov–Saleev). Coordinates are converted by their leading
// 53 bits: u = floor(x 2^53) 2^-53.
//
// seed == 0: no randomisation; the points returned are x_1, x_2, ... (the origin, whose normal
//   quantile is -inf, is skipped). Every coordinate of x_n, 1 <= n < 2^52, is a non-zero dyadic
//   rational. The same points as Boost's sobol engine and Joe–Kuo's sobol.cc.
// seed != 0: randomised; the points returned are y_0, y_1, ... with y_n = M x_n ^ s:
//   - s: a random digital shift, one 64-bit word per coordinate (splitmix64 from `seed`);
//   - M: with `scramble`, a random linear matrix scramble (Matoušek 1998): per coordinate a
//     random lower-triangular binary matrix with unit diagonal acting on the binary digits
//     (digit i of y is digit i of x plus a random combination of the digits before it); without
//     `scramble`, M = identity (a digital shift only).
//   Both keep the net structure (any 2^m consecutive points starting at a multiple of 2^m form a
//   (t, m, d)-net), make each point uniform on (0,1)^d, and different seeds give independent
//   randomisations: the basis of randomised-QMC error estimates (docs/sensitivity.md). A
//   coordinate that would round to exactly 0 (probability 2^-53 per point) is returned as 2^-54,
//   so every coordinate lies in the open interval (0, 1).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace weilgen {

class SobolSequence {
 public:
  // dimensions in [1, max_dimensions()]; throws std::invalid_argument otherwise, and for
  // scramble with seed == 0.
  SobolSequence(std::size_t dimensions, std::uint64_t seed, bool scramble = false);

  std::size_t dimensions() const { return shift_.size(); }
  // Fills `dimensions()` coordinates with the next point.
  void next(double* point);
  // The next `count` points, dimension-major: coordinate d of the j-th point goes to
  // out[d * stride + j] (stride >= count). Same points as `count` calls of next().
  void next_block(std::size_t count, double* out, std::size_t stride);
  // Skips `points` points in O(64 dimensions) operations (not O(points)).
  void discard(std::uint64_t points);
  // Points first .. first + count - 1 counted from the start of the sequence (what a fresh
  // sequence's next() returns after `first` calls), laid out as in next_block. Const: threads
  // share one sequence, each with its own `state` (scratch, resized to dimensions()).
  void points(std::uint64_t first, std::size_t count, double* out, std::size_t stride,
              std::vector<std::uint64_t>& state) const;

  // The largest dimension the direction-number table supports (3667).
  static std::size_t max_dimensions();

 private:
  void advance();  // state_ from point index_ to index_ + 1
  void fill(std::uint64_t& index, std::vector<std::uint64_t>& state, std::size_t count, double* out,
            std::size_t stride) const;
  void state_at(std::uint64_t index, std::vector<std::uint64_t>& state) const;
  std::vector<std::uint64_t> dirs_;   // dimensions x 64: direction number k of coordinate d
  std::vector<std::uint64_t> shift_;  // all zero when seed == 0
  std::vector<std::uint64_t> state_;  // M x_index_ (unshifted)
  std::uint64_t index_;               // number of the point next() returns
  std::uint64_t origin_;              // the first point's number: 1 unrandomised, else 0
};

}  // namespace weilgen
