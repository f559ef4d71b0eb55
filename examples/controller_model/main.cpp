// Controller-side use of generated error models: the tool point's deviation at a few poses with
// every error at a one-sigma value, as a compensation table would be filled. Checks that the
// linear coefficients reproduce the order-1 model and that order 2 only adds a small correction.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>

#include "vmc_3axis.hpp"     // weilgen_models::vmc_3axis: the machine file's order (1)
#include "vmc_3axis_o2.hpp"  // weilgen_models::vmc_3axis_o2: generated with ORDER 2

namespace m1 = weilgen_models::vmc_3axis;
namespace m2 = weilgen_models::vmc_3axis_o2;

namespace {

// A one-sigma value of each error, in the base units the model takes (mm, rad): mean + sigma
// for (truncated) normal errors, centre + standard deviation for uniform ones. The metadata
// gives distributions in each error's own unit; to_base converts.
template <typename ErrorInfo, std::size_t N>
std::array<double, N> OneSigmaErrors(const std::array<ErrorInfo, N>& info) {
  using Kind = decltype(ErrorInfo::distribution);
  std::array<double, N> e{};
  for (std::size_t i = 0; i < N; ++i) {
    const ErrorInfo& k = info[i];
    double v = 0.0;
    if (k.distribution == Kind::kNormal || k.distribution == Kind::kTruncatedNormal) {
      v = k.a + k.b;
    } else if (k.distribution == Kind::kUniform) {
      v = 0.5 * (k.a + k.b) + (k.b - k.a) / std::sqrt(12.0);
    }
    e[i] = v * k.to_base;
  }
  return e;
}

template <typename ParamInfo, std::size_t N>
std::array<double, N> DefaultParams(const std::array<ParamInfo, N>& info) {
  std::array<double, N> p{};
  for (std::size_t i = 0; i < N; ++i) p[i] = info[i].default_value;
  return p;
}

}  // namespace

int main() {
  constexpr double kUm = 1e3;    // mm -> um
  constexpr double kUrad = 1e6;  // rad -> urad
  const std::array<double, m1::kNumErrors> errors = OneSigmaErrors(m1::kErrors);
  const std::array<double, m1::kNumParams> params = DefaultParams(m1::kParams);

  // Poses as fractions of each axis's travel (order of kAxes).
  const std::array<std::array<double, m1::kNumAxes>, 4> fractions = {
      {{0.0, 0.0, 0.0}, {0.5, 0.5, 0.5}, {1.0, 0.0, 1.0}, {0.25, 1.0, 0.75}}};

  std::printf("%s, order %d and %d, errors at one sigma\n", m1::kMachineName, m1::kOrder,
              m2::kOrder);
  std::printf("%-26s %10s %10s %10s %10s %10s %10s %12s\n", "pose (mm)", "dx um", "dy um", "dz um",
              "da urad", "db urad", "dc urad", "o2-o1 nm");
  int failures = 0;
  for (const auto& f : fractions) {
    std::array<double, m1::kNumAxes> axes{};
    for (std::size_t a = 0; a < m1::kNumAxes; ++a) {
      axes[a] = m1::kAxes[a].min + f[a] * (m1::kAxes[a].max - m1::kAxes[a].min);
    }
    std::array<double, 3> pos{}, ori{}, pos2{};
    m1::Deviation(axes, errors, params, &pos, &ori);
    m2::Deviation(axes, errors, params, &pos2);  // orientation not needed: null pointer
    std::array<double, 3 * m1::kNumErrors> coeff{};
    m1::Coefficients(axes, params, &coeff);

    double second_order = 0.0;  // largest |order 2 - order 1| over dx, dy, dz, in mm
    for (std::size_t o = 0; o < 3; ++o) {
      double linear = 0.0;
      for (std::size_t j = 0; j < m1::kNumErrors; ++j)
        linear += coeff[o * m1::kNumErrors + j] * errors[j];
      if (std::fabs(linear - pos[o]) > 1e-12) {
        std::printf("coefficients disagree with Deviation in output %zu: %g vs %g mm\n", o, linear,
                    pos[o]);
        ++failures;
      }
      second_order = std::fmax(second_order, std::fabs(pos2[o] - pos[o]));
    }
    // Products of errors of a few um or urad over a travel of ~1 m are far below 1 nm.
    if (second_order > 1e-6) {
      std::printf("order-2 correction of %g mm is implausibly large\n", second_order);
      ++failures;
    }
    char pose[64];
    std::snprintf(pose, sizeof pose, "%s=%g %s=%g %s=%g", m1::kAxes[0].name, axes[0],
                  m1::kAxes[1].name, axes[1], m1::kAxes[2].name, axes[2]);
    std::printf("%-26s %10.3f %10.3f %10.3f %10.3f %10.3f %10.3f %12.2e\n", pose, pos[0] * kUm,
                pos[1] * kUm, pos[2] * kUm, ori[0] * kUrad, ori[1] * kUrad, ori[2] * kUrad,
                second_order * 1e6);
  }
  return failures == 0 ? 0 : 1;
}
