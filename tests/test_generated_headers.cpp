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
    template <typename S, typename... A>                                      \
    static void NominalPose(A&&... a) {                                       \
      weilgen_models::ns::NominalPose<S>(std::forward<A>(a)...);              \
    }                                                                         \
    template <typename S, typename... A>                                      \
    static void NominalJacobian(A&&... a) {                                   \
      weilgen_models::ns::NominalJacobian<S>(std::forward<A>(a)...);          \
    }                                                                         \
  };

WEILGEN_MODEL_ADAPTER(gantry_grinder)
WEILGEN_MODEL_ADAPTER(vmc_3axis)
WEILGEN_MODEL_ADAPTER(two_axis)
WEILGEN_MODEL_ADAPTER(five_axis_ac)
WEILGEN_MODEL_ADAPTER(pipe_cutter)
WEILGEN_MODEL_ADAPTER(head_head_bc)

// n values got(k) against want[k]: counts them into `total`, those not bit for bit equal into
// `differing`, and raises `worst` to the largest difference relative to want's largest magnitude.
template <typename Got>
void tally_agreement(const double* want, std::size_t n, const Got& got, std::size_t& differing,
                     std::size_t& total, double& worst) {
  double scale = 0;
  for (std::size_t k = 0; k < n; ++k) scale = std::max(scale, std::abs(want[k]));
  for (std::size_t k = 0; k < n; ++k) {
    ++total;
    const double v = got(k);
    if (v == want[k]) continue;
    ++differing;
    worst = std::max(worst, std::abs(v - want[k]) / std::max(scale, 1e-300));
  }
}

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
      tally_agreement(
          a, n, [&](std::size_t k) { return b[k]; }, differing, total, worst);
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

// Every evaluation function with Scalar = Pack<L> (one pose per lane: random poses, errors and
// parameters scaled per lane) against the double function called lane by lane. Returns the
// largest difference relative to the output array's magnitude; counts the values compared and
// those not bit for bit equal (all are, unless the compiler contracts a*b+c differently in the
// two, e.g. with -ffp-contract=fast: scripts/test_fp_variants.sh).
template <typename M, std::size_t L>
double pack_vs_double(const std::string& name, std::size_t& differing, std::size_t& total) {
  CAPTURE(name);
  CAPTURE(L);
  using P = weilgen_models::Pack<L>;
  const Description d = load_machine_file(test::machine_path(name));
  std::mt19937 rng(31);
  double worst = 0;
  for (int trial = 0; trial < 4; ++trial) {
    std::array<std::array<double, M::kNumAxes>, L> axes{};
    std::array<std::array<double, M::kNumErrors>, L> errors{};
    std::array<std::array<double, M::kNumParams>, L> params{};
    std::array<P, M::kNumAxes> pa{};
    std::array<P, M::kNumErrors> pe{};
    std::array<P, M::kNumParams> pp{};
    for (std::size_t l = 0; l < L; ++l) {
      const auto q = test::random_pose(d, rng);
      const auto e = test::scaled(test::random_direction(d, rng), 1e-2);
      for (std::size_t k = 0; k < M::kNumAxes; ++k) pa[k].Set(l, axes[l][k] = q[k]);
      for (std::size_t k = 0; k < M::kNumErrors; ++k) pe[k].Set(l, errors[l][k] = e[k]);
      for (std::size_t k = 0; k < M::kNumParams; ++k)
        pp[k].Set(l, params[l][k] = M::kParams[k].default_value * (1.0 + 0.01 * double(l)));
    }
    std::array<P, 3> pos{}, rot{}, pos2{}, rot2{}, nominal_pos{};
    std::array<P, 9> nominal_rot{};
    std::array<P, 3 * M::kNumErrors> cp{}, cr{}, cp2{}, cr2{};
    std::array<P, 6 * M::kNumAxes> jac{};
    M::template Deviation<P>(pa, pe, pp, &pos, &rot);
    M::template Coefficients<P>(pa, pp, &cp, &cr);
    M::template DeviationAndCoefficients<P>(pa, pe, pp, &pos2, &rot2, &cp2, &cr2);
    M::template NominalPose<P>(pa, pp, &nominal_pos, &nominal_rot);
    M::template NominalJacobian<P>(pa, pp, &jac);
    for (std::size_t l = 0; l < L; ++l) {
      std::array<double, 3> dpos{}, drot{}, dpos2{}, drot2{}, dnominal_pos{};
      std::array<double, 9> dnominal_rot{};
      std::array<double, 3 * M::kNumErrors> dcp{}, dcr{}, dcp2{}, dcr2{};
      std::array<double, 6 * M::kNumAxes> djac{};
      M::template Deviation<double>(axes[l], errors[l], params[l], &dpos, &drot);
      M::template Coefficients<double>(axes[l], params[l], &dcp, &dcr);
      M::template DeviationAndCoefficients<double>(axes[l], errors[l], params[l], &dpos2, &drot2,
                                                   &dcp2, &dcr2);
      M::template NominalPose<double>(axes[l], params[l], &dnominal_pos, &dnominal_rot);
      M::template NominalJacobian<double>(axes[l], params[l], &djac);
      const auto compare = [&](const auto& packs, const auto& doubles) {
        tally_agreement(
            doubles.data(), doubles.size(), [&](std::size_t k) { return packs[k].Get(l); },
            differing, total, worst);
      };
      compare(pos, dpos);
      compare(rot, drot);
      compare(cp, dcp);
      compare(cr, dcr);
      compare(pos2, dpos2);
      compare(rot2, drot2);
      compare(cp2, dcp2);
      compare(cr2, dcr2);
      compare(nominal_pos, dnominal_pos);
      compare(nominal_rot, dnominal_rot);
      compare(jac, djac);
    }
  }
  return worst;
}

