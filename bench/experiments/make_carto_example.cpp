// Writes examples/data/carto_x.csv: a synthetic linear test of an X axis in the wide per-run CSV
// layout that `weilgen import` and `weilgen iso230-2` read as a Renishaw XL-80 / CARTO export
// (docs/data-format.md, "Instrument files": the layout is weilgen's documented reading of such
// exports, not a copy of one).
//
//   build/bench/experiments/weilgen_exp_make_carto_example examples/data/carto_x.csv
//
// 11 targets P_i = 100 (i − 1) + r_i mm over 1000 mm (ISO 230-2's non-uniform spacing, r_i fixed
// below), 5 bidirectional runs. Deviation of run j (1..5) at P in direction d (µm):
//   x = 4 sin(P / 150) + 0.006 P + 11.7 (T_j − 20) P / 1000 + 0.9 d + 0.4 (j − 1) + N(0, 0.25²),
// the material temperature of run j T_j = 21.4 + 0.05 (j − 1) °C (so the uncorrected scale shows
// 11.7 µm/(m K) × 1.5 K ≈ 17.6 µm/m of expansion). Each row records the mean material temperature
// of its runs from two sensors (±0.02 K) and the air (the instrument compensated it: "Air
// Compensation,Automatic"); the material it did not ("Material Compensation,Off": the readings
// carry the expansion, which `iso230-2` removes once with the coefficient of the header). Normal
// deviates: Box-Muller on std::mt19937_64 (seed 2302), so the file is the same with any standard
// library.
#include <cmath>
#include <cstdio>

#include "bench/experiments/normal_deviates.hpp"

int main(int argc, char** argv) {
  constexpr int kTargets = 11, kRuns = 5;
  const double r[kTargets] = {0, 3.2, -2.1, 4.7, -3.9, 1.4, -0.8, 2.6, -4.4, 3.7, 0};
  std::FILE* out = argc > 1 ? std::fopen(argv[1], "w") : stdout;
  if (!out) {
    std::fprintf(stderr, "cannot write %s\n", argv[1]);
    return 1;
  }
  weilgen::bench::NormalDeviates rng(2302);
  std::fprintf(out,
               "Renishaw XL-80 linear measurement (synthetic: bench/experiments/"
               "make_carto_example.cpp)\n"
               "Machine,VMC 850 (synthetic)\n"
               "Serial Number,VM-20931\n"
               "Axis,X\n"
               "Date,2024-05-02 09:14\n"
               "Operator,A. N. Other\n"
               "Location,\"Shop floor, bay 3\"\n"
               "Instrument,XL-80 laser with XC-80 compensator\n"
               "Material Expansion Coefficient (ppm/\xC2\xB0"
               "C),11.7\n"
               "Material Compensation,Off\n"
               "Air Compensation,Automatic\n"
               "\n"
               "Target Position (mm),Direction");
  for (int j = 1; j <= kRuns; ++j) std::fprintf(out, ",Run %d (\xC2\xB5m)", j);
  std::fprintf(out,
               ",Air Temperature (\xC2\xB0"
               "C),Air Pressure (mbar),Humidity (%%),"
               "Material Temperature 1 (\xC2\xB0"
               "C),Material Temperature 2 (\xC2\xB0"
               "C)\n");
  for (int pass = 0; pass < 2; ++pass) {
    for (int k = 0; k < kTargets; ++k) {
      const int i = pass == 0 ? k : kTargets - 1 - k;
      const int d = pass == 0 ? 1 : -1;
      const double p = 100.0 * i + r[i];
      std::fprintf(out, "%.3f,%s", p, d > 0 ? "Forward" : "Reverse");
      double t_mean = 0;
      for (int j = 1; j <= kRuns; ++j) {
        const double t = 21.4 + 0.05 * (j - 1);
        t_mean += t / kRuns;
        const double x = 4 * std::sin(p / 150) + 0.006 * p + 11.7 * (t - 20) * p / 1000 + 0.9 * d +
                         0.4 * (j - 1) + rng(0.25);
        std::fprintf(out, ",%.2f", x);
      }
      std::fprintf(out, ",%.2f,%.1f,%.0f,%.2f,%.2f\n", 20.8 + rng(0.02), 1009.6 + rng(0.1),
                   41 + rng(0.3), t_mean + rng(0.02), t_mean + rng(0.02));
    }
  }
  if (out != stdout && std::fclose(out) != 0) return 1;
  return 0;
}
