#include "weilgen/uq/sobol_indices.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include "weilgen/base/parallel.hpp"
#include "weilgen/uq/sobol_sequence.hpp"

namespace weilgen {

namespace {

// Fixed block sizes: results never depend on the thread count.
constexpr std::size_t kDesignBlock = 1024;  // rows of A and B per design block (and MC stream)
constexpr std::size_t kEvalBlock = 16;      // rows per evaluation work item
constexpr std::size_t kResampleChunk = 40;  // bootstrap resamples per GEMM job
constexpr std::uint32_t kDesignTag = 0x5a11u;
constexpr std::uint32_t kBootstrapTag = 0xb007u;

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMatrixF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

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

// Type-7 (linear interpolation) quantile of sorted values.
double sorted_quantile(const std::vector<double>& v, double p) {
  const double h = p * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (h - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

// Resample multiplicities: row 0 all ones (the point estimate), row r >= 1 the counts of N
// draws with replacement from the stream (seed, r).
std::vector<std::uint16_t> resample_counts(std::size_t n, std::size_t resamples, std::uint64_t seed,
                                           unsigned threads) {
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

}  // namespace

void SobolOptions::validate() const {
  if (!(confidence > 0.0 && confidence < 1.0))
    throw std::invalid_argument("Sobol' indices: confidence must be in (0, 1), got " +
                                std::to_string(confidence));
  if (samples < 2)
    throw std::invalid_argument("Sobol' design: the sample size N must be at least 2, got " +
                                std::to_string(samples));
  if (samples > 0xffffffffu)
    throw std::invalid_argument("Sobol' design: the sample size N must be below 2^32");
}

double sobol_memory_bytes(const SobolOptions& o, std::size_t inputs, std::size_t outputs) {
  const double n = static_cast<double>(o.samples), k = static_cast<double>(inputs);
  const double r = static_cast<double>(o.bootstrap), m = static_cast<double>(outputs);
  return 16 * n * k                       // A and B
         + 2 * (r + 1) * n                // resample multiplicities (uint16)
         + 16 * n * m                     // f(A), f(B)
         + 8 * m * (r + 1) * (2 + 2 * k)  // accumulators
         + 8 * m * 2 * k * r              // bootstrap replicates
         + 8 * 4096 * k * m;              // a tile of f(A_B^i)
}

SobolAnalysis::SobolAnalysis(SobolOptions options) : options_(std::move(options)) {
  options_.validate();
}

SobolDesign::SobolDesign(std::vector<InputDistribution> inputs, const SobolOptions& options)
    : inputs_(std::move(inputs)),
      samples_(options.samples),
      sampling_(options.sampling),
      seed_(options.seed),
      resamples_(options.bootstrap) {
  options.validate();
  for (std::size_t i = 0; i < inputs_.size(); ++i)
    if (!inputs_[i].is_constant()) varying_.push_back(i);
  const std::size_t k = inputs_.size(), kv = varying_.size();
  if (sampling_ == Sampling::Qmc && 2 * kv > SobolSequence::max_dimensions())
    throw std::invalid_argument("Sobol' design: " + std::to_string(kv) +
                                " non-constant inputs need " + std::to_string(2 * kv) +
                                " Sobol' dimensions; at most " +
                                std::to_string(SobolSequence::max_dimensions()) + " are supported");
  std::vector<double> means(k);
  for (std::size_t i = 0; i < k; ++i) means[i] = inputs_[i].mean();
  a_.resize(samples_ * k);
  b_.resize(samples_ * k);
  parallel_blocks(samples_, kDesignBlock, options.threads,
                  [&](std::size_t block, std::size_t begin, std::size_t end, unsigned) {
                    std::vector<double> u(2 * kv);
                    std::unique_ptr<SobolSequence> qmc;
                    std::mt19937_64 rng;
                    if (kv > 0 && sampling_ == Sampling::Qmc) {
                      qmc = std::make_unique<SobolSequence>(2 * kv, seed_);
                      qmc->discard(begin);
                    } else if (kv > 0) {
                      rng = stream(seed_, block, kDesignTag);
                    }
                    for (std::size_t j = begin; j < end; ++j) {
                      if (qmc) {
                        qmc->next(u.data());
                      } else {
                        for (auto& x : u) x = open_unit(rng);
                      }
                      double* ra = a_.data() + j * k;
                      double* rb = b_.data() + j * k;
                      std::copy(means.begin(), means.end(), ra);
                      std::copy(means.begin(), means.end(), rb);
                      for (std::size_t v = 0; v < kv; ++v) {
                        const InputDistribution& d = inputs_[varying_[v]];
                        ra[varying_[v]] = d.quantile(u[v]);
                        rb[varying_[v]] = d.quantile(u[kv + v]);
                      }
                    }
                  });
  counts_ = resample_counts(samples_, resamples_, seed_, options.threads);
}

class SobolEstimator {
 public:
  static const std::vector<std::uint16_t>& counts(const SobolDesign& design,
                                                  const SobolOptions& options, unsigned threads,
                                                  std::vector<std::uint16_t>& own) {
    if (options.bootstrap == design.resamples_ && options.seed == design.seed_)
      return design.counts_;
    own = resample_counts(design.samples_, options.bootstrap, options.seed, threads);
    return own;
  }
};

// Layout of the work. f(A) and f(B) are evaluated and stored first (2N x outputs values): their
// mean m centres everything below. The N k' evaluations f(A_B^i) are then streamed in tiles of
// T rows (never stored in full). For every tile and output, the per-row terms
//   G(j, 0) = (fA - m) + (fB - m),  G(j, 1) = (fA - m)^2 + (fB - m)^2,
//   G(j, 2+2v) = (fB - m)(fAB_v - fA),  G(j, 3+2v) = (fA - fAB_v)^2
// are multiplied by the resample-count matrix W ((R+1) x N; row 0 all ones = the point
// estimate, row r the multiplicities of bootstrap resample r): acc += W(:, tile) G(tile, :).
// Every estimator (and every bootstrap replicate) is a ratio of columns of acc.
SobolResult SobolAnalysis::run(const SobolDesign& design, std::size_t outputs,
                               const VectorFunction& f) const {
  const SobolOptions& options = options_;
  if (outputs == 0) throw std::invalid_argument("Sobol' indices: no outputs");
  if (!f) throw std::invalid_argument("Sobol' indices: empty function");
  Eigen::initParallel();
  const std::size_t n = design.samples(), k = design.inputs();
  const std::vector<std::size_t>& varying = design.varying();
  const std::size_t kv = varying.size(), cols = 2 + 2 * kv;
  const std::size_t resamples = options.bootstrap, rows = resamples + 1;
  const unsigned threads = resolve_threads(options.threads);
  const auto nd = static_cast<double>(n);

  // f(A) and f(B).
  std::vector<double> fa(n * outputs), fb(n * outputs);
  parallel_blocks(n, kEvalBlock, threads,
                  [&](std::size_t, std::size_t begin, std::size_t end, unsigned t) {
                    for (std::size_t j = begin; j < end; ++j) {
                      f(t, design.a(j), fa.data() + j * outputs);
                      f(t, design.b(j), fb.data() + j * outputs);
                    }
                  });

  SobolResult result;
  result.samples = n;
  result.evaluations = n * (2 + kv);
  result.confidence = options.confidence;
  result.bootstrap = resamples;
  result.outputs.resize(outputs);
  std::vector<double> centre(outputs, 0.0), scale(outputs, 1.0);
  std::vector<char> active(outputs, 0);
  for (std::size_t o = 0; o < outputs; ++o) {
    double sum = 0, largest = 0;
    for (std::size_t j = 0; j < n; ++j) {
      const double x = fa[j * outputs + o], y = fb[j * outputs + o];
      if (!std::isfinite(x) || !std::isfinite(y))
        throw std::runtime_error(
            "Sobol' indices: the function returned a non-finite value "
            "for output " +
            std::to_string(o));
      sum += x + y;
      largest = std::max({largest, std::abs(x), std::abs(y)});
    }
    const double m = sum / (2 * nd);
    double c = 0, d = 0;
    for (std::size_t j = 0; j < n; ++j) {
      const double x = fa[j * outputs + o] - m, y = fb[j * outputs + o] - m;
      c += x + y;
      d += x * x + y * y;
    }
    const double variance = d / (2 * nd) - (c / (2 * nd)) * (c / (2 * nd));
    const double noise = 8 * std::numeric_limits<double>::epsilon() * largest;
    centre[o] = m;
    active[o] = variance > noise * noise;
    if (active[o]) scale[o] = std::ldexp(1.0, -std::ilogb(std::sqrt(variance)));
    SobolIndices& r = result.outputs[o];
    r.mean = m + c / (2 * nd);
    const double ci = resamples > 0 ? 0.0 : std::numeric_limits<double>::quiet_NaN();
    r.first.assign(k, 0.0);
    r.total.assign(k, 0.0);
    r.first_lo.assign(k, ci);
    r.first_hi.assign(k, ci);
    r.total_lo.assign(k, ci);
    r.total_hi.assign(k, ci);
    for (std::size_t i = 0; i < k; ++i) {
      const bool zero = !active[o] || design.distributions()[i].is_constant();
      if (zero && resamples > 0) r.first_lo[i] = r.first_hi[i] = r.total_lo[i] = r.total_hi[i] = 0;
    }
  }

  // Resample multiplicities: the design's when drawn for the same (seed, R).
  std::vector<std::uint16_t> own;
  const std::vector<std::uint16_t>& counts = SobolEstimator::counts(design, options, threads, own);

  // Jobs: per active output, the point estimate (row 0 of W, double precision) and chunks of
  // bootstrap resamples (single-precision GEMM: replicates only feed percentiles, whose Monte
  // Carlo error is ~1/sqrt(N), far above float rounding; accumulated in double across tiles).
  // Every job owns its accumulator; no job depends on the thread count.
  struct Job {
    std::size_t output, r0, r1;  // rows [r0, r1) of W; r0 == 0 is the point-estimate job
    RowMatrix acc;
  };
  std::vector<Job> jobs;
  for (std::size_t o = 0; o < outputs; ++o) {
    if (!active[o]) continue;
    for (std::size_t r0 = 0; r0 < rows; r0 = r0 == 0 ? 1 : r0 + kResampleChunk) {
      const std::size_t r1 = r0 == 0 ? 1 : std::min(rows, r0 + kResampleChunk);
      jobs.push_back(
          {o, r0, r1,
           RowMatrix::Zero(static_cast<Eigen::Index>(r1 - r0), static_cast<Eigen::Index>(cols))});
    }
  }

  if (!jobs.empty()) {
    // Tile height: about 2^18 stored f(A_B^i) values, 256 to 4096 rows (fixed by N, k', outputs).
    std::size_t tile = 256;
    while (tile < 4096 && tile * std::max<std::size_t>(1, kv * outputs) < (1u << 18)) tile *= 2;
    tile = std::min(tile, n);
    std::vector<double> fab(tile * kv * outputs);
    std::vector<std::vector<double>> x(threads, std::vector<double>(k));
    for (std::size_t t0 = 0; t0 < n; t0 += tile) {
      const std::size_t t1 = std::min(n, t0 + tile), height = t1 - t0;
      if (kv > 0) {
        parallel_blocks(height, kEvalBlock, threads,
                        [&](std::size_t, std::size_t begin, std::size_t end, unsigned t) {
                          double* xt = x[t].data();
                          for (std::size_t jj = begin; jj < end; ++jj) {
                            const std::size_t j = t0 + jj;
                            const double* ra = design.a(j);
                            const double* rb = design.b(j);
                            std::copy(ra, ra + k, xt);
                            for (std::size_t v = 0; v < kv; ++v) {
                              const std::size_t i = varying[v];
                              xt[i] = rb[i];
                              f(t, xt, fab.data() + (jj * kv + v) * outputs);
                              xt[i] = ra[i];
                            }
                          }
                        });
      }
      parallel_blocks(
          jobs.size(), 1, threads, [&](std::size_t job, std::size_t, std::size_t, unsigned) {
            Job& jb = jobs[job];
            const std::size_t o = jb.output;
            const double m = centre[o], sc = scale[o];
            // Row jj of G (scaled by a power of two, so the point estimate is unaffected).
            auto terms = [&](std::size_t jj, auto* row) {
              using T = std::remove_pointer_t<decltype(row)>;
              const std::size_t j = t0 + jj;
              const double fA = fa[j * outputs + o];
              const double da = (fA - m) * sc, db = (fb[j * outputs + o] - m) * sc;
              row[0] = static_cast<T>(da + db);
              row[1] = static_cast<T>(da * da + db * db);
              const double* y = fab.data() + jj * kv * outputs + o;
              for (std::size_t v = 0; v < kv; ++v) {
                const double diff = (y[v * outputs] - fA) * sc;
                row[2 + 2 * v] = static_cast<T>(db * diff);
                row[3 + 2 * v] = static_cast<T>(diff * diff);
              }
            };
            if (jb.r0 == 0) {
              std::vector<double> row(cols);
              double* acc = jb.acc.data();
              for (std::size_t jj = 0; jj < height; ++jj) {
                terms(jj, row.data());
                for (std::size_t c = 0; c < cols; ++c) acc[c] += row[c];
              }
              for (std::size_t c = 0; c < cols; ++c)
                if (!std::isfinite(acc[c]))
                  throw std::runtime_error(
                      "Sobol' indices: the function returned a non-finite value for output " +
                      std::to_string(o));
              return;
            }
            RowMatrixF g(static_cast<Eigen::Index>(height), static_cast<Eigen::Index>(cols));
            for (std::size_t jj = 0; jj < height; ++jj) terms(jj, g.data() + jj * cols);
            RowMatrixF w(static_cast<Eigen::Index>(jb.r1 - jb.r0),
                         static_cast<Eigen::Index>(height));
            for (std::size_t r = jb.r0; r < jb.r1; ++r) {
              const std::uint16_t* c = counts.data() + r * n + t0;
              float* dst = w.data() + (r - jb.r0) * height;
              for (std::size_t jj = 0; jj < height; ++jj) dst[jj] = c[jj];
            }
            const RowMatrixF product = w * g;
            jb.acc += product.cast<double>();
          });
    }
  }

  // Ratios: estimates (row 0) and bootstrap replicates (rows 1..R).
  const double lo_p = (1 - options.confidence) / 2, hi_p = 1 - lo_p;
  std::vector<std::vector<double>> replicates(2 * kv, std::vector<double>(resamples));
  for (std::size_t o = 0; o < outputs; ++o) {
    if (!active[o]) continue;
    SobolIndices& res = result.outputs[o];
    for (const Job& jb : jobs) {
      if (jb.output != o) continue;
      for (std::size_t r = jb.r0; r < jb.r1; ++r) {
        const double* a = jb.acc.data() + (r - jb.r0) * cols;
        const double mu = a[0] / (2 * nd);
        const double variance = a[1] / (2 * nd) - mu * mu;
        for (std::size_t v = 0; v < kv; ++v) {
          const double s = variance > 0 ? a[2 + 2 * v] / nd / variance : 0.0;
          const double st = variance > 0 ? a[3 + 2 * v] / (2 * nd) / variance : 0.0;
          if (r == 0) {
            res.first[varying[v]] = s;
            res.total[varying[v]] = st;
          } else {
            replicates[2 * v][r - 1] = s;
            replicates[2 * v + 1][r - 1] = st;
          }
        }
        if (r == 0) res.variance = variance / (scale[o] * scale[o]);  // exact: power of 2
      }
    }
    if (resamples == 0) continue;
    for (std::size_t v = 0; v < kv; ++v) {
      const std::size_t i = varying[v];
      std::sort(replicates[2 * v].begin(), replicates[2 * v].end());
      std::sort(replicates[2 * v + 1].begin(), replicates[2 * v + 1].end());
      res.first_lo[i] = sorted_quantile(replicates[2 * v], lo_p);
      res.first_hi[i] = sorted_quantile(replicates[2 * v], hi_p);
      res.total_lo[i] = sorted_quantile(replicates[2 * v + 1], lo_p);
      res.total_hi[i] = sorted_quantile(replicates[2 * v + 1], hi_p);
    }
  }
  return result;
}

std::vector<double> linear_sobol_indices(const std::vector<double>& coefficients,
                                         const std::vector<InputDistribution>& inputs) {
  if (coefficients.size() != inputs.size())
    throw std::invalid_argument("linear_sobol_indices: " + std::to_string(coefficients.size()) +
                                " coefficients for " + std::to_string(inputs.size()) + " inputs");
  std::vector<double> parts(inputs.size());
  double total = 0;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const double s = coefficients[i] * inputs[i].stddev();
    parts[i] = s * s;
    total += parts[i];
  }
  for (auto& p : parts) p = total > 0 ? p / total : 0.0;
  return parts;
}

}  // namespace weilgen
