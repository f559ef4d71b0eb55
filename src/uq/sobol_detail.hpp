// Internals of the Sobol' engine shared by sobol_design.cpp, sobol_indices.cpp and
// sobol_bootstrap.cpp (not a public header).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "weilgen/uq/sobol_indices.hpp"

namespace weilgen::sobol_detail {

// Rows per design block, which is also the evaluation chunk: fixed, so results never depend on
// the thread count. Blocks restart in every replicate.
constexpr std::size_t kBlock = 1024;
constexpr std::size_t kBatch = kSobolMaxBatch;  // rows per call of f

// A contiguous range of rows inside one replicate.
struct RowRange {
  std::size_t replicate, begin, end;
};
std::vector<RowRange> row_ranges(std::size_t replicates, std::size_t n, std::size_t size);

// The sums of one chunk of rows, per output, all centred at the output's value c0 at design
// row 0 (so that one pass suffices; the replicate mean m enters afterwards exactly):
//   [0] sum (fA - c0) + (fB - c0)   [1] sum (fA - c0)^2 + (fB - c0)^2   [2] max |fA|, |fB|
//   per varying input v, with d = fAB_v - fA:
//   [3 + 3v] sum (fB - c0) d        [4 + 3v] sum d                      [5 + 3v] sum d^2
inline std::size_t sum_width(std::size_t varying) { return 3 + 3 * varying; }

// Bootstrap pass (SobolIntervals::Bootstrap with resamples > 0, one replicate, stored design):
// fills `centre` (the exact mean of every output over f(A), f(B)) and `sums` (one chunk per
// kBlock rows, centred at `centre`), and for every output and varying input the resample
// estimates boot_first[o][v][r], boot_total[o][v][r] (empty for outputs at rounding level).
void bootstrap_pass(const SobolDesign& design, const SobolOptions& options, std::size_t outputs,
                    const BatchFunction& f, unsigned threads, std::vector<double>& centre,
                    std::vector<double>& sums,
                    std::vector<std::vector<std::vector<double>>>& boot_first,
                    std::vector<std::vector<std::vector<double>>>& boot_total);

[[noreturn]] void non_finite(std::size_t output);

// The design's private parts for the engine.
struct DesignAccess {
  static void make_block(const SobolDesign& d, std::size_t block, double* a, double* b,
                         std::vector<double>& u, std::vector<std::uint64_t>& state) {
    d.make_block(block, a, b, u, state);
  }
  // The resample multiplicities for (seed, resamples): the design's when drawn for them.
  static const std::vector<std::uint16_t>& counts(const SobolDesign& d, std::uint64_t seed,
                                                  std::size_t resamples, unsigned threads,
                                                  std::vector<std::uint16_t>& own);
};

// Resample multiplicities: row 0 all ones (the point estimate), row r >= 1 the counts of n
// draws with replacement from the stream (seed, r).
std::vector<std::uint16_t> resample_counts(std::size_t n, std::size_t resamples, std::uint64_t seed,
                                           unsigned threads);

}  // namespace weilgen::sobol_detail
