// A stand-in for the identified parameters of the stand-in model (`weilgen identify
// --emit-params` writes such a header): constant errors, so that templates/hal_errors.cpp
// compiles on its own.
#pragma once

#include <array>
#include <cstddef>

namespace weilgen_models {
namespace standin_params {

inline constexpr const char* kModelKey = "0000000000000000";
inline constexpr std::size_t kNumAxes = 2;
inline constexpr std::size_t kNumErrors = 2;
inline constexpr std::size_t kNumParams = 1;
inline constexpr std::array<double, kNumParams> kParams = {{0.0}};

template <typename Scalar>
void Errors(const std::array<Scalar, kNumAxes>&, std::array<Scalar, kNumErrors>* errors) {
  *errors = {Scalar(0.012), Scalar(2e-5)};
}

}  // namespace standin_params
}  // namespace weilgen_models
