// Writes examples/data/ballbar_xy.csv: a synthetic ballbar test (ISO 230-4) of the vmc_3axis
// machine in the XY plane at Zhang & Chen 2021's circle (section 4: centre (343.507, -285.090,
// -286.430), R = 100 mm), one counter-clockwise and one clockwise run, 1° steps.
//
//   build-ballbar/bench/experiments/weilgen_exp_make_ballbar_data examples/data/ballbar_xy.csv
//
// The errors (x, y in mm; s = (x - 250) / 250; µm and µrad):
//   E_XX  = 1.5 sin(2πx/125) + 0.008 x       ballscrew wave and an 8 µm/m scale error
//   E_YY  = 1.0 cos(2πy/100) - 0.005 y       (y < 0 on this machine)
//   E_XY  = 1.2 sin(2πy/400)                 straightness of Y along x
//   E_YX  = 2.0 (1 - s²)                     straightness of X along y
//   E_CX  = 5.0 s                            yaw of X
//   E_CY  = 3.0 sin(2πy/400)                 yaw of Y
//   E_C0Y = 12                               squareness of Y to X
// all others 0. The deviation is the generated model's (generated/vmc_3axis.hpp, order 1);
// written independently of src/measure/ballbar.cpp so that the test comparing the two checks both.
// The table carries X and Y, so the tool moves relative to the workpiece by (-X, -Y, +Z): the
// nominal vector from the table ball to the tool ball is v = -R (cos θ, sin θ, 0), and
//   dr = |v + d| - R                       (exact, µm)
//        + 3.0 cos θ - 1.5 sin θ           (the table ball set 3.0 µm off along +X, -1.5 along +Y)
//        - 0.8                             (the bar's calibrated length 0.8 µm long)
//        + N(0, 0.2²)                      (noise)
// Noise: Box-Muller on std::mt19937_64 (seed 20210510), so the file is the same on any platform.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string_view>

#include "bench/experiments/normal_deviates.hpp"
#include "vmc_3axis.hpp"

namespace {

namespace vmc = weilgen_models::vmc_3axis;

constexpr double kPi = 3.14159265358979323846;
constexpr double kCx = 343.507, kCy = -285.090, kCz = -286.430, kR = 100;
constexpr double kOffsetX = 3.0, kOffsetY = -1.5, kLength = -0.8, kSigma = 0.2;  // µm

using Normal = weilgen::bench::NormalDeviates;  // bench/experiments/normal_deviates.hpp

// The errors at (x, y) in base units (mm, rad), kErrors order.
std::array<double, vmc::kNumErrors> errors_at(double x, double y) {
  std::array<double, vmc::kNumErrors> e{};
  const double s = (x - 250) / 250;
  auto set = [&](const char* name, double value, double to_base) {
    for (std::size_t i = 0; i < vmc::kNumErrors; ++i) {
      if (std::string_view(vmc::kErrors[i].name) == name) e[i] = value * to_base;
    }
  };
  set("E_XX", 1.5 * std::sin(2 * kPi * x / 125) + 0.008 * x, 1e-3);
  set("E_YY", 1.0 * std::cos(2 * kPi * y / 100) - 0.005 * y, 1e-3);
  set("E_XY", 1.2 * std::sin(2 * kPi * y / 400), 1e-3);
  set("E_YX", 2.0 * (1 - s * s), 1e-3);
  set("E_CX", 5.0 * s, 1e-6);
  set("E_CY", 3.0 * std::sin(2 * kPi * y / 400), 1e-6);
  set("E_C0Y", 12.0, 1e-6);
  return e;
}

// Exact radial deviation (µm) at θ (deg).
double radial_um(double theta_deg) {
  const double t = theta_deg * kPi / 180;
  const double x = kCx + kR * std::cos(t), y = kCy + kR * std::sin(t);
  std::array<double, vmc::kNumAxes> axes{};
  for (std::size_t i = 0; i < vmc::kNumAxes; ++i) {
    const std::string_view name = vmc::kAxes[i].name;
    axes[i] = name == "X" ? x : name == "Y" ? y : kCz;
  }
  std::array<double, 3> d{};
  vmc::Deviation(axes, errors_at(x, y), std::array<double, vmc::kNumParams>{0.0}, &d);
  const double vx = -kR * std::cos(t) + d[0], vy = -kR * std::sin(t) + d[1], vz = d[2];
  return 1000 * (std::sqrt(vx * vx + vy * vy + vz * vz) - kR);
}

}  // namespace

int main(int argc, char** argv) {
  std::FILE* out = argc > 1 ? std::fopen(argv[1], "w") : stdout;
  if (!out) {
    std::fprintf(stderr, "cannot write %s\n", argv[1]);
    return 1;
  }
  Normal noise(20210510);
  std::fprintf(
      out,
      "# Synthetic ballbar test of vmc_3axis (NOT measured): written by\n"
      "# bench/experiments/make_ballbar_data.cpp from a known error set (E_C0Y = 12 urad,\n"
      "# scale, wave, straightness and yaw errors of X and Y; see the program) plus a\n"
      "# 3.0/-1.5 um set-up offset, a -0.8 um bar length error and N(0, 0.2^2) noise.\n"
      "# machine: vmc_3axis\n"
      "# plane: XY\n"
      "# centre: X=343.507, Y=-285.090, Z=-286.430\n"
      "# radius: 100 mm\n"
      "# feed: ccw\n"
      "# feedrate: 200 mm/min\n"
      "angle_deg,dr_um,dir,cycle\n");
  for (int dir : {1, -1}) {
    for (int k = 0; k < 360; ++k) {
      const int angle = dir > 0 ? k : (360 - k) % 360;
      const double t = angle * kPi / 180;
      const double dr = radial_um(angle) + kOffsetX * std::cos(t) + kOffsetY * std::sin(t) +
                        kLength + noise(kSigma);
      std::fprintf(out, "%d,%.3f,%d,1\n", angle, dr, dir);
    }
  }
  if (out != stdout) std::fclose(out);
  return 0;
}
