// Compiles templates/compensate.hpp on its own against the stand-in model templates/standin.hpp
// (two prismatic axes, a zero offset and a scale error of the first axis) with a controller's
// strict flags, and checks that Compensate finds the command the stand-in's closed form gives.
// CTest compensate_template; the generated headers' own Compensate is tested in
// test_compensation.cpp.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>

#include "standin.hpp"

namespace standin = weilgen_models::standin;

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
