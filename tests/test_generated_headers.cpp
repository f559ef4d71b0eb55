// The committed generated headers, compiled into the test binary, against the exact numeric
// chain and against themselves (coefficients = finite differences of the deviation).
#include <doctest/doctest.h>

#include "five_axis_ac.hpp"
#include "gantry_grinder.hpp"
#include "head_head_bc.hpp"
#include "pipe_cutter.hpp"
#include "test_support.hpp"
#include "two_axis.hpp"
#include "vmc_3axis.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/model/numeric_chain.hpp"

using namespace weilgen;

namespace {

template <typename M>
struct Checker {
  std::string name;

  static std::array<double, 6> deviation(const std::vector<double>& q, const std::vector<double>& e,
                                         const std::vector<double>& p) {
    std::array<double, M::kNumAxes> axes{};
    std::array<double, M::kNumErrors> errors{};
    std::array<double, M::kNumParams> params{};
    std::copy(q.begin(), q.end(), axes.begin());
    std::copy(e.begin(), e.end(), errors.begin());
    std::copy(p.begin(), p.end(), params.begin());
    std::array<double, 3> pos{}, rot{};
    M::template Deviation<double>(axes, errors, params, &pos, &rot);
    return {pos[0], pos[1], pos[2], rot[0], rot[1], rot[2]};
  }

  void run() const {
    CAPTURE(name);
    const Description d = load_machine_file(test::machine_path(name));
    // Metadata mirrors the description.
    REQUIRE(M::kNumErrors == d.errors.size());
    REQUIRE(M::kNumAxes == d.axes().size());
    REQUIRE(M::kNumParams == d.parameters.size());
    for (std::size_t i = 0; i < d.errors.size(); ++i) {
      CHECK(std::string(M::kErrors[i].name) == d.errors[i].name);
      CHECK(M::kErrors[i].to_base == doctest::Approx(d.errors[i].to_base));
      CHECK(M::kErrors[i].b == doctest::Approx(d.errors[i].distribution.b));
    }
    std::vector<double> p;
    for (const auto& info : M::kParams) p.push_back(info.default_value);

    const NumericChain chain(d);
    std::mt19937 rng(5);
    for (int trial = 0; trial < 4; ++trial) {
      const auto q = test::random_pose(d, rng);
      const auto u = test::random_direction(d, rng);
      // O(s²) agreement with the exact chain: the residual shrinks ~4x per halving of s.
      const double r1 = test::max_abs_diff(deviation(q, test::scaled(u, 1e-2), p),
                                           chain.deviation(q, test::scaled(u, 1e-2)));
      const double r2 = test::max_abs_diff(deviation(q, test::scaled(u, 5e-3), p),
                                           chain.deviation(q, test::scaled(u, 5e-3)));
      CHECK(r2 < r1 / 3.0);
      CHECK(r1 < 1e-4);

      // Coefficients equal central finite differences of the generated deviation.
      std::array<double, M::kNumAxes> axes{};
      std::array<double, M::kNumParams> params{};
      std::copy(q.begin(), q.end(), axes.begin());
      std::copy(p.begin(), p.end(), params.begin());
      std::array<double, 3 * M::kNumErrors> cp{}, cr{};
      M::template Coefficients<double>(axes, params, &cp, &cr);
      for (std::size_t i = 0; i < M::kNumErrors; ++i) {
        std::vector<double> ep(M::kNumErrors, 0.0), em(M::kNumErrors, 0.0);
        ep[i] = 1e-3;
        em[i] = -1e-3;
        const auto fp = deviation(q, ep, p), fm = deviation(q, em, p);
        for (int o = 0; o < 6; ++o) {
          const double fd = (fp[o] - fm[o]) / 2e-3;
          const double c = o < 3 ? cp[o * M::kNumErrors + i] : cr[(o - 3) * M::kNumErrors + i];
          CHECK(c == doctest::Approx(fd).epsilon(1e-9).scale(1.0));
        }
      }
    }
    // Optional outputs: a null pointer is skipped, the other is still written.
    std::array<double, M::kNumAxes> axes{};
    std::array<double, M::kNumErrors> errors{};
    std::array<double, M::kNumParams> params{};
    errors.fill(1e-3);
    std::array<double, 3> rot{};
    M::template Deviation<double>(axes, errors, params, nullptr, &rot);
    CHECK((rot[0] != 0 || rot[1] != 0 || rot[2] != 0));
  }
};

// Adapters so that Checker can name each generated namespace.
#define WEILGEN_MODEL_ADAPTER(ns)                                             \
  struct ns##_model {                                                         \
    static constexpr auto kNumAxes = weilgen_models::ns::kNumAxes;            \
    static constexpr auto kNumErrors = weilgen_models::ns::kNumErrors;        \
    static constexpr auto kNumParams = weilgen_models::ns::kNumParams;        \
    static constexpr const auto& kErrors = weilgen_models::ns::kErrors;       \
    static constexpr const auto& kParams = weilgen_models::ns::kParams;       \
    template <typename S, typename... A>                                      \
    static void Deviation(A&&... a) {                                         \
      weilgen_models::ns::Deviation<S>(std::forward<A>(a)...);                \
    }                                                                         \
    template <typename S, typename... A>                                      \
    static void Coefficients(A&&... a) {                                      \
      weilgen_models::ns::Coefficients<S>(std::forward<A>(a)...);             \
    }                                                                         \
    template <typename S, typename... A>                                      \
    static void DeviationAndCoefficients(A&&... a) {                          \
      weilgen_models::ns::DeviationAndCoefficients<S>(std::forward<A>(a)...); \
    }                                                                         \
  };

