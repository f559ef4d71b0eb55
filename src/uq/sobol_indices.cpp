// The Sobol' estimators in one pass over the design, and the replicate intervals.
// Method and formulas: docs/sensitivity.md.
#include "weilgen/uq/sobol_indices.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "sobol_detail.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/base/parallel.hpp"
#include "weilgen/uq/test_statistics.hpp"

namespace weilgen {

using sobol_detail::kBatch;
using sobol_detail::kBlock;
using sobol_detail::sum_width;

namespace {

// Type-7 (linear interpolation) quantile of sorted values.
double sorted_quantile(const std::vector<double>& v, double p) {
  const double h = p * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (h - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

// One pass over the design, chunk by chunk (a chunk is a design block of 1024 rows of one
// replicate): make (or copy) the chunk's rows of A and B, evaluate f(A) and f(B) in batches,
// then for every varying input i set column i of a batch of A rows to B's values, evaluate the
// batch and restore the column (2 x rows writes per input instead of rows x k), and accumulate the
// chunk's sums (sobol_detail::sum_width) centred at c0. Every chunk has its own slot; slots are
// reduced in chunk order, so the result does not depend on the thread count.
void streamed_pass(const SobolDesign& design, std::size_t outputs, const BatchFunction& f,
                   unsigned threads, const std::vector<double>& c0, std::vector<double>& sums) {
  const std::size_t k = design.inputs(), kv = design.varying().size(), w = sum_width(kv);
  const std::vector<std::size_t>& varying = design.varying();
  const std::size_t n = design.samples() / design.replicates();
  const auto chunks = sobol_detail::row_ranges(design.replicates(), n, kBlock);
  struct Work {  // per thread
    std::vector<double> a, b, fa, fb, y, u;
    std::vector<std::uint64_t> state;
  };
  std::vector<Work> work(threads);
  for (Work& wk : work) {
    wk.a.resize(kBlock * k);
    wk.b.resize(design.stored() ? 0 : kBlock * k);
    wk.fa.resize(kBlock * outputs);
    wk.fb.resize(kBlock * outputs);
    wk.y.resize(kBatch * outputs);
  }
  parallel_blocks(
      chunks.size(), 1, threads, [&](std::size_t ci, std::size_t, std::size_t, unsigned t) {
        Work& wk = work[t];
        const std::size_t begin = chunks[ci].begin, rows = chunks[ci].end - begin;
        double* x = wk.a.data();  // A rows, columns swapped in turn
        const double* brows;
        if (design.stored()) {
          std::memcpy(x, design.a(begin), rows * k * sizeof(double));
          brows = design.b(begin);
        } else {
          sobol_detail::DesignAccess::make_block(design, ci, x, wk.b.data(), wk.u, wk.state);
          brows = wk.b.data();
        }
        for (std::size_t j = 0; j < rows; j += kBatch) {
          const std::size_t count = std::min(kBatch, rows - j);
          f(t, count, x + j * k, wk.fa.data() + j * outputs);
          f(t, count, brows + j * k, wk.fb.data() + j * outputs);
        }
        double* s = sums.data() + ci * outputs * w;
        for (std::size_t o = 0; o < outputs; ++o) {
          double s0 = 0, s1 = 0, largest = 0;
          for (std::size_t j = 0; j < rows; ++j) {
            const double fa = wk.fa[j * outputs + o], fb = wk.fb[j * outputs + o];
            if (!std::isfinite(fa) || !std::isfinite(fb)) sobol_detail::non_finite(o);
            const double da = fa - c0[o], db = fb - c0[o];
            s0 += da + db;
            s1 += da * da + db * db;
            largest = std::max({largest, std::abs(fa), std::abs(fb)});
          }
          s[o * w] = s0, s[o * w + 1] = s1, s[o * w + 2] = largest;
        }
        for (std::size_t b0 = 0; b0 < rows; b0 += kBatch) {
          const std::size_t b1 = std::min(rows, b0 + kBatch), count = b1 - b0;
          for (std::size_t v = 0; v < kv; ++v) {
            const std::size_t i = varying[v];
            double saved[kBatch];
            for (std::size_t j = b0; j < b1; ++j) {
              saved[j - b0] = x[j * k + i];
              x[j * k + i] = brows[j * k + i];
            }
            f(t, count, x + b0 * k, wk.y.data());
            for (std::size_t j = b0; j < b1; ++j) x[j * k + i] = saved[j - b0];
            for (std::size_t o = 0; o < outputs; ++o) {
              double p = 0, d = 0, q = 0;
              for (std::size_t j = 0; j < count; ++j) {
                const double fa = wk.fa[(b0 + j) * outputs + o];
                const double diff = wk.y[j * outputs + o] - fa;
                p += (wk.fb[(b0 + j) * outputs + o] - c0[o]) * diff;
                d += diff;
                q += diff * diff;
              }
              s[o * w + 3 + 3 * v] += p;
              s[o * w + 4 + 3 * v] += d;
              s[o * w + 5 + 3 * v] += q;
            }
          }
        }
      });
}

}  // namespace

double sobol_memory_bytes(const SobolOptions& o, std::size_t inputs, std::size_t outputs) {
  const double n = static_cast<double>(o.samples), k = static_cast<double>(inputs);
  const double r =
      o.intervals == SobolIntervals::Bootstrap ? static_cast<double>(o.bootstrap) : 0.0;
  const double m = static_cast<double>(outputs);
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

SobolResult SobolAnalysis::run(const SobolDesign& design, std::size_t outputs,
                               const VectorFunction& f) const {
  if (!f) throw std::invalid_argument("Sobol' indices: empty function");
  const std::size_t k = design.inputs();
  return run(design, outputs,
             [&f, k, outputs](unsigned t, std::size_t count, const double* x, double* y) {
               for (std::size_t j = 0; j < count; ++j) f(t, x + j * k, y + j * outputs);
             });
}

SobolResult SobolAnalysis::run(const SobolDesign& design, std::size_t outputs,
                               const BatchFunction& f) const {
  const SobolOptions& options = options_;
  if (outputs == 0) throw std::invalid_argument("Sobol' indices: no outputs");
  if (!f) throw std::invalid_argument("Sobol' indices: empty function");
  if (options.replicate_count() != design.replicates())
    throw std::invalid_argument(
        "Sobol' indices: the design has " + std::to_string(design.replicates()) +
        " replicates, the options ask for " + std::to_string(options.replicate_count()));
  const std::size_t big_n = design.samples(), k = design.inputs();
  const std::size_t replicates = design.replicates(), n = big_n / replicates;
  const std::vector<std::size_t>& varying = design.varying();
  const std::size_t kv = varying.size(), w = sum_width(kv);
  const bool bootstrap = options.intervals == SobolIntervals::Bootstrap && options.bootstrap > 0;
  const bool intervals = bootstrap || options.intervals == SobolIntervals::Replicates;
  const unsigned threads = resolve_threads(options.threads);
  const auto chunks = sobol_detail::row_ranges(replicates, n, kBlock);
  std::vector<double> sums(chunks.size() * outputs * w, 0.0), c0(outputs);
  std::vector<std::vector<std::vector<double>>> boot_first, boot_total;
  if (bootstrap) {
    sobol_detail::bootstrap_pass(design, options, outputs, f, threads, c0, sums, boot_first,
                                 boot_total);
  } else {
    // The centre: f at design row 0 (a sampled point, so always in f's domain).
    std::vector<double> a0(design.stored() ? 0 : kBlock * k), b0(a0.size()), u;
    std::vector<std::uint64_t> state;
    if (!design.stored())
      sobol_detail::DesignAccess::make_block(design, 0, a0.data(), b0.data(), u, state);
    f(0, 1, design.stored() ? design.a(0) : a0.data(), c0.data());
    for (std::size_t o = 0; o < outputs; ++o)
      if (!std::isfinite(c0[o])) sobol_detail::non_finite(o);
    streamed_pass(design, outputs, f, threads, c0, sums);
  }

  SobolResult result;
  result.samples = big_n;
  result.evaluations = big_n * (2 + kv);
  result.confidence = options.confidence;
  result.intervals = options.intervals;
  result.replicates = replicates;
  result.bootstrap = bootstrap ? options.bootstrap : 0;
  result.outputs.resize(outputs);
  const double hi_p = (1 + options.confidence) / 2, lo_p = 1 - hi_p;
  const double t_quantile =
      replicates > 1 ? students_t_quantile(static_cast<double>(replicates - 1), hi_p) : kNaN;
  const auto nd = static_cast<double>(n), two_n_all = 2 * static_cast<double>(big_n);
  std::vector<double> acc(w), first(replicates * kv), total(replicates * kv);
  for (std::size_t o = 0; o < outputs; ++o) {
    SobolIndices& res = result.outputs[o];
    // Pooled over every replicate: mean, variance and the rounding-level test.
    double s0 = 0, s1 = 0, largest = 0;
    for (std::size_t ci = 0; ci < chunks.size(); ++ci) {
      const double* s = sums.data() + (ci * outputs + o) * w;
      s0 += s[0], s1 += s[1], largest = std::max(largest, s[2]);
    }
    const double shift = s0 / two_n_all, variance = s1 / two_n_all - shift * shift;
    const double noise = 8 * std::numeric_limits<double>::epsilon() * largest;
    const bool active = variance > noise * noise;
    res.mean = c0[o] + shift;
    res.variance = active ? variance : 0.0;
    const double zero_ci = intervals ? 0.0 : kNaN;
    res.first.assign(k, 0.0);
    res.total.assign(k, 0.0);
    res.first_lo.assign(k, zero_ci);
    res.first_hi.assign(k, zero_ci);
    res.total_lo.assign(k, zero_ci);
    res.total_hi.assign(k, zero_ci);
    if (!active) continue;
    // Per replicate: V, V_i = (sum (fB - m) d) / n and V_Ti = (sum d^2) / 2n, with
    // sum (fB - m) d = sum (fB - c0) d - (m - c0) sum d.
    for (std::size_t r = 0; r < replicates; ++r) {
      std::fill(acc.begin(), acc.end(), 0.0);
      for (std::size_t ci = 0; ci < chunks.size(); ++ci) {
        if (chunks[ci].replicate != r) continue;
        const double* s = sums.data() + (ci * outputs + o) * w;
        for (std::size_t c = 0; c < w; ++c) acc[c] += s[c];
      }
      const double m_shift = acc[0] / (2 * nd), v = acc[1] / (2 * nd) - m_shift * m_shift;
      for (std::size_t j = 0; j < kv; ++j) {
        const double vi = (acc[3 + 3 * j] - m_shift * acc[4 + 3 * j]) / nd;
        const double vti = acc[5 + 3 * j] / (2 * nd);
        if (!std::isfinite(vi) || !std::isfinite(vti)) sobol_detail::non_finite(o);
        first[r * kv + j] = v > 0 ? vi / v : 0.0;
        total[r * kv + j] = v > 0 ? vti / v : 0.0;
      }
    }
    if (replicates > 1) {
      res.first_replicates.assign(replicates * k, 0.0);
      res.total_replicates.assign(replicates * k, 0.0);
      for (std::size_t r = 0; r < replicates; ++r)
        for (std::size_t j = 0; j < kv; ++j) {
          res.first_replicates[r * k + varying[j]] = first[r * kv + j];
          res.total_replicates[r * k + varying[j]] = total[r * kv + j];
        }
    }
    for (std::size_t j = 0; j < kv; ++j) {
      const std::size_t i = varying[j];
      for (int which = 0; which < 2; ++which) {
        const std::vector<double>& rep = which == 0 ? first : total;
        double mean = 0;
        for (std::size_t r = 0; r < replicates; ++r) mean += rep[r * kv + j];
        mean /= static_cast<double>(replicates);
        (which == 0 ? res.first : res.total)[i] = mean;
        double& lo = (which == 0 ? res.first_lo : res.total_lo)[i];
        double& hi = (which == 0 ? res.first_hi : res.total_hi)[i];
        if (replicates > 1) {
          // Student t over the replicates: mean +- t_{R-1} sd / sqrt(R).
          double ss = 0;
          for (std::size_t r = 0; r < replicates; ++r) {
            const double d = rep[r * kv + j] - mean;
            ss += d * d;
          }
          const auto rd = static_cast<double>(replicates);
          const double half = t_quantile * std::sqrt(ss / (rd - 1) / rd);
          lo = mean - half;
          hi = mean + half;
        } else if (bootstrap) {
          std::vector<double>& b = (which == 0 ? boot_first : boot_total)[o][j];
          std::sort(b.begin(), b.end());
          lo = sorted_quantile(b, lo_p);
          hi = sorted_quantile(b, hi_p);
        } else {
          lo = hi = kNaN;
        }
      }
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
