// Convergence of the Sobol' index estimators: max abs error over first and total indices
// against the analytic values, versus N = 2^8 ... 2^16, for QMC (digitally shifted Sobol'
// points) and plain Monte Carlo, averaged over seeds; then the cost of the engine on a model
// the size of a machine (70 inputs, 7 outputs, ~100 ns per evaluation).
//
//   weilgen_exp_sobol_convergence [--seeds S] [--threads T] [--csv PATH] [--repeats R]
//                                 [--no-timing]
//
// Reported in docs/experiments/sobol_convergence.md.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "weilgen/base/parallel.hpp"
#include "weilgen/uq/sobol_indices.hpp"

using namespace weilgen;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Problem {
  std::string name;
  std::vector<InputDistribution> inputs;
  double (*f)(const double*);
  std::vector<double> first, total;
};

double ishigami(const double* x) {
  const double s2 = std::sin(x[1]);
  return std::sin(x[0]) * (1 + 0.1 * std::pow(x[2], 4)) + 7.0 * s2 * s2;
}

const double kGa[8] = {0, 1, 4.5, 9, 99, 99, 99, 99};
double g_function(const double* x) {
  double p = 1;
  for (int i = 0; i < 8; ++i) p *= (std::abs(4 * x[i] - 2) + kGa[i]) / (1 + kGa[i]);
  return p;
}

Problem ishigami_problem() {
  const double a = 7, b = 0.1, pi4 = std::pow(kPi, 4), pi8 = pi4 * pi4;
  const double v1 = 0.5 * (1 + b * pi4 / 5) * (1 + b * pi4 / 5), v2 = a * a / 8;
  const double v13 = b * b * pi8 * (1.0 / 18 - 1.0 / 50), v = v1 + v2 + v13;
  return {"Ishigami (k=3)",
          std::vector<InputDistribution>(3, InputDistribution::uniform(-kPi, kPi)),
          ishigami,
          {v1 / v, v2 / v, 0},
          {(v1 + v13) / v, v2 / v, v13 / v}};
}

Problem g_problem() {
  Problem p{"G-function (k=8)",
            std::vector<InputDistribution>(8, InputDistribution::uniform(0, 1)),
            g_function,
            {},
            {}};
  double prod = 1;
  std::vector<double> vi;
  for (double a : kGa) {
    vi.push_back(1.0 / (3 * (1 + a) * (1 + a)));
    prod *= 1 + vi.back();
  }
  for (double x : vi) {
    p.first.push_back(x / (prod - 1));
    p.total.push_back(x * prod / (1 + x) / (prod - 1));
  }
  return p;
}

// Max error of one run: a single design (replicates = 1) or R scrambled replicates of N/R.
double error(const Problem& p, Sampling sampling, std::size_t n, std::uint64_t seed,
             unsigned threads, std::size_t replicates = 1) {
  SobolOptions o;
  o.samples = n;
  o.sampling = sampling;
  o.seed = seed;
  o.intervals = replicates > 1 ? SobolIntervals::Replicates : SobolIntervals::None;
  o.replicates = replicates;
  o.threads = threads;
  const SobolDesign design(p.inputs, o);
  const auto fn = p.f;
  const SobolIndices s =
      SobolAnalysis(o)
          .run(design, 1, [fn](unsigned, const double* x, double* y) { *y = fn(x); })
          .outputs[0];
  double e = 0;
  for (std::size_t i = 0; i < p.first.size(); ++i)
    e = std::max({e, std::abs(s.first[i] - p.first[i]), std::abs(s.total[i] - p.total[i])});
  return e;
}

