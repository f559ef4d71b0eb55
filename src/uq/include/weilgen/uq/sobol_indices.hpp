// Variance-based (Sobol') global sensitivity indices of a vector function of independent
// random inputs, estimated on the Saltelli design [A; B; A_B^i] (Saltelli et al. 2010) with
// quasi-Monte Carlo (Sobol' points) or plain Monte Carlo sampling. Generic: knows nothing about
// machines. The method, formulas, confidence intervals and costs are in docs/sensitivity.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "weilgen/uq/distribution.hpp"

namespace weilgen {

enum class Sampling { Qmc, MonteCarlo };

struct SobolOptions {
  std::size_t samples = 1u << 14;  // N: base sample size (a power of two is best for Qmc)
  Sampling sampling = Sampling::Qmc;
  std::uint64_t seed = 1;       // 0 with Qmc: unshifted Sobol' points (see sobol_sequence.hpp)
  std::size_t bootstrap = 200;  // bootstrap resamples for the confidence intervals (0 = none)
  double confidence = 0.95;     // in (0, 1)
  unsigned threads = 0;         // 0 = all cores

  // Throws std::invalid_argument naming the field: samples >= 2 and < 2^32, confidence in (0, 1).
  void validate() const;
};

// Bytes a SobolAnalysis of `inputs` inputs and `outputs` outputs holds at once with these options
// (design, resample multiplicities, f(A), f(B), accumulators, replicates): checked before a run.
double sobol_memory_bytes(const SobolOptions& options, std::size_t inputs, std::size_t outputs);

// Matrices A and B (N x k each, row-major, already mapped through each input's quantile:
// x = F^-1(u)). Built once and reused for many poses/outputs: evaluating a model is the cost,
// not sampling.
//
// Only the k' non-constant inputs are sampled: with Qmc, the 2k'-dimensional Sobol' point j gives
// row j of A (first k' coordinates, in input order) and of B (last k'); constant inputs hold
// their mean in both. Listing a constant input therefore changes nothing. With MonteCarlo, rows
// are drawn from std::mt19937_64 streams seeded from (seed, block of 1024 rows).
// The bootstrap resample multiplicities for (options.seed, options.bootstrap) are drawn here too
// (2 (R+1) N bytes), so repeated SobolAnalysis::run calls with the same options do not redraw them.
// Any N >= 2: with Qmc a power of two keeps the Sobol' net property (the most uniform design);
// other N take the sequence's first N points (the pipe-cutter seed uses N = 20000).
// Throws std::invalid_argument for samples < 2, 2k' above the Sobol' table's 3667 dimensions, or
// a confidence outside (0, 1).
class SobolDesign {
 public:
  SobolDesign(std::vector<InputDistribution> inputs, const SobolOptions& options);

  std::size_t samples() const { return samples_; }
  std::size_t inputs() const { return inputs_.size(); }
  Sampling sampling() const { return sampling_; }
  std::uint64_t seed() const { return seed_; }
  const double* a(std::size_t row) const { return a_.data() + row * inputs_.size(); }
  const double* b(std::size_t row) const { return b_.data() + row * inputs_.size(); }
  const std::vector<InputDistribution>& distributions() const { return inputs_; }
  // Indices of the non-constant inputs, ascending (the inputs that get A_B^i evaluations).
  const std::vector<std::size_t>& varying() const { return varying_; }

 private:
  std::vector<InputDistribution> inputs_;
  std::vector<std::size_t> varying_;
  std::size_t samples_;
  Sampling sampling_;
  std::uint64_t seed_;
  std::vector<double> a_, b_;
  std::size_t resamples_;
  std::vector<std::uint16_t> counts_;  // (resamples_ + 1) x N; row 0 all ones

  friend class SobolEstimator;
};

struct SobolIndices {             // one output
  double mean = 0, variance = 0;  // of the output over [A; B] (variance with divisor 2N)
  std::vector<double> first, first_lo, first_hi;  // S_i and its confidence interval
  std::vector<double> total, total_lo, total_hi;  // S_Ti (Jansen) and its CI
};

struct SobolResult {
  std::vector<SobolIndices> outputs;
  std::size_t samples = 0, evaluations = 0;  // evaluations = N (2 + number of non-constant inputs)
  double confidence = 0.95;
  std::size_t bootstrap = 0;  // resamples behind the intervals; 0: the *_lo/_hi entries are NaN
};

// f(thread, x, y): x has design.inputs() values; write `outputs` values into y. Called
// concurrently from different threads with thread in [0, resolve_threads(options.threads)):
// use it to pick a per-thread workspace. run() does not allocate per call.
using VectorFunction = std::function<void(unsigned thread, const double* x, double* y)>;

// The indices of every output of f on a design.
class SobolAnalysis {
 public:
  explicit SobolAnalysis(SobolOptions options);  // validates the options
  const SobolOptions& options() const { return options_; }

  // The sample size and sampling are the design's (options.samples and options.sampling are
  // not used); options.seed seeds the bootstrap, options.threads the parallelism. Bit-identical
  // results for any thread count. Constant inputs get exactly 0 (interval [0, 0]); an output
  // whose variance is at rounding level (V <= (8 eps max|f|)^2, e.g. exactly constant) gets
  // mean, variance 0 and all indices and intervals exactly 0. Exceptions thrown by f are
  // rethrown.
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
