// Compiles templates/compensate.hpp on its own against a stand-in model (two prismatic axes,
// a zero offset and a scale error of the first axis) with a controller's strict flags, and
// checks that Compensate finds the command the stand-in's closed form gives. CTest
// compensate_template; the generated headers' own Compensate is tested in test_compensation.cpp.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>

namespace standin {

inline constexpr std::size_t kNumAxes = 2;
inline constexpr std::size_t kNumErrors = 2;  // e0: offset of axis 0 (mm), e1: its scale error
inline constexpr std::size_t kNumParams = 1;

template <typename Scalar>
void NominalPose(const std::array<Scalar, kNumAxes>& q, const std::array<Scalar, kNumParams>&,
                 std::array<Scalar, 3>* const position, std::array<Scalar, 9>* const rotation) {
  if (position) *position = {q[0], q[1], Scalar(0)};
  if (rotation)
    *rotation = {Scalar(1), Scalar(0), Scalar(0), Scalar(0), Scalar(1),
                 Scalar(0), Scalar(0), Scalar(0), Scalar(1)};
}

template <typename Scalar>
void NominalJacobian(const std::array<Scalar, kNumAxes>&, const std::array<Scalar, kNumParams>&,
                     std::array<Scalar, 6 * kNumAxes>* const jacobian) {
  *jacobian = {};
  (*jacobian)[0 * kNumAxes + 0] = Scalar(1);
  (*jacobian)[1 * kNumAxes + 1] = Scalar(1);
}

template <typename Scalar>
void Deviation(const std::array<Scalar, kNumAxes>& q, const std::array<Scalar, kNumErrors>& e,
               const std::array<Scalar, kNumParams>&, std::array<Scalar, 3>* const position,
               std::array<Scalar, 3>* const orientation) {
  if (position) *position = {e[0] + e[1] * q[0], Scalar(0), Scalar(0)};
  if (orientation) *orientation = {};
}

#define WEILGEN_TEMPLATE_ORIENTATION false
#include "compensate.hpp"
#undef WEILGEN_TEMPLATE_ORIENTATION

}  // namespace standin

int main() {
  const std::array<double, 2> target = {250.0, -40.0};
  const std::array<double, 2> errors = {0.012, 2e-5};  // 12 um offset, 20 um/m scale
  std::array<double, 2> command{};
  const int iterations = standin::Compensate(target, errors, {0.0}, &command);
  // q0 + e0 + e1 q0 = t0: q0 = (t0 - e0) / (1 + e1); q1 = t1.
  const double q0 = (target[0] - errors[0]) / (1 + errors[1]);
  const bool ok = iterations >= 1 && std::fabs(command[0] - q0) < 1e-9 &&
                  std::fabs(command[1] - target[1]) < 1e-12;
  std::printf("Compensate: %d iterations, command %.12f %.12f (expected %.12f %.12f): %s\n",
              iterations, command[0], command[1], q0, target[1], ok ? "ok" : "WRONG");
  return ok ? 0 : 1;
}
