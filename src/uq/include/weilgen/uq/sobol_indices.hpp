// Variance-based (Sobol') global sensitivity indices of a vector function of independent
// random inputs, estimated on the Saltelli design [A; B; A_B^i] (Saltelli et al. 2010) with
// randomised quasi-Monte Carlo (scrambled Sobol' points) or plain Monte Carlo sampling. Generic:
// knows nothing about machines. The method, formulas, confidence intervals and costs are in
// docs/sensitivity.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "weilgen/uq/distribution.hpp"
#include "weilgen/uq/sobol_sequence.hpp"

namespace weilgen {

enum class Sampling { Qmc, MonteCarlo };

// Where the confidence intervals come from.
//   Replicates: the N rows are R independent randomisations of n = N / R rows each (QMC: R
//     independent scrambles of the Sobol' net; MC: R independent batches); every index is the
//     mean of its R replicate estimates, and its interval mean +- t_{R-1} sd / sqrt(R)
//     (Student t). Costs nothing beyond the N (k' + 2) evaluations.
//   Bootstrap: one design of N rows; percentile bootstrap over rows with `bootstrap` resamples.
//     Valid for MC; on QMC it measures the Monte-Carlo spread, a conservative bound.
//   None: one design of N rows, no intervals (the *_lo/_hi entries are NaN).
enum class SobolIntervals { Replicates, Bootstrap, None };

struct SobolOptions {
  std::size_t samples = 1u << 14;  // N: base sample size over all replicates (powers of two
                                   // keep the Sobol' net property of every replicate)
  Sampling sampling = Sampling::Qmc;
  std::uint64_t seed = 1;  // 0 with Qmc: unrandomised Sobol' points (not with Replicates)
  SobolIntervals intervals = SobolIntervals::Replicates;
  std::size_t replicates = 4;   // R, with Replicates: 2 <= R <= 1024, N a multiple of R, N/R >= 2
                                // (4: docs/sensitivity.md, "Confidence intervals")
  std::size_t bootstrap = 200;  // resamples, with Bootstrap (0: no intervals, like None)
  double confidence = 0.95;     // in (0, 1)
  unsigned threads = 0;         // 0 = all cores

  // Throws std::invalid_argument naming the field and its range: samples >= 2 and < 2^32,
  // confidence in (0, 1), the replicate conditions above, seed != 0 for Qmc replicates.
  void validate() const;
  // Replicates behind the point estimate: `replicates` with Replicates, else 1.
  std::size_t replicate_count() const {
    return intervals == SobolIntervals::Replicates ? replicates : 1;
  }
};

// Bytes a SobolAnalysis of `inputs` inputs and `outputs` outputs holds at once with these options
// (design, resample multiplicities, f(A), f(B), accumulators, replicates): checked before a run.
double sobol_memory_bytes(const SobolOptions& options, std::size_t inputs, std::size_t outputs);

// The seed of QMC replicate r of R: its SobolSequence(2k', seed, /*scramble=*/R > 1) is the
// replicate's design (R = 1: `seed` itself, so 0 stays unrandomised). splitmix64's output for
// the state seed + (r + 1) γ; never 0.
std::uint64_t sobol_replicate_seed(std::uint64_t seed, std::size_t r, std::size_t replicates);

// "replicates" | "bootstrap" | "none": the interval method as written in documents.
const char* interval_method_name(SobolIntervals intervals);

namespace sobol_detail {
struct DesignAccess;
}

// Matrices A and B (N x k each, row-major, already mapped through each input's quantile:
// x = F^-1(u)).
//
// Only the k' non-constant inputs are sampled: with Qmc, the 2k'-dimensional Sobol' point j gives
// row j of A (first k' coordinates, in input order) and of B (last k'); constant inputs hold
// their mean in both. Listing a constant input therefore changes nothing. Replicate r holds rows
// [r n, (r + 1) n), made in blocks of 1024 rows: with Qmc the points 0 .. n-1 of its own
// linearly scrambled and digitally shifted sequence (seeded from (seed, r)); a single design
// (bootstrap, none) is the digitally shifted sequence of `seed` (seed 0: unshifted). With
// MonteCarlo, every block of rows has its own std::mt19937_64 stream seeded from (seed, block
// number). Any n >= 2: with Qmc a power of two keeps the net property (the most uniform design);
// other n take the sequence's first n points.
//
// `store` = true keeps A and B in memory (16 N k bytes): build the design once and reuse it for
// many poses or outputs. `store` = false keeps only the sequences: every analysis makes each
// block of rows when it evaluates it (one pass over the design, no N x k matrices; the right
// choice for a single run). A bootstrap design is always stored, and its resample multiplicities
// for (options.seed, options.bootstrap) are drawn here too (2 (R+1) N bytes).
// Throws std::invalid_argument for invalid options (SobolOptions::validate) or 2k' above the
// Sobol' table's 3667 dimensions.
class SobolDesign {
 public:
  SobolDesign(std::vector<InputDistribution> inputs, const SobolOptions& options,
              bool store = true);

