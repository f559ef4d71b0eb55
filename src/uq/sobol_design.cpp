// The Sobol' design: options, the matrices A and B (stored or made block by block), and the
// bootstrap's resample multiplicities. Method: docs/sensitivity.md.
#include <algorithm>
#include <random>
#include <stdexcept>
#include <string>

#include "sobol_detail.hpp"
#include "splitmix64.hpp"
#include "weilgen/base/parallel.hpp"
#include "weilgen/uq/sobol_indices.hpp"

namespace weilgen {

namespace {

constexpr std::size_t kMaxReplicates = 1024;
constexpr std::uint32_t kDesignTag = 0x5a11u;
constexpr std::uint32_t kBootstrapTag = 0xb007u;

std::mt19937_64 stream(std::uint64_t seed, std::uint64_t block, std::uint32_t tag) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(block), static_cast<std::uint32_t>(block >> 32),
                    tag};
  return std::mt19937_64(seq);
}

// Uniform in the open interval (0, 1): the midpoint of one of 2^52 equal cells.
double open_unit(std::mt19937_64& rng) {
  return (static_cast<double>(rng() >> 12) + 0.5) * 0x1p-52;
}

// Uniform integer in [0, n), n < 2^32 (Lemire's multiply-and-reject, unbiased).
std::uint32_t bounded(std::mt19937_64& rng, std::uint32_t n) {
  std::uint64_t m = (rng() >> 32) * n;
  auto low = static_cast<std::uint32_t>(m);
  if (low < n) {
    const std::uint32_t threshold = (0u - n) % n;
    while (low < threshold) {
      m = (rng() >> 32) * n;
      low = static_cast<std::uint32_t>(m);
    }
  }
  return static_cast<std::uint32_t>(m >> 32);
}

}  // namespace

std::uint64_t sobol_replicate_seed(std::uint64_t seed, std::size_t r, std::size_t replicates) {
  if (replicates == 1) return seed;
  std::uint64_t state = seed + 0x9e3779b97f4a7c15ULL * r;  // splitmix64 steps to + (r + 1) γ
  const std::uint64_t z = splitmix64(state);
  return z != 0 ? z : 1;
}

namespace sobol_detail {

std::vector<RowRange> row_ranges(std::size_t replicates, std::size_t n, std::size_t size) {
  std::vector<RowRange> out;
  for (std::size_t r = 0; r < replicates; ++r)
    for (std::size_t j = 0; j < n; j += size)
      out.push_back({r, r * n + j, r * n + std::min(n, j + size)});
  return out;
}

void non_finite(std::size_t output) {
  throw std::runtime_error("Sobol' indices: the function returned a non-finite value for output " +
                           std::to_string(output));
}

std::vector<std::uint16_t> resample_counts(std::size_t n, std::size_t resamples, std::uint64_t seed,
                                           unsigned threads) {
  if (resamples == 0) return {};
  std::vector<std::uint16_t> counts((resamples + 1) * n, 0);
  std::fill(counts.begin(), counts.begin() + static_cast<std::ptrdiff_t>(n), 1);
  parallel_blocks(resamples, 1, threads, [&](std::size_t r, std::size_t, std::size_t, unsigned) {
    std::mt19937_64 rng = stream(seed, r + 1, kBootstrapTag);
    std::uint16_t* w = counts.data() + (r + 1) * n;
    for (std::size_t j = 0; j < n; ++j) {
      std::uint16_t& c = w[bounded(rng, static_cast<std::uint32_t>(n))];
      if (c == 0xffff) throw std::overflow_error("Sobol' bootstrap: resample count overflow");
      ++c;
    }
  });
  return counts;
}

const std::vector<std::uint16_t>& DesignAccess::counts(const SobolDesign& d, std::uint64_t seed,
                                                       std::size_t resamples, unsigned threads,
                                                       std::vector<std::uint16_t>& own) {
  if (resamples == d.resamples_ && seed == d.seed_) return d.counts_;
  own = resample_counts(d.samples_, resamples, seed, threads);
  return own;
}

}  // namespace sobol_detail

const char* interval_method_name(SobolIntervals intervals) {
  switch (intervals) {
    case SobolIntervals::Replicates:
      return "replicates";
    case SobolIntervals::Bootstrap:
      return "bootstrap";
    case SobolIntervals::None:
      return "none";
  }
  return "";
}