WEILGEN_MODEL_ADAPTER(gantry_grinder)
WEILGEN_MODEL_ADAPTER(vmc_3axis)
WEILGEN_MODEL_ADAPTER(two_axis)
WEILGEN_MODEL_ADAPTER(five_axis_ac)
WEILGEN_MODEL_ADAPTER(pipe_cutter)
WEILGEN_MODEL_ADAPTER(head_head_bc)

// DeviationAndCoefficients against Deviation and Coefficients called separately, on random poses
// and errors: returns the largest difference relative to the output's magnitude (0 when every
// value is bit for bit the same) and counts the values that differ at all. Every combination
// of null outputs writes exactly the non-null ones, bit for bit those of the full call.
template <typename M>
double combined_vs_separate(const std::string& name, std::size_t& differing, std::size_t& total) {
  CAPTURE(name);
  const Description d = load_machine_file(test::machine_path(name));
  std::array<double, M::kNumParams> params{};
  for (std::size_t k = 0; k < M::kNumParams; ++k) params[k] = M::kParams[k].default_value;
  std::mt19937 rng(23);
  double worst = 0;
  for (int trial = 0; trial < 16; ++trial) {
    const auto q = test::random_pose(d, rng);
    const auto e = test::scaled(test::random_direction(d, rng), 1e-2);
    std::array<double, M::kNumAxes> axes{};
    std::array<double, M::kNumErrors> errors{};
    std::copy(q.begin(), q.end(), axes.begin());
    std::copy(e.begin(), e.end(), errors.begin());
    std::array<double, 3> pos{}, rot{}, pos2{}, rot2{};
    std::array<double, 3 * M::kNumErrors> cp{}, cr{}, cp2{}, cr2{};
    M::template Deviation<double>(axes, errors, params, &pos, &rot);
    M::template Coefficients<double>(axes, params, &cp, &cr);
    M::template DeviationAndCoefficients<double>(axes, errors, params, &pos2, &rot2, &cp2, &cr2);
    const auto compare = [&](const double* a, const double* b, std::size_t n) {
      double scale = 0;
      for (std::size_t k = 0; k < n; ++k) scale = std::max(scale, std::abs(a[k]));
      for (std::size_t k = 0; k < n; ++k) {
        ++total;
        if (a[k] == b[k]) continue;
        ++differing;
        worst = std::max(worst, std::abs(a[k] - b[k]) / std::max(scale, 1e-300));
      }
    };
    compare(pos.data(), pos2.data(), 3);
    compare(rot.data(), rot2.data(), 3);
    compare(cp.data(), cp2.data(), cp.size());
    compare(cr.data(), cr2.data(), cr.size());
    for (int mask = 0; mask < 16; ++mask) {
      CAPTURE(mask);
      std::array<double, 3> p3{}, r3{};
      std::array<double, 3 * M::kNumErrors> c3{}, o3{};
      p3.fill(-7);
      r3.fill(-7);
      c3.fill(-7);
      o3.fill(-7);
      M::template DeviationAndCoefficients<double>(
          axes, errors, params, mask & 1 ? &p3 : nullptr, mask & 2 ? &r3 : nullptr,
          mask & 4 ? &c3 : nullptr, mask & 8 ? &o3 : nullptr);
      std::array<double, 3> p_none{}, r_none{};
      std::array<double, 3 * M::kNumErrors> c_none{}, o_none{};
      p_none.fill(-7);
      r_none.fill(-7);
      c_none.fill(-7);
      o_none.fill(-7);
      CHECK(p3 == (mask & 1 ? pos2 : p_none));
      CHECK(r3 == (mask & 2 ? rot2 : r_none));
      CHECK(c3 == (mask & 4 ? cp2 : c_none));
      CHECK(o3 == (mask & 8 ? cr2 : o_none));
    }
  }
  return worst;
}

}  // namespace

TEST_CASE("generated headers agree with the exact chain and their coefficients are exact") {
  Checker<gantry_grinder_model>{"gantry_grinder"}.run();
  Checker<vmc_3axis_model>{"vmc_3axis"}.run();
  Checker<two_axis_model>{"two_axis"}.run();
  Checker<pipe_cutter_model>{"pipe_cutter"}.run();
  Checker<five_axis_ac_model>{"five_axis_ac"}.run();
}

TEST_CASE("DeviationAndCoefficients equals Deviation and Coefficients to rounding, nulls skip") {
  std::size_t differing = 0, total = 0;
  double worst = 0;
  worst = std::max(worst,
                   combined_vs_separate<gantry_grinder_model>("gantry_grinder", differing, total));
  worst = std::max(worst, combined_vs_separate<vmc_3axis_model>("vmc_3axis", differing, total));
  worst = std::max(worst, combined_vs_separate<two_axis_model>("two_axis", differing, total));
  worst =
      std::max(worst, combined_vs_separate<five_axis_ac_model>("five_axis_ac", differing, total));
  worst = std::max(worst, combined_vs_separate<pipe_cutter_model>("pipe_cutter", differing, total));
  worst =
      std::max(worst, combined_vs_separate<head_head_bc_model>("head_head_bc", differing, total));
  MESSAGE("DeviationAndCoefficients: " << differing << " of " << total
                                       << " values differ from the separate calls, by at most "
                                       << worst << " of the output's magnitude");
  // A few ulps of the largest value of the output: the same sums, grouped differently.
  CHECK(worst < 1e-14);
}