template <typename M>
double pack_vs_double_all_widths(const std::string& name, std::size_t& differing,
                                 std::size_t& total) {
  return std::max({pack_vs_double<M, 2>(name, differing, total),
                   pack_vs_double<M, 4>(name, differing, total),
                   pack_vs_double<M, 8>(name, differing, total)});
}

}  // namespace

TEST_CASE("Pack<2>, <4>, <8>: every lane is the double functions' result for its pose") {
  std::size_t differing = 0, total = 0;
  double worst = 0;
  worst = std::max(
      worst, pack_vs_double_all_widths<gantry_grinder_model>("gantry_grinder", differing, total));
  worst =
      std::max(worst, pack_vs_double_all_widths<vmc_3axis_model>("vmc_3axis", differing, total));
  worst = std::max(worst, pack_vs_double_all_widths<two_axis_model>("two_axis", differing, total));
  worst = std::max(worst,
                   pack_vs_double_all_widths<five_axis_ac_model>("five_axis_ac", differing, total));
  worst = std::max(worst,
                   pack_vs_double_all_widths<pipe_cutter_model>("pipe_cutter", differing, total));
  worst = std::max(worst,
                   pack_vs_double_all_widths<head_head_bc_model>("head_head_bc", differing, total));
  MESSAGE("Pack lanes: " << differing << " of " << total
                         << " values differ from the double functions, by at most " << worst
                         << " of the output's magnitude");
  CHECK(total > 100000);
  // The same operations in the same order: bit for bit, or (when a build contracts a*b+c in one
  // and not the other) a few ulps of the output's magnitude.
  CHECK(worst < 1e-14);
}

namespace {
// |a - b| in units of the last place of b (the C library's value).
double ulps(double a, double b) {
  if (a == b) return 0;
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b) ? 0 : 1e300;
  int exponent = 0;
  std::frexp(b, &exponent);
  const double ulp = b == 0 ? std::numeric_limits<double>::denorm_min()
                            : std::ldexp(1.0, std::max(exponent - 53, -1074));
  return std::abs(a - b) / ulp;
}

