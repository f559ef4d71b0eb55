// A stand-in for a generated model header (weilgen_models::standin), so that the C API templates
// (c_api.h, c_api.cpp) and the HAL component template compile and run on their own: two
// prismatic axes X, Y, an offset E_X0 (mm) and a scale error E_XX (mm per mm) of X, one
// parameter. The same declarations as a generated header, with closed forms a check can solve:
// the position deviation is (E_X0 + E_XX * X, 0, 0). Used by c_api_check.c and hal_check.sh.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

namespace weilgen_models {
namespace standin {

inline constexpr const char* kMachineName = "standin";
inline constexpr int kOrder = 1;
inline constexpr const char* kModelKey = "0000000000000000";
inline constexpr std::size_t kNumAxes = 2;
inline constexpr std::size_t kNumErrors = 2;
inline constexpr std::size_t kNumParams = 1;
inline constexpr std::size_t kNumOutputs = 6;

struct AxisInfo {
  const char* name;
  const char* unit;
};
struct ErrorInfo {
  const char* name;
};
struct ParamInfo {
  const char* name;
  const char* unit;
  double default_value;
};
inline constexpr std::array<AxisInfo, kNumAxes> kAxes = {{{"X", "mm"}, {"Y", "mm"}}};
inline constexpr std::array<ErrorInfo, kNumErrors> kErrors = {{{"E_X0"}, {"E_XX"}}};
inline constexpr std::array<ParamInfo, kNumParams> kParams = {{{"tool_length", "mm", 0.0}}};

namespace axis {
inline constexpr std::size_t X = 0;
inline constexpr std::size_t Y = 1;
}  // namespace axis
namespace error {
inline constexpr std::size_t E_X0 = 0;
inline constexpr std::size_t E_XX = 1;
}  // namespace error
namespace param {
inline constexpr std::size_t tool_length = 0;
}  // namespace param

template <typename Scalar>
void Deviation(const std::array<Scalar, kNumAxes>& q, const std::array<Scalar, kNumErrors>& e,
               const std::array<Scalar, kNumParams>&, std::array<Scalar, 3>* const position,
               std::array<Scalar, 3>* const orientation = nullptr) {
  if (position) *position = {e[0] + e[1] * q[0], Scalar(0), Scalar(0)};
  if (orientation) *orientation = {};
}

template <typename Scalar>
void Coefficients(const std::array<Scalar, kNumAxes>& q, const std::array<Scalar, kNumParams>&,
                  std::array<Scalar, 3 * kNumErrors>* const position_coeff,
                  std::array<Scalar, 3 * kNumErrors>* const orientation_coeff = nullptr) {
  if (position_coeff)
    *position_coeff = {Scalar(1), q[0], Scalar(0), Scalar(0), Scalar(0), Scalar(0)};
  if (orientation_coeff) *orientation_coeff = {};
}

template <typename Scalar>
void DeviationAndCoefficients(
    const std::array<Scalar, kNumAxes>& q, const std::array<Scalar, kNumErrors>& e,
    const std::array<Scalar, kNumParams>& p, std::array<Scalar, 3>* const position,
    std::array<Scalar, 3>* const orientation,
    std::array<Scalar, 3 * kNumErrors>* const position_coeff,
    std::array<Scalar, 3 * kNumErrors>* const orientation_coeff = nullptr) {
  Deviation(q, e, p, position, orientation);
  Coefficients(q, p, position_coeff, orientation_coeff);
}

template <typename Scalar>
void NominalPose(const std::array<Scalar, kNumAxes>& q, const std::array<Scalar, kNumParams>&,
                 std::array<Scalar, 3>* const position,
                 std::array<Scalar, 9>* const rotation = nullptr) {
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

#define WEILGEN_TEMPLATE_ORIENTATION false
#include "compensate.hpp"
#undef WEILGEN_TEMPLATE_ORIENTATION

}  // namespace standin
}  // namespace weilgen_models
