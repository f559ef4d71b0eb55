// The plain-C interface of a compiled model: what a built-in model and a model compiled at run
// time (a shared object loaded with dlopen) both expose. Self-contained on purpose: the run-time
// compiler is handed this file's text together with the generated header, nothing else.
//
// WEILGEN_DEFINE_MODEL_ABI(ns, var) defines `var`, a WeilgenModelAbi for the generated model in
// namespace `ns` (e.g. weilgen_models::gantry_grinder). Pointer arguments are copied into the
// generated functions' std::array arguments: a few dozen doubles, cheap against the model.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>

extern "C" {
struct WeilgenModelAbi {
  int abi_version;  // kWeilgenModelAbiVersion
  int order;
  const char* name;
  const char* key;  // kModelKey of the generated header
  std::size_t num_axes, num_errors, num_params;
  // axes in their units (mm, deg), errors in base units (mm, rad), params (mm, deg);
  // position (dx, dy, dz) in mm and orientation (da, db, dc) in rad; either may be null.
  void (*deviation)(const double* axes, const double* errors, const double* params,
                    double* position, double* orientation);
  // Row-major [output][error] first-order coefficients; either output may be null.
  void (*coefficients)(const double* axes, const double* params, double* position_coeff,
                       double* orientation_coeff);
  // `count` deviations at one pose (ABI version 2): errors row-major [count][num_errors],
  // position row-major [count][3] (dx, dy, dz) mm, orientation [count][3] (da, db, dc) rad;
  // either may be null. One call per batch instead of one per point (Sobol' designs).
  void (*deviation_batch)(const double* axes, const double* params, std::size_t count,
                          const double* errors, double* position, double* orientation);
  // deviation and coefficients at one pose in one call (ABI version 3), sharing the sin/cos and
  // the terms common to both (the generated DeviationAndCoefficients); any output may be null.
  void (*deviation_and_coefficients)(const double* axes, const double* errors, const double* params,
                                     double* position, double* orientation, double* position_coeff,
                                     double* orientation_coeff);
};
}

// 3: deviation_and_coefficients. A cached model built for an older version is compiled again.
inline constexpr int kWeilgenModelAbiVersion = 3;

#define WEILGEN_DEFINE_MODEL_ABI(ns, var)                                                        \
  namespace var##_impl {                                                                         \
    inline void coefficients(const double* axes, const double* params, double* position_coeff,   \
                             double* orientation_coeff) {                                        \
      std::array<double, ns::kNumAxes> a{};                                                      \
      std::array<double, ns::kNumParams> p{};                                                    \
      std::copy_n(axes, ns::kNumAxes, a.begin());                                                \
      std::copy_n(params, ns::kNumParams, p.begin());                                            \
      std::array<double, 3 * ns::kNumErrors> pc{}, oc{};                                         \
      ns::Coefficients<double>(a, p, position_coeff ? &pc : nullptr,                             \
                               orientation_coeff ? &oc : nullptr);                               \
      if (position_coeff) std::copy_n(pc.begin(), pc.size(), position_coeff);                    \
      if (orientation_coeff) std::copy_n(oc.begin(), oc.size(), orientation_coeff);              \
    }                                                                                            \
    inline void deviation_batch(const double* axes, const double* params, std::size_t count,     \
                                const double* errors, double* position, double* orientation) {   \
      std::array<double, ns::kNumAxes> a{};                                                      \
      std::array<double, ns::kNumErrors> e{};                                                    \
      std::array<double, ns::kNumParams> p{};                                                    \
      std::copy_n(axes, ns::kNumAxes, a.begin());                                                \
      std::copy_n(params, ns::kNumParams, p.begin());                                            \
      std::array<double, 3> pos{}, ori{};                                                        \
      for (std::size_t j = 0; j < count; ++j) {                                                  \
        std::copy_n(errors + j * ns::kNumErrors, ns::kNumErrors, e.begin());                     \
        ns::Deviation<double>(a, e, p, position ? &pos : nullptr, orientation ? &ori : nullptr); \
        if (position) std::copy_n(pos.begin(), 3, position + 3 * j);                             \
        if (orientation) std::copy_n(ori.begin(), 3, orientation + 3 * j);                       \
      }                                                                                          \
    }                                                                                            \
    /* One deviation is a batch of one. */                                                       \
    inline void deviation(const double* axes, const double* errors, const double* params,        \
                          double* position, double* orientation) {                               \
      deviation_batch(axes, params, 1, errors, position, orientation);                           \
    }                                                                                            \
    inline void deviation_and_coefficients(                                                      \
        const double* axes, const double* errors, const double* params, double* position,        \
        double* orientation, double* position_coeff, double* orientation_coeff) {                \
      std::array<double, ns::kNumAxes> a{};                                                      \
      std::array<double, ns::kNumErrors> e{};                                                    \
      std::array<double, ns::kNumParams> p{};                                                    \
      std::copy_n(axes, ns::kNumAxes, a.begin());                                                \
      std::copy_n(errors, ns::kNumErrors, e.begin());                                            \
      std::copy_n(params, ns::kNumParams, p.begin());                                            \
      std::array<double, 3> pos{}, ori{};                                                        \
      std::array<double, 3 * ns::kNumErrors> pc{}, oc{};                                         \
      ns::DeviationAndCoefficients<double>(                                                      \
          a, e, p, position ? &pos : nullptr, orientation ? &ori : nullptr,                      \
          position_coeff ? &pc : nullptr, orientation_coeff ? &oc : nullptr);                    \
      if (position) std::copy_n(pos.begin(), 3, position);                                       \
      if (orientation) std::copy_n(ori.begin(), 3, orientation);                                 \
      if (position_coeff) std::copy_n(pc.begin(), pc.size(), position_coeff);                    \
      if (orientation_coeff) std::copy_n(oc.begin(), oc.size(), orientation_coeff);              \
    }                                                                                            \
  }                                                                                              \
  const WeilgenModelAbi var = {kWeilgenModelAbiVersion,                                          \
                               ns::kOrder,                                                       \
                               ns::kMachineName,                                                 \
                               ns::kModelKey,                                                    \
                               ns::kNumAxes,                                                     \
                               ns::kNumErrors,                                                   \
                               ns::kNumParams,                                                   \
                               &var##_impl::deviation,                                           \
                               &var##_impl::coefficients,                                        \
                               &var##_impl::deviation_batch,                                     \
                               &var##_impl::deviation_and_coefficients};
