// The C API (`weilgen generate --c-api`, docs/controllers.md): for every shipped machine a C99
// program (tests/c_api/run_body.c, built with -Wall -Wextra -Wpedantic -Werror and linked as C)
// evaluates deviation, coefficients, nominal pose and Jacobian and compensate at many poses;
// every double must equal the C++ header's to rounding (bit for bit without FP contraction).
// Plus the named indices of the C++ header, and names the C API cannot take (clashes in upper
// case, reserved names).
#include <doctest/doctest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "five_axis_ac.hpp"
#include "gantry_grinder.hpp"
#include "pipe_cutter.hpp"
#include "test_support.hpp"
#include "two_axis.hpp"
#include "vmc_3axis.hpp"

using namespace weilgen;
namespace fs = std::filesystem;

namespace {

// The C++ side of one model: random cases, its results in the runner's layout.
template <typename Axes, typename Errors, typename Params>
struct Case {
  Axes axes{};
  Errors errors{};
  Params params{};
};

void append(std::vector<double>& v, const double* p, std::size_t n) { v.insert(v.end(), p, p + n); }

#define WEILGEN_C_API_MODEL(ns)                                                              \
  struct ns##_model {                                                                        \
    static constexpr const char* name = #ns;                                                 \
    static constexpr std::size_t na = weilgen_models::ns::kNumAxes;                          \
    static constexpr std::size_t ne = weilgen_models::ns::kNumErrors;                        \
    static constexpr std::size_t np = weilgen_models::ns::kNumParams;                        \
    static const auto& axes() { return weilgen_models::ns::kAxes; }                          \
    static const auto& errors() { return weilgen_models::ns::kErrors; }                      \
    static const auto& params() { return weilgen_models::ns::kParams; }                      \
    template <typename C>                                                                    \
    static std::vector<double> results(const C& c) {                                         \
      namespace m = weilgen_models::ns;                                                      \
      std::vector<double> out;                                                               \
      std::array<double, 3> p{}, o{}, pose{};                                                \
      std::array<double, 3 * ne> pc{}, oc{};                                                 \
      std::array<double, 9> r{};                                                             \
      std::array<double, 6 * na> j{};                                                        \
      std::array<double, na> command{};                                                      \
      m::Deviation(c.axes, c.errors, c.params, &p, &o);                                      \
      m::Coefficients(c.axes, c.params, &pc, &oc);                                           \
      m::NominalPose(c.axes, c.params, &pose, &r);                                           \
      m::NominalJacobian(c.axes, c.params, &j);                                              \
      const int it = m::Compensate(c.axes, c.errors, c.params, &command, 10, 1e-9);          \
      const std::array<double, 2> status = {it < 0 ? -1.0 : 0.0, it < 0 ? 0.0 : double(it)}; \
      for (const auto* a : {&p, &o}) append(out, a->data(), 3);                              \
      for (const auto* a : {&pc, &oc}) append(out, a->data(), a->size());                    \
      m::DeviationAndCoefficients(c.axes, c.errors, c.params, &p, &o, &pc, &oc);             \
      for (const auto* a : {&p, &o}) append(out, a->data(), 3);                              \
      for (const auto* a : {&pc, &oc}) append(out, a->data(), a->size());                    \
      append(out, pose.data(), 3);                                                           \
      append(out, r.data(), 9);                                                              \
      append(out, j.data(), j.size());                                                       \
      append(out, command.data(), na);                                                       \
      append(out, status.data(), 2);                                                         \
      return out;                                                                            \
    }                                                                                        \
  };

WEILGEN_C_API_MODEL(gantry_grinder)
WEILGEN_C_API_MODEL(vmc_3axis)
WEILGEN_C_API_MODEL(two_axis)
WEILGEN_C_API_MODEL(five_axis_ac)
WEILGEN_C_API_MODEL(pipe_cutter)

