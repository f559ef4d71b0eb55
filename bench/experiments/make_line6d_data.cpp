// Writes examples/data/line6d_x.csv: a synthetic 6D-laser line measurement of the X axis of a
// 500 mm travel, sampled every 10 mm (Zhang & Chen 2021, Table 1 X line), 5 runs, in the laser's
// own channels (lin_um, str_h_um, str_v_um, yaw_urad, pitch_urad, roll_urad) so that reading it
// exercises the Table 2 sign conversions and the eq. (1) straightness line removal.
//
//   weilgen_exp_make_line6d_data [PATH]     (default: print to stdout)
//
// The true ISO 230-1 profiles (x in mm, travel [0, 500]; s = (x - 250) / 250):
//   E_XX = 3.0 sin(2πx/250 + 0.5) + 1.5 sin(2πx/(500/3) + 2.0) + 1.0 cos(2πx/500 + 0.3)
//          + 0.002 x                                   µm   (wave-shaped ballscrew lead error)
//   E_YX = 2.5 (1 - s²) + 0.4 sin(2πx/100)                                  µm
//   E_ZX = -3.0 s² + 1.0 s³                                                  µm
//   E_AX = 4.0 sin(2πx/500 + 0.2) + 0.01 x                                   µrad (roll)
//   E_BX = 6.0 sin(2πx/250 + 1.0) + 2.5 cos(2πx/125) - 3.0 s²                 µrad (pitch)
//   E_CX = 5.0 s + 2.0 sin(2πx/(500/3))                                      µrad (yaw)
// What the laser reports (run c = 1..5; Table 2: yaw = -E_CX, pitch = -E_BX, the rest +):
//   lin   = E_XX - E_XX(0) + 0.15 (c - 1)       (zeroed at the start of run 1; slow thermal
//                                                drift between runs)
//   str_h = E_YX + 2.0 + 0.030 x                 (beam misaligned by 30 µrad in the XY plane)
//   str_v = E_ZX - 1.5 - 0.020 x                 (and by 20 µrad in XZ)
//   yaw   = -E_CX + 25,  pitch = -E_BX - 12,  roll = E_AX + 8   (the head's angular zero)
// plus independent normal noise: σ = 0.25 µm (lin), 0.30 µm (straightness), 0.6 µrad (angles).
// Noise: Box-Muller on std::mt19937_64 (seed 20210510), so the file is the same on any platform.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr std::uint64_t kSeed = 20210510;

class Normal {
 public:
  explicit Normal(std::uint64_t seed) : rng_(seed) {}
  double operator()(double sigma) {
    if (has_spare_) {
      has_spare_ = false;
      return sigma * spare_;
    }
    const double u1 = uniform(), u2 = uniform();
    const double r = std::sqrt(-2 * std::log(u1));
    spare_ = r * std::sin(2 * kPi * u2);
    has_spare_ = true;
    return sigma * r * std::cos(2 * kPi * u2);
  }

 private:
  double uniform() {  // (0, 1]
    return (static_cast<double>(rng_() >> 11) + 1) * 0x1.0p-53;
  }
  std::mt19937_64 rng_;
  double spare_ = 0;
  bool has_spare_ = false;
};

double w(double x, double period) { return 2 * kPi * x / period; }

}  // namespace

int main(int argc, char** argv) {
  if (argc > 2 || (argc == 2 && std::string(argv[1]).rfind("-", 0) == 0)) {
    std::fprintf(stderr, "usage: weilgen_exp_make_line6d_data [PATH]\n");
    return 2;
  }
  FILE* out = argc == 2 ? std::fopen(argv[1], "w") : stdout;
  if (!out) {
    std::perror(argv[1]);
    return 1;
  }
  std::fprintf(out,
               "# Synthetic 6D laser line measurement of the X axis (laser channels, Table 2 of\n"
               "# the 6D-laser seed). Written by bench/experiments/make_line6d_data.cpp, seed "
               "%llu;\n"
               "# the true profiles and the laser model are documented there.\n"
               "# format: line6d\n"
               "# axis: X\n"
               "# instrument: synthetic 6D laser interferometer, 10 mm steps, 5 runs\n"
               "X,cycle,lin_um,str_h_um,str_v_um,yaw_urad,pitch_urad,roll_urad\n",
               static_cast<unsigned long long>(kSeed));
  Normal noise(kSeed);
  const double exx0 = 3.0 * std::sin(0.5) + 1.5 * std::sin(2.0) + 1.0 * std::cos(0.3);  // E_XX(0)
  for (int c = 1; c <= 5; ++c) {
    for (int i = 0; i <= 50; ++i) {
      const double x = 10.0 * i;
      const double s = (x - 250) / 250;
      const double exx = 3.0 * std::sin(w(x, 250) + 0.5) + 1.5 * std::sin(w(x, 500.0 / 3) + 2.0) +
                         1.0 * std::cos(w(x, 500) + 0.3) + 0.002 * x;
      const double eyx = 2.5 * (1 - s * s) + 0.4 * std::sin(w(x, 100));
      const double ezx = -3.0 * s * s + 1.0 * s * s * s;
      const double eax = 4.0 * std::sin(w(x, 500) + 0.2) + 0.01 * x;
      const double ebx = 6.0 * std::sin(w(x, 250) + 1.0) + 2.5 * std::cos(w(x, 125)) - 3.0 * s * s;
      const double ecx = 5.0 * s + 2.0 * std::sin(w(x, 500.0 / 3));
      const double lin = exx - exx0 + 0.15 * (c - 1) + noise(0.25);
      const double str_h = eyx + 2.0 + 0.030 * x + noise(0.30);
      const double str_v = ezx - 1.5 - 0.020 * x + noise(0.30);
      const double yaw = -ecx + 25 + noise(0.6);
      const double pitch = -ebx - 12 + noise(0.6);
      const double roll = eax + 8 + noise(0.6);
      std::fprintf(out, "%g,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f\n", x, c, lin, str_h, str_v, yaw,
                   pitch, roll);
    }
  }
  if (out != stdout && std::fclose(out) != 0) {
    std::perror(argv[1]);
    return 1;
  }
  return 0;
}
