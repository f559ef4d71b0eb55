// The C++ reference of the LinuxCNC component test (run_component_test.py): the model header's
// Compensate, with the same errors and parameters as the component, for targets read from stdin.
// Built per machine by tests/CMakeLists.txt with WEILGEN_MODEL (the namespace) and
// WEILGEN_MODEL_HEADER and, when the component builds identified errors in, WEILGEN_PARAMS (the
// identify --emit-params namespace) and WEILGEN_PARAMS_HEADER.
//
// stdin: the model parameters (kNumParams numbers), the constant errors added to the identified
// ones (kNumErrors numbers, mm / rad), then targets of kNumAxes numbers until the end.
// stdout: per target "iterations c_1 ... c_n" (iterations -1: not compensated), %.17g.
#include <array>
#include <cstdio>
#include <iostream>

#include WEILGEN_MODEL_HEADER
#ifdef WEILGEN_PARAMS
#include WEILGEN_PARAMS_HEADER
#endif

namespace model = weilgen_models::WEILGEN_MODEL;

int main() {
  std::array<double, model::kNumParams> params{};
  std::array<double, model::kNumErrors> extra{};
  for (double& p : params) std::cin >> p;
  for (double& e : extra) std::cin >> e;
  if (!std::cin) return 2;
  const auto errors_at = [&](const std::array<double, model::kNumAxes>& axes,
                             std::array<double, model::kNumErrors>* errors) {
    errors->fill(0.0);
#ifdef WEILGEN_PARAMS
    weilgen_models::WEILGEN_PARAMS::Errors(axes, errors);
#else
    (void)axes;
#endif
    for (std::size_t i = 0; i < errors->size(); ++i) (*errors)[i] += extra[i];
  };
  std::array<double, model::kNumAxes> target{};
  while (true) {
    for (double& t : target) std::cin >> t;
    if (!std::cin) break;
    std::array<double, model::kNumAxes> command{};
    const int iterations = model::Compensate(target, errors_at, params, &command, 10, 1e-9);
    std::printf("%d", iterations);
    for (double c : command) std::printf(" %.17g", c);
    std::printf("\n");
  }
  return 0;
}
