// Writes examples/data/iso230_2_drift.csv: synthetic ISO 230-2 line runs of an X axis under
// thermal drift, shaped like the first measurement of Stejskal et al. 2017 (16 targets
// over 300 mm, bidirectional cycles, a local anomaly at position 3).
//
//   build-iso/bench/experiments/weilgen_exp_make_iso_drift_data examples/data/iso230_2_drift.csv
//
// Model of each observation (um), deterministic for the seed below:
//   x = profile(X) ± 0.75 (reversal 1.5 um) + 4 um/h · t + N(0, 0.4²),
//   profile(X) = 3 sin(X / 60 mm) + 0.01 X,
// with 4× the noise (1.6 um) at target 3 (X = 40 mm) in the positive direction only. Each cycle
// runs up through X = 0, 20, ..., 300 then down; one observation every 15 s (dwell and move), so a
// cycle takes 8 min and the 30 cycles 4 h. T_table (degC) rises 0.3 K/h from 22 degC with
// N(0, 0.01²) noise. Normal deviates: Box-Muller on std::mt19937_64 (seed 20171205), so the file
// is the same with any standard library.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>

#include "bench/experiments/normal_deviates.hpp"

namespace {

using Normal = weilgen::bench::NormalDeviates;  // bench/experiments/normal_deviates.hpp

}  // namespace

int main(int argc, char** argv) {
  constexpr int kTargets = 16, kCycles = 30, kAnomalous = 2;  // target 3 (0-based 2)
  constexpr double kSpacing = 20, kDt = 15, kDrift = 4, kSigma = 0.4, kReversal = 1.5;
  std::FILE* out = argc > 1 ? std::fopen(argv[1], "w") : stdout;
  if (!out) {
    std::fprintf(stderr, "cannot write %s\n", argv[1]);
    return 1;
  }
  Normal rng(20171205);
  std::fprintf(
      out,
      "# Synthetic ISO 230-2 runs under thermal drift, written by\n"
      "# bench/experiments/make_iso_drift_data.cpp (seed 20171205; model in its header):\n"
      "# x = 3 sin(X/60) + 0.01 X +-0.75 + 4 um/h * t + N(0, 0.4^2), 4x noise at X=40 (+).\n"
      "# axis: X\n"
      "# machine: synthetic three-axis milling machine\n"
      "# feed_mm_min: 300\n"
      "X,dir,cycle,t_s,T_table,dx_um\n");
  double t = 0;
  for (int j = 1; j <= kCycles; ++j) {
    for (int pass = 0; pass < 2; ++pass) {
      for (int k = 0; k < kTargets; ++k) {
        const int i = pass == 0 ? k : kTargets - 1 - k;
        const int dir = pass == 0 ? 1 : -1;
        const double x = kSpacing * i;
        const double sigma = kSigma * (pass == 0 && i == kAnomalous ? 4.0 : 1.0);
        const double dev = 3 * std::sin(x / 60.0) + 0.01 * x + dir * kReversal / 2 +
                           kDrift * t / 3600.0 + sigma * rng();
        const double temp = 22.0 + 0.3 * t / 3600.0 + 0.01 * rng();
        std::fprintf(out, "%g,%d,%d,%g,%.3f,%.3f\n", x, dir, j, t, temp, dev);
        t += kDt;
      }
    }
  }
  if (out != stdout && std::fclose(out) != 0) return 1;
  return 0;
}
