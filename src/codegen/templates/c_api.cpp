// The implementation of the C API that `weilgen generate --c-api` writes beside a model header
// (<name>_c.cpp), as a real C++ file: the generator (src/codegen/emit_c_api.cpp) emits everything
// after the marker line with the stand-in names replaced by the model's, and the block between
// the check markers replaced by static_asserts tying every C enumerator to the C++ header's
// named index. It is compiled on its own against the stand-in model templates/standin.hpp with
// -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Werror -fno-exceptions -fno-rtti by CTest
// c_api_template.
// clang-format off: the text below is emitted byte for byte (the generated files are golden).
// ---- weilgen template: emitted from the next line ----
// Each function copies its arguments into the std::arrays of the C++ header, calls its template
// for double and copies the results out: the results are bit for bit the C++ header's. Nothing
// here allocates or throws: compiled with -fno-exceptions it needs no C++ runtime (only libm).
#include "standin_c.h"

#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>

#include "standin.hpp"

namespace {

namespace model = weilgen_models::standin;

static_assert(STANDIN_NUM_AXES == model::kNumAxes, "axes: the C header does not match the model");
static_assert(STANDIN_NUM_ERRORS == model::kNumErrors, "errors: the C header does not match the model");
static_assert(STANDIN_NUM_PARAMS == model::kNumParams, "params: the C header does not match the model");
static_assert(STANDIN_NUM_OUTPUTS == model::kNumOutputs, "outputs: the C header does not match the model");
static_assert(STANDIN_ORDER == model::kOrder, "order: the C header does not match the model");
// ---- weilgen template: checks begin ----
static_assert(STANDIN_AXIS_X == model::axis::X, "STANDIN_AXIS_X");
static_assert(STANDIN_AXIS_Y == model::axis::Y, "STANDIN_AXIS_Y");
static_assert(STANDIN_ERROR_E_X0 == model::error::E_X0, "STANDIN_ERROR_E_X0");
static_assert(STANDIN_ERROR_E_XX == model::error::E_XX, "STANDIN_ERROR_E_XX");
static_assert(STANDIN_PARAM_TOOL_LENGTH == model::param::tool_length, "STANDIN_PARAM_TOOL_LENGTH");
// ---- weilgen template: checks end ----

template <std::size_t N>
std::array<double, N> load(const double* from) noexcept {
  std::array<double, N> a{};
  if constexpr (N > 0) std::memcpy(a.data(), from, sizeof(double) * N);
  return a;
}

template <std::size_t N>
void store(const std::array<double, N>& a, double* to) noexcept {
  if constexpr (N > 0) std::memcpy(to, a.data(), sizeof(double) * N);
}

// params may be NULL only when the model has none.
bool params_ok(const double* params) noexcept { return params != nullptr || model::kNumParams == 0; }

bool iteration_args_ok(int max_iterations, double tolerance_mm) noexcept {
  return max_iterations >= 1 && max_iterations <= STANDIN_MAX_ITERATIONS && tolerance_mm > 0 &&
         std::isfinite(tolerance_mm);
}

int status_of(int iterations, int* out) noexcept {
  if (out != nullptr) *out = iterations < 0 ? 0 : iterations;
  return iterations < 0 ? STANDIN_STATUS_NOT_COMPENSATED : STANDIN_STATUS_OK;
}

}  // namespace