void SobolOptions::validate() const {
  if (!(confidence > 0.0 && confidence < 1.0))
    throw std::invalid_argument("Sobol' indices: confidence must be in (0, 1), got " +
                                std::to_string(confidence));
  if (samples < 2)
    throw std::invalid_argument("Sobol' design: the sample size N must be at least 2, got " +
                                std::to_string(samples));
  if (samples > 0xffffffffu)
    throw std::invalid_argument("Sobol' design: the sample size N must be below 2^32");
  if (intervals != SobolIntervals::Replicates) return;
  if (replicates < 2 || replicates > kMaxReplicates)
    throw std::invalid_argument("Sobol' design: replicates must be in [2, " +
                                std::to_string(kMaxReplicates) + "], got " +
                                std::to_string(replicates));
  if (samples % replicates != 0 || samples / replicates < 2)
    throw std::invalid_argument("Sobol' design: the sample size N = " + std::to_string(samples) +
                                " must be a multiple of the replicates R = " +
                                std::to_string(replicates) + " with N / R >= 2");
  if (sampling == Sampling::Qmc && seed == 0)
    throw std::invalid_argument(
        "Sobol' design: seed 0 (unrandomised Sobol' points) cannot give independent replicates; "
        "use a seed != 0, or the bootstrap / no intervals");
}

SobolDesign::SobolDesign(std::vector<InputDistribution> inputs, const SobolOptions& options,
                         bool store)
    : inputs_(std::move(inputs)),
      samples_(options.samples),
      replicates_(options.replicate_count()),
      sampling_(options.sampling),
      seed_(options.seed),
      stored_(store || options.intervals == SobolIntervals::Bootstrap),
      resamples_(options.intervals == SobolIntervals::Bootstrap ? options.bootstrap : 0) {
  options.validate();
  for (std::size_t i = 0; i < inputs_.size(); ++i)
    if (!inputs_[i].is_constant()) varying_.push_back(i);
  const std::size_t k = inputs_.size(), dims = 2 * varying_.size();
  if (sampling_ == Sampling::Qmc && dims > SobolSequence::max_dimensions())
    throw std::invalid_argument("Sobol' design: " + std::to_string(varying_.size()) +
                                " non-constant inputs need " + std::to_string(dims) +
                                " Sobol' dimensions; at most " +
                                std::to_string(SobolSequence::max_dimensions()) + " are supported");
  // One sequence per replicate, copied by every block: replicates are independent linear
  // matrix scrambles with digital shifts; a single design keeps the digital shift alone
  // (seed != 0) or the plain points (seed 0), as before replicates existed.
  if (sampling_ == Sampling::Qmc && dims > 0)
    for (std::size_t r = 0; r < replicates_; ++r)
      sequences_.emplace_back(dims, sobol_replicate_seed(seed_, r, replicates_), replicates_ > 1);
  if (stored_) {
    a_.resize(samples_ * k);
    b_.resize(samples_ * k);
    const auto blocks =
        sobol_detail::row_ranges(replicates_, samples_ / replicates_, sobol_detail::kBlock);
    parallel_blocks(blocks.size(), 1, options.threads,
                    [&](std::size_t block, std::size_t, std::size_t, unsigned) {
                      std::vector<double> u;
                      std::vector<std::uint64_t> state;
                      const std::size_t begin = blocks[block].begin;
                      make_block(block, a_.data() + begin * k, b_.data() + begin * k, u, state);
                    });
  }
  counts_ = sobol_detail::resample_counts(samples_, resamples_, seed_, options.threads);
}

void SobolDesign::make_block(std::size_t block, double* a, double* b, std::vector<double>& u,
                             std::vector<std::uint64_t>& state) const {
  const std::size_t k = inputs_.size(), kv = varying_.size(), dims = 2 * kv;
  const std::size_t n = samples_ / replicates_,
                    per = (n + sobol_detail::kBlock - 1) / sobol_detail::kBlock;
  const std::size_t r = block / per, first = (block % per) * sobol_detail::kBlock;
  const std::size_t rows = std::min(n, first + sobol_detail::kBlock) - first;
  for (std::size_t i = 0; i < k; ++i)
    if (inputs_[i].is_constant())
      for (std::size_t j = 0; j < rows; ++j) a[j * k + i] = b[j * k + i] = inputs_[i].mean();
  if (kv == 0) return;
  u.resize(dims * rows);  // dimension-major uniforms, mapped in place
  if (sampling_ == Sampling::Qmc) {
    sequences_[r].points(first, rows, u.data(), rows, state);
  } else {
    std::mt19937_64 rng = stream(seed_, block, kDesignTag);
    for (std::size_t j = 0; j < rows; ++j)
      for (std::size_t d = 0; d < dims; ++d) u[d * rows + j] = open_unit(rng);
  }
  // Interleaved: dimensions 2v and 2v + 1 give varying input v's columns of A and B (see
  // docs/sensitivity.md, "The sampling design", for why not A in the first k' dimensions).
  for (std::size_t d = 0; d < dims; ++d) {
    const std::size_t i = varying_[d / 2];
    double* col = u.data() + d * rows;
    inputs_[i].quantiles(col, col, rows);
    double* dst = (d % 2 == 0 ? a : b) + i;
    for (std::size_t j = 0; j < rows; ++j) dst[j * k] = col[j];
  }
}

}  // namespace weilgen
