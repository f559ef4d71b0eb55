// A controller's compensation cycle on Zhang & Chen 2021's ballbar circle (section 4): every
// point of the commanded path goes through Compensate with the identified errors, as a real-time
// controller would call it once per interpolation cycle. The program prints the circularity of
// the predicted actual path (ISO 230-4: the range of the radial deviation about the least-squares
// centre) before and after compensation.
//
// Only two project headers, both generated: the model (weilgen generate) and the identified
// error parameters (weilgen identify --emit-params). No allocation in the cycle.
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstring>

#include "vmc_3axis.hpp"
#include "vmc_3axis_params.hpp"

namespace model = weilgen_models::vmc_3axis;
namespace identified = weilgen_models::vmc_3axis_params;

namespace {

constexpr bool same_text(const char* a, const char* b) {
  return *a == *b && (*a == '\0' || same_text(a + 1, b + 1));
}
static_assert(same_text(model::kMachineName, identified::kMachineName),
              "the parameters were identified for another machine");
static_assert(model::kNumAxes == identified::kNumAxes &&
                  model::kNumErrors == identified::kNumErrors &&
                  model::kNumParams == identified::kNumParams,
              "the parameters do not match the model header");

using Axes = std::array<double, model::kNumAxes>;
using Errors = std::array<double, model::kNumErrors>;

constexpr std::size_t kPoints = 360;
// Zhang & Chen 2021's ballbar test: centre (343.507, -285.090, -286.430) mm, radius 100 mm, XY
// plane.
constexpr double kCentreX = 343.507, kCentreY = -285.090, kCentreZ = -286.430;
constexpr double kRadiusMm = 100.0;
constexpr double kPi = 3.14159265358979323846;

// Index of an axis in kAxes (the model's axis order is its chain order, here Y, X, Z).
constexpr std::size_t axis_index(const char* name) {
  for (std::size_t i = 0; i < model::kNumAxes; ++i)
    if (same_text(model::kAxes[i].name, name)) return i;
  return model::kNumAxes;
}
constexpr std::size_t kX = axis_index("X"), kY = axis_index("Y"), kZ = axis_index("Z");
static_assert(kX < model::kNumAxes && kY < model::kNumAxes && kZ < model::kNumAxes,
              "the model has no X, Y or Z axis");

// The errors at a pose, from the identified parameters: what Compensate's errors_at calls.
void errors_at(const Axes& axes, Errors* errors) { identified::Errors(axes, errors); }

// The predicted tool point (workpiece frame, mm) when `command` is sent: nominal pose plus the
// model's deviation with the errors at the command.
std::array<double, 3> predicted_point(const Axes& command) {
  const std::array<double, model::kNumParams>& params = identified::kParams;
  std::array<double, 3> nominal{}, deviation{};
  Errors errors{};
  errors_at(command, &errors);
  model::NominalPose(command, params, &nominal);
  model::Deviation(command, errors, params, &deviation);
  return {nominal[0] + deviation[0], nominal[1] + deviation[1], nominal[2] + deviation[2]};
}

struct Circularity {
  double range_um;                  // max - min radial deviation about the least-squares centre
  double centre_x_um, centre_y_um;  // least-squares centre minus the nominal centre
  double radius_um;                 // least-squares radius minus the nominal radius
};

// Least-squares circle (Kasa: x^2 + y^2 = 2ax + 2by + c, linear in a, b, c) through points given
// relative to the nominal centre, then the range of the radial deviations about its centre.
Circularity circularity(const std::array<std::array<double, 2>, kPoints>& p) {
  double m[3][4] = {};  // normal equations [A^T A | A^T r]
  for (const auto& q : p) {
    const double row[3] = {2 * q[0], 2 * q[1], 1.0};
    const double rhs = q[0] * q[0] + q[1] * q[1];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) m[i][j] += row[i] * row[j];
      m[i][3] += row[i] * rhs;
    }
  }
  for (int k = 0; k < 3; ++k)  // Gauss-Jordan; the matrix is well conditioned for a full circle
    for (int i = 0; i < 3; ++i) {
      if (i == k) continue;
      const double f = m[i][k] / m[k][k];
      for (int j = k; j < 4; ++j) m[i][j] -= f * m[k][j];
    }
  const double a = m[0][3] / m[0][0], b = m[1][3] / m[1][1], c = m[2][3] / m[2][2];
  double lo = 1e300, hi = -1e300;
  for (const auto& q : p) {
    const double r = std::hypot(q[0] - a, q[1] - b);
    lo = r < lo ? r : lo;
    hi = r > hi ? r : hi;
  }
  return {(hi - lo) * 1e3, a * 1e3, b * 1e3, (std::sqrt(c + a * a + b * b) - kRadiusMm) * 1e3};
}

