#include "weilgen/uq/sobol_sequence.hpp"

#include <boost/random/sobol.hpp>
#include <limits>
#include <stdexcept>
#include <string>

namespace weilgen {

namespace {

std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// The leading 53 bits of a 64-bit word as a double in [0, 1); 0 becomes 2^-54.
double to_unit(std::uint64_t x) {
  const double u = static_cast<double>(x >> 11) * 0x1p-53;
  return u > 0.0 ? u : 0x1p-54;
}

}  // namespace

struct SobolSequence::Engine {
  explicit Engine(std::size_t d) : sobol(d) {}
  boost::random::sobol sobol;
};

std::size_t SobolSequence::max_dimensions() {
  return boost::random::detail::qrng_tables::sobol::max_dimension;
}

SobolSequence::SobolSequence(std::size_t dimensions, std::uint64_t seed)
    : shift_(dimensions, 0), at_origin_(seed != 0) {
  if (dimensions == 0 || dimensions > max_dimensions())
    throw std::invalid_argument("Sobol' sequence: " + std::to_string(dimensions) +
                                " dimensions requested; supported are 1 to " +
                                std::to_string(max_dimensions()));
  engine_ = std::make_unique<Engine>(dimensions);
  if (seed != 0) {
    std::uint64_t state = seed;
    for (auto& s : shift_) s = splitmix64(state);
  }
}

SobolSequence::~SobolSequence() = default;
SobolSequence::SobolSequence(SobolSequence&&) noexcept = default;
SobolSequence& SobolSequence::operator=(SobolSequence&&) noexcept = default;

void SobolSequence::next(double* point) {
  const std::size_t d = shift_.size();
  if (at_origin_) {
    at_origin_ = false;
    for (std::size_t i = 0; i < d; ++i) point[i] = to_unit(shift_[i]);
    return;
  }
  for (std::size_t i = 0; i < d; ++i) point[i] = to_unit(engine_->sobol() ^ shift_[i]);
}

void SobolSequence::discard(std::uint64_t points) {
  if (points == 0) return;
  if (at_origin_) {
    at_origin_ = false;
    --points;
  }
  if (points == 0) return;
  const std::uint64_t d = shift_.size();
  if (points > std::numeric_limits<std::uint64_t>::max() / d)
    throw std::out_of_range("Sobol' sequence: discard beyond the end of the sequence");
  // We only ever consume whole points, so Boost's element cursor is at a point boundary.
  engine_->sobol.discard(points * d);
}

}  // namespace weilgen