double slope(const std::vector<double>& x, const std::vector<double>& y) {
  double mx = 0, my = 0;
  const double n = static_cast<double>(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += std::log(x[i]) / n;
    my += std::log(y[i]) / n;
  }
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (std::log(x[i]) - mx) * (std::log(y[i]) - my);
    sxx += (std::log(x[i]) - mx) * (std::log(x[i]) - mx);
  }
  return sxy / sxx;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A dense linear model with k inputs and m outputs, y = C x (k m multiply-adds, ~100 ns for
// k = 70, m = 7): the size and cost of a machine error model. All times single-threaded (the
// overhead ratio is what matters; the estimate's parallel speed-up is shown separately).
void timing(unsigned threads, int repeats) {
  const std::size_t k = 70, m = 7;
  std::vector<double> c(k * m);
  for (std::size_t i = 0; i < c.size(); ++i) c[i] = std::sin(static_cast<double>(i + 1));
  const auto model = [&c](unsigned, const double* x, double* y) {
    double acc[m] = {0, 0, 0, 0, 0, 0, 0};
    for (std::size_t i = 0; i < k; ++i)
      for (std::size_t o = 0; o < m; ++o) acc[o] += c[i * m + o] * x[i];
    for (std::size_t o = 0; o < m; ++o) y[o] = acc[o];
  };
  // The same model through the batch interface (one call per batch of points).
  const BatchFunction batch = [&model](unsigned t, std::size_t count, const double* x, double* y) {
    for (std::size_t j = 0; j < count; ++j) model(t, x + j * k, y + j * m);
  };
  std::vector<InputDistribution> inputs;
  for (std::size_t i = 0; i < k; ++i)
    inputs.push_back(i % 2 ? InputDistribution::normal(0, 0.005)
                           : InputDistribution::uniform(-0.01, 0.01));
  // Best of `repeats` runs (the machine may be shared).
  const auto best = [repeats](auto&& body) {
    double t = 1e300;
    for (int r = 0; r < repeats; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      body();
      t = std::min(t, seconds_since(t0));
    }
    return t;
  };
  std::printf(
      "\nCost on a 70-input, 7-output linear model (seconds, best of %d; 1 thread unless "
      "stated):\n\n",
      repeats);
  std::printf(
      "| N | evaluations | bare evaluations | design | estimate, no intervals | estimate, 8 "
      "replicates | design + estimate, bootstrap 200 | 8 replicates, %u threads |\n"
      "| --- | --- | --- | --- | --- | --- | --- | --- |\n",
      threads);
  for (std::size_t n : {std::size_t{1} << 12, std::size_t{1} << 14, std::size_t{1} << 16}) {
    SobolOptions o;  // default: 8 replicates
    o.samples = n;
    o.threads = 1;
    const double t_design = best([&] { SobolDesign d(inputs, o); });
    const SobolDesign design(inputs, o);
    SobolOptions o0 = o, ob = o;
    o0.intervals = SobolIntervals::None;
    ob.intervals = SobolIntervals::Bootstrap;
    ob.bootstrap = 200;
    const SobolDesign design0(inputs, o0);
    // The evaluations alone, in the engine's order, without storing anything.
    std::vector<double> x(k), y(m);
    double sink = 0;
    const double t_bare = best([&] {
      for (std::size_t j = 0; j < n; ++j) {
        model(0, design.a(j), y.data());
        sink += y[0];
        model(0, design.b(j), y.data());
        sink += y[0];
        std::copy(design.a(j), design.a(j) + k, x.begin());
        for (std::size_t i = 0; i < k; ++i) {
          x[i] = design.b(j)[i];
          model(0, x.data(), y.data());
          sink += y[0];
          x[i] = design.a(j)[i];
        }
      }
    });
    SobolResult r0, r1, rb, rt;
    const double t_est0 = best([&] { r0 = SobolAnalysis(o0).run(design0, m, batch); });
    const double t_est1 = best([&] { r1 = SobolAnalysis(o).run(design, m, batch); });
    const double t_boot = best([&] {
      const SobolDesign d(inputs, ob);
      rb = SobolAnalysis(ob).run(d, m, batch);
    });
    SobolOptions ot = o;
    ot.threads = threads;
    const double t_estt = best([&] { rt = SobolAnalysis(ot).run(design, m, batch); });
    std::printf("| 2^%d | %zu | %.3f (%.0f ns each) | %.3f | %.3f | %.3f | %.3f | %.3f |\n",
                static_cast<int>(std::log2(static_cast<double>(n))), r0.evaluations, t_bare,
                1e9 * t_bare / static_cast<double>(r0.evaluations), t_design, t_est0, t_est1,
                t_boot, t_estt);
    if (sink == 0.123456789 || r1.outputs[0].first_lo != rt.outputs[0].first_lo)
      std::printf("(thread counts disagree)\n");
  }
}

}  // namespace