// Below the printed resolution, 0 (not "-0.000").
double shown(double um) { return std::fabs(um) < 5e-4 ? 0.0 : um; }

void print_row(const char* label, const Circularity& c) {
  std::printf("%-21s  %11.3f  %15.3f  %15.3f  %6.3f\n", label, shown(c.range_um),
              shown(c.centre_x_um), shown(c.centre_y_um), shown(c.radius_um));
}

}  // namespace

// --time: the cost of one compensation cycle, best of 5 runs of 1000 circles (ns per call).
int time_cycle(const std::array<Axes, kPoints>& targets) {
  const std::array<double, model::kNumParams>& params = identified::kParams;
  constexpr int kCircles = 1000;
  double best_ns = 1e300, sink = 0;
  for (int run = 0; run < 5; ++run) {
    const auto start = std::chrono::steady_clock::now();
    for (int circle = 0; circle < kCircles; ++circle)
      for (const Axes& target : targets) {
        Axes command{};
        sink += model::Compensate(target, errors_at, params, &command) + command[0];
      }
    const std::chrono::duration<double, std::nano> took = std::chrono::steady_clock::now() - start;
    const double ns = took.count() / (kCircles * static_cast<double>(kPoints));
    best_ns = ns < best_ns ? ns : best_ns;
  }
  std::printf("Compensate: %.0f ns per call (best of 5 runs of %d circles; checksum %.6g)\n",
              best_ns, kCircles, sink);
  return 0;
}

int main(int argc, char** argv) {
  const std::array<double, model::kNumParams>& params = identified::kParams;
  Axes centre{};
  centre[kX] = kCentreX;
  centre[kY] = kCentreY;
  centre[kZ] = kCentreZ;
  std::array<double, 3> nominal_centre{};
  model::NominalPose(centre, params, &nominal_centre);

  std::array<Axes, kPoints> targets{};
  for (std::size_t i = 0; i < kPoints; ++i) {
    const double angle = 2 * kPi * static_cast<double>(i) / static_cast<double>(kPoints);
    targets[i] = centre;
    targets[i][kX] += kRadiusMm * std::cos(angle);
    targets[i][kY] += kRadiusMm * std::sin(angle);
  }
  if (argc == 2 && std::strcmp(argv[1], "--time") == 0) return time_cycle(targets);
  if (argc != 1) {
    std::fprintf(stderr, "usage: %s [--time]\n", argv[0]);
    return 2;
  }

  std::array<std::array<double, 2>, kPoints> before{}, after{};
  int max_iterations_used = 0, failures = 0;
  double max_correction_um = 0;
  for (std::size_t i = 0; i < kPoints; ++i) {
    const Axes& target = targets[i];

    // The controller's cycle: one call, bounded iterations, no allocation.
    Axes command{};
    const int iterations = model::Compensate(target, errors_at, params, &command);
    if (iterations < 0) ++failures;  // command is the target then: uncompensated
    if (iterations > max_iterations_used) max_iterations_used = iterations;
    for (std::size_t k = 0; k < model::kNumAxes; ++k) {
      const double d = std::fabs(command[k] - target[k]) * 1e3;
      max_correction_um = d > max_correction_um ? d : max_correction_um;
    }

    const std::array<double, 3> p = predicted_point(target), q = predicted_point(command);
    before[i] = {p[0] - nominal_centre[0], p[1] - nominal_centre[1]};
    after[i] = {q[0] - nominal_centre[0], q[1] - nominal_centre[1]};
  }

  const Circularity b = circularity(before), a = circularity(after);
  std::printf(
      "%s: circle in the XY plane, centre X=%.3f Y=%.3f Z=%.3f mm, radius %.0f mm, %zu "
      "points\n",
      model::kMachineName, kCentreX, kCentreY, kCentreZ, kRadiusMm, kPoints);
  std::printf("predicted by the model with the identified errors (um)\n");
  std::printf("                       circularity  centre offset x  centre offset y  radius\n");
  print_row("before compensation", b);
  print_row("after compensation", a);
  std::printf(
      "Compensate: %zu calls, at most %d iterations, %d not converged, largest axis "
      "correction %.3f um\n",
      kPoints, max_iterations_used, failures, max_correction_um);
  return failures == 0 ? 0 : 1;
}