extern "C" {

int standin_deviation(const double* axes, const double* errors, const double* params,
                      double* position, double* orientation) noexcept {
  if (axes == nullptr || errors == nullptr || !params_ok(params)) return STANDIN_STATUS_BAD_ARGUMENT;
  std::array<double, 3> p{}, o{};
  model::Deviation(load<model::kNumAxes>(axes), load<model::kNumErrors>(errors),
                   load<model::kNumParams>(params), position != nullptr ? &p : nullptr,
                   orientation != nullptr ? &o : nullptr);
  if (position != nullptr) store(p, position);
  if (orientation != nullptr) store(o, orientation);
  return STANDIN_STATUS_OK;
}

int standin_coefficients(const double* axes, const double* params, double* position_coeff,
                         double* orientation_coeff) noexcept {
  if (axes == nullptr || !params_ok(params)) return STANDIN_STATUS_BAD_ARGUMENT;
  std::array<double, 3 * model::kNumErrors> p{}, o{};
  model::Coefficients(load<model::kNumAxes>(axes), load<model::kNumParams>(params),
                      position_coeff != nullptr ? &p : nullptr,
                      orientation_coeff != nullptr ? &o : nullptr);
  if (position_coeff != nullptr) store(p, position_coeff);
  if (orientation_coeff != nullptr) store(o, orientation_coeff);
  return STANDIN_STATUS_OK;
}

int standin_deviation_and_coefficients(const double* axes, const double* errors,
                                       const double* params, double* position, double* orientation,
                                       double* position_coeff, double* orientation_coeff) noexcept {
  if (axes == nullptr || errors == nullptr || !params_ok(params)) return STANDIN_STATUS_BAD_ARGUMENT;
  std::array<double, 3> p{}, o{};
  std::array<double, 3 * model::kNumErrors> pc{}, oc{};
  model::DeviationAndCoefficients(load<model::kNumAxes>(axes), load<model::kNumErrors>(errors),
                                  load<model::kNumParams>(params), position != nullptr ? &p : nullptr,
                                  orientation != nullptr ? &o : nullptr,
                                  position_coeff != nullptr ? &pc : nullptr,
                                  orientation_coeff != nullptr ? &oc : nullptr);
  if (position != nullptr) store(p, position);
  if (orientation != nullptr) store(o, orientation);
  if (position_coeff != nullptr) store(pc, position_coeff);
  if (orientation_coeff != nullptr) store(oc, orientation_coeff);
  return STANDIN_STATUS_OK;
}

int standin_nominal_pose(const double* axes, const double* params, double* position,
                         double* rotation) noexcept {
  if (axes == nullptr || !params_ok(params)) return STANDIN_STATUS_BAD_ARGUMENT;
  std::array<double, 3> p{};
  std::array<double, 9> r{};
  model::NominalPose(load<model::kNumAxes>(axes), load<model::kNumParams>(params),
                     position != nullptr ? &p : nullptr, rotation != nullptr ? &r : nullptr);
  if (position != nullptr) store(p, position);
  if (rotation != nullptr) store(r, rotation);
  return STANDIN_STATUS_OK;
}

int standin_nominal_jacobian(const double* axes, const double* params, double* jacobian) noexcept {
  if (axes == nullptr || !params_ok(params) || jacobian == nullptr) return STANDIN_STATUS_BAD_ARGUMENT;
  std::array<double, 6 * model::kNumAxes> j{};
  model::NominalJacobian(load<model::kNumAxes>(axes), load<model::kNumParams>(params), &j);
  store(j, jacobian);
  return STANDIN_STATUS_OK;
}

int standin_compensate(const double* target, const double* errors, const double* params,
                       double* command, int max_iterations, double tolerance_mm,
                       int* iterations) noexcept {
  if (target == nullptr || errors == nullptr || !params_ok(params) || command == nullptr ||
      !iteration_args_ok(max_iterations, tolerance_mm))
    return STANDIN_STATUS_BAD_ARGUMENT;
  std::array<double, model::kNumAxes> c{};
  const int used = model::Compensate(load<model::kNumAxes>(target), load<model::kNumErrors>(errors),
                                     load<model::kNumParams>(params), &c, max_iterations, tolerance_mm);
  store(c, command);
  return status_of(used, iterations);
}

int standin_compensate_at(const double* target, standin_errors_fn errors_at, void* context,
                          const double* params, double* command, int max_iterations,
                          double tolerance_mm, int* iterations) noexcept {
  if (target == nullptr || errors_at == nullptr || !params_ok(params) || command == nullptr ||
      !iteration_args_ok(max_iterations, tolerance_mm))
    return STANDIN_STATUS_BAD_ARGUMENT;
  const auto errors = [errors_at, context](const std::array<double, model::kNumAxes>& axes,
                                           std::array<double, model::kNumErrors>* out) {
    errors_at(axes.data(), out->data(), context);
  };
  std::array<double, model::kNumAxes> c{};
  const int used = model::Compensate(load<model::kNumAxes>(target), errors,
                                     load<model::kNumParams>(params), &c, max_iterations, tolerance_mm);
  store(c, command);
  return status_of(used, iterations);
}

const char* standin_axis_name(int axis) noexcept {
  return axis >= 0 && static_cast<std::size_t>(axis) < model::kNumAxes
             ? model::kAxes[static_cast<std::size_t>(axis)].name : nullptr;
}

const char* standin_axis_unit(int axis) noexcept {
  return axis >= 0 && static_cast<std::size_t>(axis) < model::kNumAxes
             ? model::kAxes[static_cast<std::size_t>(axis)].unit : nullptr;
}

const char* standin_error_name(int error) noexcept {
  return error >= 0 && static_cast<std::size_t>(error) < model::kNumErrors
             ? model::kErrors[static_cast<std::size_t>(error)].name : nullptr;
}

const char* standin_param_name(int param) noexcept {
  if (param < 0 || static_cast<std::size_t>(param) >= model::kNumParams) return nullptr;
  return model::kParams[static_cast<std::size_t>(param)].name;
}

double standin_param_default(int param) noexcept {
  if (param < 0 || static_cast<std::size_t>(param) >= model::kNumParams) return 0.0;
  return model::kParams[static_cast<std::size_t>(param)].default_value;
}

}  // extern "C"
