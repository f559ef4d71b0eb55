// The bootstrap pass of the Sobol' estimators: f(A) and f(B) first (their exact mean centres
// every sum), then f(A_B^i) tile by tile, each tile's per-row terms multiplied by the resample
// multiplicities. Method: docs/sensitivity.md ("Confidence intervals").
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "sobol_detail.hpp"
#include "weilgen/base/parallel.hpp"

namespace weilgen::sobol_detail {

namespace {

constexpr std::size_t kTile = 4 * kBlock;   // rows whose f(A_B^i) are kept at once
constexpr std::size_t kResampleChunk = 40;  // resamples per GEMM job

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMatrixF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

}  // namespace

// Layout: for every tile and active output, the per-row terms
//   G(j, 0) = (fA - m) + (fB - m),  G(j, 1) = (fA - m)^2 + (fB - m)^2,
//   G(j, 2+2v) = (fB - m)(fAB_v - fA),  G(j, 3+2v) = (fA - fAB_v)^2
// are multiplied by the resample-count matrix W (R x N, row r the multiplicities of resample
// r): acc += W(:, tile) G(tile, :) in single precision (the replicates only feed percentiles,
// whose Monte Carlo error ~1/sqrt(N) is far above float rounding; the terms are scaled by a
// power of two near 1/sd first), accumulated in double across tiles. Every resample estimate is
// a ratio of columns of acc. Jobs (output, chunk of resamples) own their accumulators.
void bootstrap_pass(const SobolDesign& design, const SobolOptions& options, std::size_t outputs,
                    const BatchFunction& f, unsigned threads, std::vector<double>& centre,
                    std::vector<double>& sums,
                    std::vector<std::vector<std::vector<double>>>& boot_first,
                    std::vector<std::vector<std::vector<double>>>& boot_total) {
  Eigen::initParallel();
  const std::size_t big_n = design.samples(), k = design.inputs();
  const std::vector<std::size_t>& varying = design.varying();
  const std::size_t kv = varying.size(), w = sum_width(kv), cols = 2 + 2 * kv;
  const std::size_t resamples = options.bootstrap;
  const auto nd = static_cast<double>(big_n);

  std::vector<double> fa(big_n * outputs), fb(big_n * outputs);
  parallel_blocks(big_n, kBatch, threads,
                  [&](std::size_t, std::size_t begin, std::size_t end, unsigned t) {
                    f(t, end - begin, design.a(begin), fa.data() + begin * outputs);
                    f(t, end - begin, design.b(begin), fb.data() + begin * outputs);
                  });
  std::vector<double> scale(outputs, 1.0);
  std::vector<char> active(outputs, 0);
  boot_first.assign(outputs, {});
  boot_total.assign(outputs, {});
  for (std::size_t o = 0; o < outputs; ++o) {
    double sum = 0, largest = 0;
    for (std::size_t j = 0; j < big_n; ++j) {
      const double x = fa[j * outputs + o], y = fb[j * outputs + o];
      if (!std::isfinite(x) || !std::isfinite(y)) non_finite(o);
      sum += x + y;
      largest = std::max({largest, std::abs(x), std::abs(y)});
    }
    const double m = sum / (2 * nd);
    double c = 0, d = 0;
    for (std::size_t j = 0; j < big_n; ++j) {
      const double x = fa[j * outputs + o] - m, y = fb[j * outputs + o] - m;
      c += x + y;
      d += x * x + y * y;
    }
    const double variance = d / (2 * nd) - (c / (2 * nd)) * (c / (2 * nd));
    const double noise = 8 * std::numeric_limits<double>::epsilon() * largest;
    centre[o] = m;
    active[o] = variance > noise * noise;
    if (active[o]) scale[o] = std::ldexp(1.0, -std::ilogb(std::sqrt(variance)));
    if (active[o]) {
      boot_first[o].assign(kv, std::vector<double>(resamples));
      boot_total[o].assign(kv, std::vector<double>(resamples));
    }
  }

  std::vector<std::uint16_t> own;
  const std::vector<std::uint16_t>& counts =
      DesignAccess::counts(design, options.seed, resamples, threads, own);
  struct Job {
    std::size_t output, r0, r1;  // rows [r0, r1) of W, r0 >= 1
    RowMatrix acc;
  };
  std::vector<Job> jobs;
  for (std::size_t o = 0; o < outputs; ++o) {
    if (!active[o] || kv == 0) continue;
    for (std::size_t r0 = 1; r0 <= resamples; r0 += kResampleChunk) {
      const std::size_t r1 = std::min(resamples + 1, r0 + kResampleChunk);
      jobs.push_back(
          {o, r0, r1,
           RowMatrix::Zero(static_cast<Eigen::Index>(r1 - r0), static_cast<Eigen::Index>(cols))});
    }
  }

  // f(A_B^i) of one tile, [row in tile][v][output]; chunk sums as in the streamed pass.
  const auto chunks = row_ranges(1, big_n, kBlock);
  std::vector<double> tile_f(std::min(kTile, big_n) * kv * outputs);
  std::vector<std::vector<double>> xbuf(threads, std::vector<double>(kBlock * k));
  std::vector<std::vector<double>> ybuf(threads, std::vector<double>(kBatch * outputs));
  for (std::size_t tile = 0; tile < big_n; tile += kTile) {
    const std::size_t tile_end = std::min(big_n, tile + kTile), height = tile_end - tile;
    const std::size_t c0 = tile / kBlock, c1 = (tile_end + kBlock - 1) / kBlock;
    parallel_blocks(c1 - c0, 1, threads, [&](std::size_t c, std::size_t, std::size_t, unsigned t) {
      const std::size_t ci = c0 + c, begin = chunks[ci].begin, rows = chunks[ci].end - begin;
      double* x = xbuf[t].data();
      double* y = ybuf[t].data();
      std::memcpy(x, design.a(begin), rows * k * sizeof(double));
      double* s = sums.data() + ci * outputs * w;
      for (std::size_t o = 0; o < outputs; ++o) {
        double s0 = 0, s1 = 0, largest = 0;
        for (std::size_t j = begin; j < begin + rows; ++j) {
          const double da = fa[j * outputs + o] - centre[o], db = fb[j * outputs + o] - centre[o];
          s0 += da + db;
          s1 += da * da + db * db;
          largest =
              std::max({largest, std::abs(fa[j * outputs + o]), std::abs(fb[j * outputs + o])});
        }
        s[o * w] = s0, s[o * w + 1] = s1, s[o * w + 2] = largest;
      }
      for (std::size_t b0 = 0; b0 < rows; b0 += kBatch) {
        const std::size_t count = std::min(kBatch, rows - b0);
        for (std::size_t v = 0; v < kv; ++v) {
          const std::size_t i = varying[v];
          for (std::size_t j = b0; j < b0 + count; ++j) x[j * k + i] = design.b(begin + j)[i];
          f(t, count, x + b0 * k, y);
          for (std::size_t j = b0; j < b0 + count; ++j) x[j * k + i] = design.a(begin + j)[i];
          for (std::size_t j = 0; j < count; ++j) {
            const std::size_t row = begin + b0 + j;
            std::memcpy(tile_f.data() + ((row - tile) * kv + v) * outputs, y + j * outputs,
                        outputs * sizeof(double));
            for (std::size_t o = 0; o < outputs; ++o) {
              const double diff = y[j * outputs + o] - fa[row * outputs + o];
              s[o * w + 3 + 3 * v] += (fb[row * outputs + o] - centre[o]) * diff;
              s[o * w + 4 + 3 * v] += diff;
              s[o * w + 5 + 3 * v] += diff * diff;
            }
          }
        }
      }
    });
    parallel_blocks(
        jobs.size(), 1, threads, [&](std::size_t job, std::size_t, std::size_t, unsigned) {
          Job& jb = jobs[job];
          const std::size_t o = jb.output;
          const double m = centre[o], sc = scale[o];
          RowMatrixF g(static_cast<Eigen::Index>(height), static_cast<Eigen::Index>(cols));
          for (std::size_t jj = 0; jj < height; ++jj) {
            const std::size_t j = tile + jj;
            float* row = g.data() + jj * cols;
            const double fA = fa[j * outputs + o];
            const double da = (fA - m) * sc, db = (fb[j * outputs + o] - m) * sc;
            row[0] = static_cast<float>(da + db);
            row[1] = static_cast<float>(da * da + db * db);
            const double* y = tile_f.data() + jj * kv * outputs + o;
            for (std::size_t v = 0; v < kv; ++v) {
              const double diff = (y[v * outputs] - fA) * sc;
              row[2 + 2 * v] = static_cast<float>(db * diff);
              row[3 + 2 * v] = static_cast<float>(diff * diff);
            }
          }
          RowMatrixF wm(static_cast<Eigen::Index>(jb.r1 - jb.r0),
                        static_cast<Eigen::Index>(height));
          for (std::size_t r = jb.r0; r < jb.r1; ++r) {
            const std::uint16_t* c = counts.data() + r * big_n + tile;
            float* dst = wm.data() + (r - jb.r0) * height;
            for (std::size_t jj = 0; jj < height; ++jj) dst[jj] = c[jj];
          }
          const RowMatrixF product = wm * g;
          jb.acc += product.cast<double>();
        });
  }
  for (const Job& jb : jobs) {
    for (std::size_t r = jb.r0; r < jb.r1; ++r) {
      const double* a = jb.acc.data() + (r - jb.r0) * cols;
      const double mu = a[0] / (2 * nd);
      const double variance = a[1] / (2 * nd) - mu * mu;
      for (std::size_t v = 0; v < kv; ++v) {
        boot_first[jb.output][v][r - 1] = variance > 0 ? a[2 + 2 * v] / nd / variance : 0.0;
        boot_total[jb.output][v][r - 1] = variance > 0 ? a[3 + 2 * v] / (2 * nd) / variance : 0.0;
      }
    }
  }
}

}  // namespace weilgen::sobol_detail