  std::size_t samples() const { return samples_; }
  std::size_t replicates() const { return replicates_; }
  std::size_t inputs() const { return inputs_.size(); }
  Sampling sampling() const { return sampling_; }
  std::uint64_t seed() const { return seed_; }
  bool stored() const { return stored_; }
  // Row `row` of A and B; stored designs only (nullptr otherwise).
  const double* a(std::size_t row) const {
    return a_.empty() ? nullptr : a_.data() + row * inputs_.size();
  }
  const double* b(std::size_t row) const {
    return b_.empty() ? nullptr : b_.data() + row * inputs_.size();
  }
  const std::vector<InputDistribution>& distributions() const { return inputs_; }
  // Indices of the non-constant inputs, ascending (the inputs that get A_B^i evaluations).
  const std::vector<std::size_t>& varying() const { return varying_; }

 private:
  // Rows of design block `block` into a and b (row-major, rows x inputs()); u, state: scratch.
  void make_block(std::size_t block, double* a, double* b, std::vector<double>& u,
                  std::vector<std::uint64_t>& state) const;

  std::vector<InputDistribution> inputs_;
  std::vector<std::size_t> varying_;
  std::size_t samples_, replicates_;
  Sampling sampling_;
  std::uint64_t seed_;
  std::vector<SobolSequence> sequences_;  // Qmc: one per replicate, at point 0
  bool stored_;
  std::vector<double> a_, b_;  // stored designs
  std::size_t resamples_;
  std::vector<std::uint16_t> counts_;  // bootstrap: (resamples_ + 1) x N; row 0 all ones

  friend struct sobol_detail::DesignAccess;
};

struct SobolIndices {             // one output
  double mean = 0, variance = 0;  // of the output over [A; B] (variance with divisor 2N)
  std::vector<double> first, first_lo, first_hi;  // S_i and its confidence interval
  std::vector<double> total, total_lo, total_hi;  // S_Ti (Jansen) and its CI
  // With replicates (R > 1): every replicate's own estimates, replicate-major (entry r k + i is
  // replicate r's S_i or S_Ti; first and total are their means). Empty otherwise, and for an
  // output at rounding level.
  std::vector<double> first_replicates, total_replicates;
};

struct SobolResult {
  std::vector<SobolIndices> outputs;
  std::size_t samples = 0, evaluations = 0;  // evaluations = N (2 + number of non-constant inputs)
  double confidence = 0.95;
  SobolIntervals intervals = SobolIntervals::Replicates;
  std::size_t replicates = 1;  // R behind the estimates (1 unless Replicates)
  std::size_t bootstrap = 0;   // resamples behind the intervals (0 unless Bootstrap)
};

// f(thread, x, y): x has design.inputs() values; write `outputs` values into y.
using VectorFunction = std::function<void(unsigned thread, const double* x, double* y)>;
// f(thread, count, x, y): `count` points, x row-major (count x design.inputs()); write
// count x outputs values, row-major, into y. Called with 1 <= count <= kSobolMaxBatch.
inline constexpr std::size_t kSobolMaxBatch = 64;
using BatchFunction =
    std::function<void(unsigned thread, std::size_t count, const double* x, double* y)>;
// Either is called concurrently from different threads with thread in
// [0, resolve_threads(options.threads)): use it to pick a per-thread workspace. run() does not
// allocate per call.

// The indices of every output of f on a design.
class SobolAnalysis {
 public:
  explicit SobolAnalysis(SobolOptions options);  // validates the options
  const SobolOptions& options() const { return options_; }

  // The sample size, replicates and sampling are the design's (options.samples, .replicates and
  // .sampling are not used); options.intervals must match the design's (replicates or one
  // design), options.seed seeds the bootstrap, options.threads the parallelism. Bit-identical
  // results for any thread count. Constant inputs get exactly 0 (interval [0, 0]); an output
  // whose variance is at rounding level (V <= (8 eps max|f|)^2, e.g. exactly constant) gets
  // mean, variance 0 and all indices and intervals exactly 0. Exceptions thrown by f are
  // rethrown; non-finite outputs are a std::runtime_error.
  SobolResult run(const SobolDesign& design, std::size_t outputs, const BatchFunction& f) const;
  SobolResult run(const SobolDesign& design, std::size_t outputs, const VectorFunction& f) const;

 private:
  SobolOptions options_;
};

// Exact indices of y = c0 + sum c_i x_i with independent inputs:
// S_i = S_Ti = c_i^2 s_i^2 / sum_j c_j^2 s_j^2 (all zero when the variance is zero).
// Throws std::invalid_argument when the sizes differ.
std::vector<double> linear_sobol_indices(const std::vector<double>& coefficients,
                                         const std::vector<InputDistribution>& inputs);

}  // namespace weilgen