// Pack<L>'s sin and cos against std::sin and std::cos lane by lane over `x`: the largest
// difference in ulps and the fraction of values not bit for bit equal (sign of zero included).
template <std::size_t L>
std::pair<double, double> pack_sincos_error(const std::vector<double>& x) {
  using P = weilgen_models::Pack<L>;
  double worst = 0;
  std::size_t differing = 0;
  for (std::size_t i = 0; i + L <= x.size(); i += L) {
    const P a = P::Load(x.data() + i);
    const P s = sin(a), c = cos(a);
    for (std::size_t l = 0; l < L; ++l) {
      const double ws = std::sin(x[i + l]), wc = std::cos(x[i + l]);
      worst = std::max({worst, ulps(s.Get(l), ws), ulps(c.Get(l), wc)});
      const auto same = [](double u, double w) {
        return (u == w && std::signbit(u) == std::signbit(w)) || (std::isnan(u) && std::isnan(w));
      };
      if (!same(s.Get(l), ws)) ++differing;
      if (!same(c.Get(l), wc)) ++differing;
    }
  }
  return {worst, double(differing) / double(2 * x.size())};
}
}  // namespace

TEST_CASE("Pack sin/cos: within 1 ulp of the C library, beyond 1e6 rad, inf, NaN the library's") {
  std::mt19937_64 rng(17);
  const auto uniform = [&](double lo, double hi, std::size_t n) {
    std::uniform_real_distribution<double> u(lo, hi);
    std::vector<double> v(n);
    for (double& x : v) x = u(rng);
    return v;
  };
  std::vector<double> near_multiples;  // k pi/2 as doubles, and 3 ulps either side
  for (int k = -20000; k <= 20000; ++k)
    for (int d = -3; d <= 3; ++d) {
      double x = k * 1.5707963267948966;
      for (int j = 0; j < std::abs(d); ++j) x = std::nextafter(x, d > 0 ? 1e300 : -1e300);
      near_multiples.push_back(x);
    }
  std::vector<double> degrees;  // whole and tenth degrees as an axis gives them, in rad
  for (int k = -36000; k <= 36000; ++k) degrees.push_back(k * 0.1 * 0.017453292519943295);
  std::vector<double> tiny = uniform(-1e-8, 1e-8, 10000);
  for (double v : {0.0, -0.0, 1e-310, -1e-310, 5e-324}) tiny.push_back(v);
  const std::vector<std::pair<std::string, std::vector<double>>> sets = {
      {"[-2 pi, 2 pi]", uniform(-6.3, 6.3, 400000)},
      {"[-1e3, 1e3]", uniform(-1e3, 1e3, 200000)},
      {"[-1e6, 1e6]", uniform(-1e6, 1e6, 200000)},
      {"k pi/2 +- 3 ulp", near_multiples},
      {"0.1 deg steps", degrees},
      {"tiny, +-0, subnormal", tiny}};
  for (const auto& [name, x] : sets) {
    for (const auto& [worst, fraction] :
         {pack_sincos_error<2>(x), pack_sincos_error<4>(x), pack_sincos_error<8>(x)}) {
      CAPTURE(name);
      MESSAGE(name << ": max " << worst << " ulp, " << 100 * fraction << " % differ");
      CHECK(worst <= 1.0);
      CHECK(fraction < 0.25);
    }
  }
  // A lane out of range sends the whole pack to the C library: bit for bit its values.
  const double inf = std::numeric_limits<double>::infinity();
  for (const double odd : {1e7, -3e9, inf, -inf, std::nan("")}) {
    CAPTURE(odd);
    const std::vector<double> x = {0.3, odd, -1.2, 2.5};
    const auto [worst, fraction] = pack_sincos_error<4>(x);
    CHECK(worst == 0);
    CHECK(fraction == 0);
  }
}

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