int main(int argc, char** argv) {
  int seeds = 10, repeats = 3;
  unsigned threads = 0;
  bool with_timing = true;
  std::string csv;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--seeds" && i + 1 < argc) {
      seeds = std::atoi(argv[++i]);
    } else if (a == "--threads" && i + 1 < argc) {
      threads = static_cast<unsigned>(std::atoi(argv[++i]));
    } else if (a == "--csv" && i + 1 < argc) {
      csv = argv[++i];
    } else if (a == "--repeats" && i + 1 < argc) {
      repeats = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--no-timing") {
      with_timing = false;
    } else {
      std::fprintf(stderr,
                   "usage: %s [--seeds S] [--threads T] [--csv PATH] [--repeats R] [--no-timing]\n",
                   argv[0]);
      return 2;
    }
  }
  std::ofstream out;
  if (!csv.empty()) {
    out.open(csv);
    if (!out) {
      std::fprintf(stderr, "cannot write %s\n", csv.c_str());
      return 1;
    }
    out << "function,sampling,N,mean_max_error,max_max_error\n";
  }
  std::printf("Mean (over %d seeds) of the max abs error over first and total indices:\n\n", seeds);
  for (const Problem& p : {ishigami_problem(), g_problem()}) {
    std::printf(
        "%s\n\n| N | QMC mean | QMC worst | MC mean | MC worst | MC / QMC | RQMC 8 replicates "
        "mean | RQMC worst |\n| --- | --- | --- | --- | --- | --- | --- | --- |\n",
        p.name.c_str());
    std::vector<double> ns, qmc, mc;
    for (int e = 8; e <= 16; ++e) {
      const std::size_t n = std::size_t{1} << e;
      double mean[3] = {0, 0, 0}, worst[3] = {0, 0, 0};
      for (int s = 1; s <= seeds; ++s) {
        for (int m = 0; m < 3; ++m) {
          const double err = error(p, m == 1 ? Sampling::MonteCarlo : Sampling::Qmc, n,
                                   static_cast<std::uint64_t>(s), threads, m == 2 ? 8 : 1);
          mean[m] += err / seeds;
          worst[m] = std::max(worst[m], err);
        }
      }
      ns.push_back(static_cast<double>(n));
      qmc.push_back(mean[0]);
      mc.push_back(mean[1]);
      std::printf("| 2^%d | %.2e | %.2e | %.2e | %.2e | %.1f | %.2e | %.2e |\n", e, mean[0],
                  worst[0], mean[1], worst[1], mean[1] / mean[0], mean[2], worst[2]);
      if (out) {
        out << p.name << ",qmc," << n << ',' << mean[0] << ',' << worst[0] << '\n';
        out << p.name << ",mc," << n << ',' << mean[1] << ',' << worst[1] << '\n';
        out << p.name << ",rqmc8," << n << ',' << mean[2] << ',' << worst[2] << '\n';
      }
    }
    std::printf("\nlog-log slope of the mean error vs N: QMC %.2f, MC %.2f\n\n", slope(ns, qmc),
                slope(ns, mc));
  }
  if (with_timing) timing(resolve_threads(threads), repeats);
  return 0;
}