// Random cases within the axes' ranges, errors up to 3x their machine-file scale, parameters
// at and around their defaults; runs the C program and compares every double with memcmp.
template <typename T>
void check_against_cpp(std::size_t cases) {
  CAPTURE(T::name);
  using C = Case<std::array<double, T::na>, std::array<double, T::ne>, std::array<double, T::np>>;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0), unit(0.0, 1.0);
  std::vector<C> all(cases);
  for (std::size_t k = 0; k < cases; ++k) {
    C& c = all[k];
    for (std::size_t i = 0; i < T::na; ++i)
      c.axes[i] = T::axes()[i].min + (T::axes()[i].max - T::axes()[i].min) * unit(rng);
    for (std::size_t i = 0; i < T::ne; ++i) {
      const auto& e = T::errors()[i];
      const double scale = std::max(std::fabs(e.a), std::fabs(e.b)) * e.to_base;
      c.errors[i] = 3 * scale * u(rng);
    }
    for (std::size_t i = 0; i < T::np; ++i)
      c.params[i] = T::params()[i].default_value * (k % 2 ? 1.0 + 0.01 * u(rng) : 1.0);
  }
  const fs::path dir = test::fresh_dir(std::string("c_api_") + T::name);
  const std::string in = (dir / "in.bin").string(), out = (dir / "out.bin").string();
  {
    std::ofstream f(in, std::ios::binary);
    for (const C& c : all) {
      f.write(reinterpret_cast<const char*>(c.axes.data()), sizeof(double) * T::na);
      f.write(reinterpret_cast<const char*>(c.errors.data()), sizeof(double) * T::ne);
      if (T::np) f.write(reinterpret_cast<const char*>(c.params.data()), sizeof(double) * T::np);
    }
  }
  const std::string runner = std::string(WEILGEN_C_API_RUNNERS) + "/c_api_run_" + T::name;
  const test::Run r = test::run(runner + " " + in + " " + out);
  INFO(r.out);
  REQUIRE(r.status == 0);
  CHECK(r.out.find(std::to_string(cases) + " cases") != std::string::npos);

  // The same code through two compilers: bit for bit where neither contracts a*b+c into a fused
  // multiply-add, and equal to rounding where one does (-mfma -ffp-contract=fast): every value
  // within 1e-12 of the case's largest (mm, rad and their coefficients; the status flags exact).
  std::ifstream f(out, std::ios::binary);
  std::size_t identical = 0, close = 0, compensated = 0;
  double worst = 0;
  for (std::size_t k = 0; k < cases; ++k) {
    const std::vector<double> want = T::results(all[k]);
    std::vector<double> got(want.size());
    REQUIRE(f.read(reinterpret_cast<char*>(got.data()),
                   static_cast<std::streamsize>(sizeof(double) * got.size())));
    if (std::memcmp(got.data(), want.data(), sizeof(double) * want.size()) == 0) ++identical;
    double scale = 1e-300, diff = 0;
    for (std::size_t i = 0; i < want.size(); ++i) {
      scale = std::max(scale, std::fabs(want[i]));
      diff = std::max(diff, std::fabs(got[i] - want[i]));
    }
    worst = std::max(worst, diff / scale);
    if (diff <= 1e-12 * scale && got.back() == want.back()) ++close;
    if (want.back() > 0) ++compensated;
  }
  CHECK(f.peek() == std::char_traits<char>::eof());
  CHECK(close == cases);
  MESSAGE(std::string(T::name) << ": " << identical << " of " << cases << " cases bit-identical, "
                               << close << " within 1e-12 (worst " << worst << "), " << compensated
                               << " compensated");
  // The pipe cutter's compensation is singular (docs/compensation.md): every call says so.
  if (std::string(T::name) == "pipe_cutter")
    CHECK(compensated == 0);
  else
    CHECK(compensated == cases);
}

}  // namespace

TEST_CASE("C API: a C99 program agrees with the C++ header to rounding on every shipped model") {
  check_against_cpp<gantry_grinder_model>(2000);
  check_against_cpp<vmc_3axis_model>(2000);
  check_against_cpp<two_axis_model>(2000);
  check_against_cpp<five_axis_ac_model>(2000);
  check_against_cpp<pipe_cutter_model>(500);
}

TEST_CASE("the C++ header's named indices are the kAxes / kErrors / kParams positions") {
  namespace m = weilgen_models::five_axis_ac;
  CHECK(std::string(m::kAxes[m::axis::A].name) == "A");
  CHECK(std::string(m::kAxes[m::axis::C].name) == "C");
  CHECK(std::string(m::kErrors[m::error::E_X0C].name) == "E_X0C");
  CHECK(std::string(m::kParams[m::param::c_above_a].name) == "c_above_a");
  namespace v = weilgen_models::vmc_3axis;
  CHECK(v::error::E_XX == 7);
  CHECK(v::axis::X == 1);
}

TEST_CASE("C API: names that clash in upper case or are reserved are refused, nothing written") {
  std::string text;
  REQUIRE(read_file(test::machine_path("two_axis"), text));
  const fs::path dir = test::fresh_dir("c_api_clash");

  // Two parameters that differ in case only: fine in C++, one enumerator in C.
  const auto at = text.find("\nparameters:");
  REQUIRE(at != std::string::npos);
  std::string clash = text;
  clash.insert(text.find('\n', at + 1) + 1, "  Tool_Length: {value: 0, unit: mm}\n");
  const std::string clash_path = (dir / "clash.yaml").string();
  write_file_atomically(clash_path, clash);
  const std::string out = (dir / "out").string();
  test::Run r = test::run(test::cli("generate " + clash_path + " --out " + out));
  INFO(r.out);
  REQUIRE(r.status == 0);  // the C++ header alone is fine
  fs::remove_all(out);
  r = test::run(test::cli("generate " + clash_path + " --c-api --out " + out));
  INFO(r.out);
  CHECK(r.status == 3);
  CHECK(r.out.find("clash.yaml:") != std::string::npos);
  CHECK(r.out.find("TWO_AXIS_PARAM_TOOL_LENGTH") != std::string::npos);
  CHECK(!fs::exists(out));

  // A model name with a leading underscore is reserved in C.
  std::string reserved = text;
  const auto name_at = reserved.find("name: two_axis");
  REQUIRE(name_at != std::string::npos);
  reserved.replace(name_at, 14, "name: _two_axis");
  const std::string reserved_path = (dir / "reserved.yaml").string();
  write_file_atomically(reserved_path, reserved);
  r = test::run(test::cli("generate " + reserved_path + " --c-api --out " + out));
  INFO(r.out);
  CHECK(r.status == 3);
  CHECK(r.out.find("reserved") != std::string::npos);
  CHECK(!fs::exists(out));
}
