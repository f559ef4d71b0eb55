#include "weilgen/uq/sobol_sequence.hpp"

#include <algorithm>
#include <boost/random/sobol.hpp>
#include <limits>
#include <stdexcept>
#include <string>

#include "splitmix64.hpp"

namespace weilgen {

namespace {

constexpr unsigned kBits = 64;
using Lattice = boost::random::qrng_detail::sobol_lattice<std::uint64_t, kBits,
                                                          boost::random::default_sobol_table>;

// The leading 53 bits of a 64-bit word as a double in [0, 1); 0 becomes 2^-54.
inline double to_unit(std::uint64_t x) {
  const double u = static_cast<double>(x >> 11) * 0x1p-53;
  return u > 0.0 ? u : 0x1p-54;
}

inline unsigned lowest_bit(std::uint64_t n) { return static_cast<unsigned>(__builtin_ctzll(n)); }

// y = L x over GF(2) for a lower-triangular binary L with unit diagonal, digits counted from
// the most significant bit (digit 1 = bit 63): the XOR of the columns of L at x's set digits.
// Column j (digit j + 1) is `cols[j]`: its own digit and random digits after it. Direction
// number k has at most k + 1 set digits, so this costs ~1000 XORs per coordinate.
std::uint64_t apply_scramble(const std::uint64_t* cols, std::uint64_t x) {
  std::uint64_t y = 0;
  while (x != 0) {
    const auto j = static_cast<unsigned>(__builtin_clzll(x));  // the leading set digit
    y ^= cols[j];
    x &= ~(std::uint64_t{1} << (kBits - 1 - j));
  }
  return y;
}

}  // namespace

std::size_t SobolSequence::max_dimensions() {
  return boost::random::default_sobol_table::max_dimension;
}

SobolSequence::SobolSequence(std::size_t dimensions, std::uint64_t seed, bool scramble)
    : shift_(dimensions, 0), state_(dimensions, 0), index_(seed == 0 ? 1 : 0), origin_(index_) {
  if (dimensions == 0 || dimensions > max_dimensions())
    throw std::invalid_argument("Sobol' sequence: " + std::to_string(dimensions) +
                                " dimensions requested; supported are 1 to " +
                                std::to_string(max_dimensions()));
  if (scramble && seed == 0)
    throw std::invalid_argument("Sobol' sequence: a scrambled sequence needs a seed != 0");
  const Lattice lattice(dimensions);
  dirs_.resize(kBits * dimensions);
  for (std::size_t k = 0; k < kBits; ++k) {
    auto it = lattice.iter_at(k * dimensions);
    for (std::size_t d = 0; d < dimensions; ++d) dirs_[d * kBits + k] = it[d];
  }
  if (seed != 0) {
    std::uint64_t state = seed;
    for (auto& s : shift_) s = splitmix64(state);
    if (scramble) {
      // Per coordinate the 64 columns of L: column j keeps digit j + 1 and has random digits
      // below it (less significant bits), none above (lower triangular).
      std::uint64_t cols[kBits];
      for (std::size_t d = 0; d < dimensions; ++d) {
        for (unsigned j = 0; j < kBits; ++j) {
          const std::uint64_t below = j == kBits - 1 ? 0 : ~std::uint64_t{0} >> (j + 1);
          cols[j] = (splitmix64(state) & below) | (std::uint64_t{1} << (kBits - 1 - j));
        }
        for (std::size_t k = 0; k < kBits; ++k)
          dirs_[d * kBits + k] = apply_scramble(cols, dirs_[d * kBits + k]);
      }
    }
  }
  if (index_ == 1)
    for (std::size_t d = 0; d < dimensions; ++d) state_[d] = dirs_[d * kBits];
}

void SobolSequence::advance() {
  ++index_;
  if (index_ == 0) throw std::out_of_range("Sobol' sequence: past the end of the sequence");
  const std::size_t d = state_.size();
  const std::uint64_t* v = dirs_.data() + lowest_bit(index_);  // gray(n+1) ^ gray(n)
  for (std::size_t i = 0; i < d; ++i) state_[i] ^= v[i * kBits];
}

void SobolSequence::next(double* point) {
  const std::size_t d = state_.size();
  for (std::size_t i = 0; i < d; ++i) point[i] = to_unit(state_[i] ^ shift_[i]);
  advance();
}

// Points index, index + 1, ... of the scrambled words (state = the words of point `index`,
// advanced past the last point), dimension-major into out[i * stride + j].
void SobolSequence::fill(std::uint64_t& index, std::vector<std::uint64_t>& state, std::size_t count,
                         double* out, std::size_t stride) const {
  // Dimension by dimension over sub-blocks of points (contiguous writes, one dimension's 64
  // direction numbers in cache): first the direction number that each step flips.
  constexpr std::size_t kSub = 256;
  unsigned flip[kSub];
  const std::size_t d = state.size();
  for (std::size_t b = 0; b < count; b += kSub) {
    const std::size_t m = std::min(kSub, count - b);
    if (index > std::numeric_limits<std::uint64_t>::max() - m)
      throw std::out_of_range("Sobol' sequence: past the end of the sequence");
    for (std::size_t j = 0; j < m; ++j) flip[j] = lowest_bit(index + 1 + j);
    for (std::size_t i = 0; i < d; ++i) {
      std::uint64_t x = state[i];
      const std::uint64_t s = shift_[i];
      const std::uint64_t* v = dirs_.data() + i * kBits;
      double* o = out + i * stride + b;
      for (std::size_t j = 0; j < m; ++j) {
        o[j] = to_unit(x ^ s);
        x ^= v[flip[j]];
      }
      state[i] = x;
    }
    index += m;
  }
}

void SobolSequence::state_at(std::uint64_t index, std::vector<std::uint64_t>& state) const {
  const std::size_t d = shift_.size();
  state.assign(d, 0);
  const std::uint64_t gray = index ^ (index >> 1);
  for (unsigned k = 0; k < kBits; ++k)
    if ((gray >> k) & 1u)
      for (std::size_t i = 0; i < d; ++i) state[i] ^= dirs_[i * kBits + k];
}

void SobolSequence::next_block(std::size_t count, double* out, std::size_t stride) {
  fill(index_, state_, count, out, stride);
}

void SobolSequence::points(std::uint64_t first, std::size_t count, double* out, std::size_t stride,
                           std::vector<std::uint64_t>& state) const {
  if (first > std::numeric_limits<std::uint64_t>::max() - origin_)
    throw std::out_of_range("Sobol' sequence: point beyond the end of the sequence");
  std::uint64_t index = origin_ + first;
  state_at(index, state);
  fill(index, state, count, out, stride);
}

void SobolSequence::discard(std::uint64_t points) {
  if (points > std::numeric_limits<std::uint64_t>::max() - index_)
    throw std::out_of_range("Sobol' sequence: discard beyond the end of the sequence");
  index_ += points;
  state_at(index_, state_);
}

}  // namespace weilgen
