// NominalPose, NominalJacobian and Compensate of the committed generated headers
// (docs/compensation.md): the nominal kinematics against the exact numeric chain, the true pose
// error of a compensated command (O(s²) in the errors, against O(s) uncompensated), iteration
// counts, failure reporting, and a strict standalone compile of every template.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <fstream>

#include "five_axis_ac.hpp"
#include "gantry_grinder.hpp"
#include "pipe_cutter.hpp"
#include "test_support.hpp"
#include "two_axis.hpp"
#include "vmc_3axis.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/model/numeric_chain.hpp"

using namespace weilgen;

namespace {

// Adapters so that templates can name each generated namespace (Scalar = double).
#define WEILGEN_COMPENSATION_ADAPTER(ns)                                                       \
  struct ns##_model {                                                                          \
    static constexpr const char* kName = #ns;                                                  \
    static constexpr std::size_t kNumAxes = weilgen_models::ns::kNumAxes;                      \
    static constexpr std::size_t kNumErrors = weilgen_models::ns::kNumErrors;                  \
    static constexpr std::size_t kNumParams = weilgen_models::ns::kNumParams;                  \
    static constexpr bool kCompensateOrientation = weilgen_models::ns::kCompensateOrientation; \
    static constexpr double kLengthMm = weilgen_models::ns::kCompensationLengthMm;             \
    static constexpr double kSpinWeight = weilgen_models::ns::kCompensationSpinWeight;         \
    template <typename... A>                                                                   \
    static void NominalPose(A&&... a) {                                                        \
      weilgen_models::ns::NominalPose<double>(std::forward<A>(a)...);                          \
    }                                                                                          \
    template <typename... A>                                                                   \
    static void NominalJacobian(A&&... a) {                                                    \
      weilgen_models::ns::NominalJacobian<double>(std::forward<A>(a)...);                      \
    }                                                                                          \
    template <typename... A>                                                                   \
    static int Compensate(A&&... a) {                                                          \
      return weilgen_models::ns::Compensate<double>(std::forward<A>(a)...);                    \
    }                                                                                          \
  };

WEILGEN_COMPENSATION_ADAPTER(gantry_grinder)
WEILGEN_COMPENSATION_ADAPTER(vmc_3axis)
WEILGEN_COMPENSATION_ADAPTER(two_axis)
WEILGEN_COMPENSATION_ADAPTER(five_axis_ac)
WEILGEN_COMPENSATION_ADAPTER(pipe_cutter)

template <std::size_t N>
std::array<double, N> to_array(const std::vector<double>& v) {
  std::array<double, N> a{};
  REQUIRE(v.size() == N);
  std::copy(v.begin(), v.end(), a.begin());
  return a;
}

template <std::size_t N>
std::vector<double> to_vector(const std::array<double, N>& a) {
  return {a.begin(), a.end()};
}

Eigen::Vector3d rotation_vector(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

std::vector<double> default_params(const Description& d) {
  std::vector<double> p;
  const auto defaults = d.parameter_defaults();
  for (const auto& info : d.parameters) p.push_back(defaults.at(info.name));
  return p;
}

// The spread of an error's distribution in base units (mm, rad): sigma, or the half width.
double spread(const ErrorDef& e) {
  const Distribution& dist = e.distribution;
  const double s = dist.kind == Distribution::Kind::Uniform ? (dist.b - dist.a) / 2 : dist.b;
  return s * e.to_base;
}

// NominalPose equals the exact chain at zero errors; NominalJacobian equals its central
// differences (position in mm, orientation as the rotation vector of R(q+h)·R(q−h)ᵀ, per axis
// unit).
template <typename M>
void check_nominal_kinematics() {
  const std::string name = M::kName;
  CAPTURE(name);
  const Description d = load_machine_file(test::machine_path(name));
  const NumericChain chain(d);
  const std::vector<double> zero(d.errors.size(), 0.0);
  const auto params = to_array<M::kNumParams>(default_params(d));
  std::mt19937 rng(17);
  for (int trial = 0; trial < 5; ++trial) {
    const auto q = test::random_pose(d, rng);
    const auto axes = to_array<M::kNumAxes>(q);
    std::array<double, 3> position{};
    std::array<double, 9> rotation{};
    M::NominalPose(axes, params, &position, &rotation);
    const Eigen::Matrix4d t = chain.tool_in_workpiece(q, zero);
    for (int i = 0; i < 3; ++i) {
      CHECK(position[i] == doctest::Approx(t(i, 3)).epsilon(1e-12).scale(1.0));
      for (int j = 0; j < 3; ++j)
        CHECK(rotation[3 * i + j] == doctest::Approx(t(i, j)).epsilon(1e-12).scale(1.0));
    }
    std::array<double, 6 * M::kNumAxes> jacobian{};
    M::NominalJacobian(axes, params, &jacobian);
    for (std::size_t k = 0; k < M::kNumAxes; ++k) {
      CAPTURE(k);
      const double h = 1e-3;  // mm or deg
      auto qp = q, qm = q;
      qp[k] += h;
      qm[k] -= h;
      const Eigen::Matrix4d tp = chain.tool_in_workpiece(qp, zero);
      const Eigen::Matrix4d tm = chain.tool_in_workpiece(qm, zero);
      const Eigen::Vector3d dp = (tp.block<3, 1>(0, 3) - tm.block<3, 1>(0, 3)) / (2 * h);
      const Eigen::Vector3d dr =
          rotation_vector(tp.block<3, 3>(0, 0) * tm.block<3, 3>(0, 0).transpose()) / (2 * h);
      for (std::size_t o = 0; o < 6; ++o) {
        CAPTURE(o);
        const double fd = o < 3 ? dp[static_cast<int>(o)] : dr[static_cast<int>(o - 3)];
        CHECK(jacobian[o * M::kNumAxes + k] == doctest::Approx(fd).epsilon(1e-7).scale(1.0));
      }
    }
  }
}

// Errors of scale s at a pose: s · (u + v · Σ_k c_k (q_k − mid_k)/half_k) per error, u, v, c drawn
// within the error's distribution spread: constant parts (PIGE-like) and parts linear in every
// axis (PDGE-like), so that the errors at the command differ from those at the target.
struct PoseErrors {
  std::vector<double> u, v;
  std::vector<std::vector<double>> c;  // [error][axis]
  std::vector<double> mid, half;
  double s = 1;

  PoseErrors(const Description& d, std::mt19937& rng) {
    std::uniform_real_distribution<double> unit(-1, 1);
    for (int b : d.axes()) {
      const Joint& j = d.bodies[b].joint;
      mid.push_back((j.min + j.max) / 2);
      half.push_back((j.max - j.min) / 2);
    }
    for (const auto& e : d.errors) {
      u.push_back(spread(e) * unit(rng));
      v.push_back(spread(e) * unit(rng));
      c.emplace_back();
      for (std::size_t k = 0; k < mid.size(); ++k) c.back().push_back(unit(rng));
    }
  }

  std::vector<double> at(const std::vector<double>& q) const {
    std::vector<double> e(u.size());
    for (std::size_t i = 0; i < e.size(); ++i) {
      double x = 0;
      for (std::size_t k = 0; k < q.size(); ++k) x += c[i][k] * (q[k] - mid[k]) / half[k];
      e[i] = s * (u[i] + v[i] * x / static_cast<double>(q.size()));
    }
    return e;
  }
};

struct PoseError {
  double position_mm = 0;
  double tool_axis_rad = 0;  // angle between the actual and the nominal tool axis (z)
  double correctable = 0;    // |Aᵀ·W·r|: the part of the weighted pose error the axes can move
};

// The true pose error of commanding `command` on the machine whose errors are `errors`, against
// the nominal pose at `target`, by the exact chain; W weighs as Compensate does.
template <typename M>
PoseError true_pose_error(const NumericChain& chain, const std::vector<double>& target,
                          const std::vector<double>& command, const std::vector<double>& errors,
                          const std::array<double, M::kNumParams>& params) {
  const Eigen::Matrix4d actual = chain.tool_in_workpiece(command, errors);
  const Eigen::Matrix4d nominal =
      chain.tool_in_workpiece(target, std::vector<double>(errors.size(), 0.0));
  const Eigen::Vector3d dp = actual.block<3, 1>(0, 3) - nominal.block<3, 1>(0, 3);
  const Eigen::Vector3d dr =
      rotation_vector(actual.block<3, 3>(0, 0) * nominal.block<3, 3>(0, 0).transpose());
  const Eigen::Vector3d z = nominal.block<3, 1>(0, 2);
  // Orientation rows: tilt of the tool axis z by L, spin about it by spin weight · L.
  const auto weigh = [&](const Eigen::Vector3d& v) -> Eigen::Vector3d {
    return M::kLengthMm * (v - (1 - M::kSpinWeight) * z * z.dot(v));
  };
  std::array<double, 6 * M::kNumAxes> j{};
  M::NominalJacobian(to_array<M::kNumAxes>(target), params, &j);
  double g2 = 0;
  for (std::size_t k = 0; k < M::kNumAxes; ++k) {
    const auto col = [&](std::size_t r) { return j[r * M::kNumAxes + k]; };
    double g = Eigen::Vector3d(col(0), col(1), col(2)).dot(dp);
    if (M::kCompensateOrientation)
      g += weigh(Eigen::Vector3d(col(3), col(4), col(5))).dot(weigh(dr));
    g2 += g * g;
  }
  const double cos_tilt = std::min(1.0, actual.block<3, 1>(0, 2).dot(z));
  return {dp.norm(), std::acos(cos_tilt), std::sqrt(g2)};
}

template <typename M>
void check_second_order() {
  const std::string name = M::kName;
  CAPTURE(name);
  const Description d = load_machine_file(test::machine_path(name));
  const NumericChain chain(d);
  const auto params = to_array<M::kNumParams>(default_params(d));
  std::mt19937 rng(23);
  const std::vector<double> scales = {1, 2, 4, 8, 16};
  double worst = 0, best_gain = 1e300;
  for (int trial = 0; trial < 4; ++trial) {
    CAPTURE(trial);
    const auto target = test::random_pose(d, rng);
    PoseErrors truth(d, rng);
    std::vector<double> compensated, correctable, uncompensated, uncompensated_correctable;
    for (double s : scales) {
      truth.s = s;
      const auto errors_at = [&](const std::array<double, M::kNumAxes>& axes,
                                 std::array<double, M::kNumErrors>* errors) {
        *errors = to_array<M::kNumErrors>(truth.at(to_vector(axes)));
      };
      std::array<double, M::kNumAxes> command{};
      const int iterations =
          M::Compensate(to_array<M::kNumAxes>(target), errors_at, params, &command);
      CAPTURE(s);
      REQUIRE(iterations >= 1);
      CHECK(iterations <= 4);
      const auto cmd = to_vector(command);
      const PoseError after = true_pose_error<M>(chain, target, cmd, truth.at(cmd), params);
      const PoseError before = true_pose_error<M>(chain, target, target, truth.at(target), params);
      compensated.push_back(after.position_mm);
      correctable.push_back(after.correctable);
      uncompensated.push_back(before.position_mm);
      uncompensated_correctable.push_back(before.correctable);
    }
    // Log-log slopes: 2 ± 0.2 compensated, 1 ± 0.1 uncompensated.
    const double slope = test::loglog_slope(scales, compensated);
    CHECK(std::abs(slope - 2) < 0.2);
    CHECK(std::abs(test::loglog_slope(scales, correctable) - 2) < 0.2);
    CHECK(std::abs(test::loglog_slope(scales, uncompensated) - 1) < 0.1);
    CHECK(std::abs(test::loglog_slope(scales, uncompensated_correctable) - 1) < 0.1);
    // At the machine's own error level the compensation removes nearly all of the error.
    CHECK(compensated[0] < 1e-2 * uncompensated[0]);
    worst = std::max(worst, std::abs(slope - 2));
    best_gain = std::min(best_gain, uncompensated[0] / compensated[0]);
  }
  MESSAGE(name << ": compensated position error slope within " << worst
               << " of 2; at s = 1 the error shrinks at least " << best_gain << "x");
}

}  // namespace

TEST_CASE("NominalPose and NominalJacobian equal the exact chain and its finite differences") {
  check_nominal_kinematics<gantry_grinder_model>();
  check_nominal_kinematics<vmc_3axis_model>();
  check_nominal_kinematics<two_axis_model>();
  check_nominal_kinematics<five_axis_ac_model>();
  check_nominal_kinematics<pipe_cutter_model>();
}

TEST_CASE("orientation rows take part exactly when some axis turns the tool") {
  CHECK_FALSE(weilgen_models::vmc_3axis::kCompensateOrientation);
  CHECK_FALSE(weilgen_models::gantry_grinder::kCompensateOrientation);
  CHECK_FALSE(weilgen_models::pipe_cutter::kCompensateOrientation);
  CHECK(weilgen_models::two_axis::kCompensateOrientation);
  CHECK(weilgen_models::five_axis_ac::kCompensateOrientation);
}

TEST_CASE("a compensated command's true pose error is second order in the errors") {
  check_second_order<vmc_3axis_model>();
  check_second_order<five_axis_ac_model>();
}

TEST_CASE("Compensate: iterations, fixed errors, failures") {
  namespace m = weilgen_models::five_axis_ac;
  const Description d = load_machine_file(test::machine_path("five_axis_ac"));
  const auto params = to_array<m::kNumParams>(default_params(d));
  std::mt19937 rng(31);
  PoseErrors truth(d, rng);
  const std::array<double, m::kNumAxes> target = {120.0, -250.0, 80.0, 35.0, 70.0};
  const auto errors = to_array<m::kNumErrors>(truth.at(to_vector(target)));
  std::array<double, m::kNumAxes> command{}, command2{};

  SUBCASE("no errors: one iteration, the target itself") {
    const std::array<double, m::kNumErrors> zero{};
    CHECK(m::Compensate(target, zero, params, &command) == 1);
    CHECK(command == target);
  }
  SUBCASE("fixed errors equal a constant callable, and converge in a few iterations") {
    const int a = m::Compensate(target, errors, params, &command);
    const int b = m::Compensate(
        target,
        [&](const std::array<double, m::kNumAxes>&, std::array<double, m::kNumErrors>* e) {
          *e = errors;
        },
        params, &command2);
    CHECK(a >= 2);
    CHECK(a <= 3);
    CHECK(a == b);
    CHECK(command == command2);
    CHECK(command != target);
  }
  SUBCASE("the five-axis machine corrects the tool point and the tool axis") {
    const NumericChain chain(d);
    REQUIRE(m::Compensate(target, errors, params, &command) >= 1);
    const std::vector<double> e(errors.begin(), errors.end()), t = to_vector(target);
    const PoseError before = true_pose_error<five_axis_ac_model>(chain, t, t, e, params);
    const PoseError after =
        true_pose_error<five_axis_ac_model>(chain, t, to_vector(command), e, params);
    CHECK(after.position_mm < 1e-4 * before.position_mm);
    CHECK(after.tool_axis_rad < 1e-2 * before.tool_axis_rad);
  }
  SUBCASE("A = 0 (C turns about the tool axis) is not singular: the spin weight") {
    auto level = target;
    level[3] = 0.0;
    CHECK(m::Compensate(level, errors, params, &command) >= 1);
  }
  SUBCASE("not converged within max_iterations: -1 and the target") {
    CHECK(m::Compensate(target, errors, params, &command, 1) == -1);
    CHECK(command == target);
  }
  SUBCASE("non-finite errors: -1 and the target") {
    auto bad = errors;
    bad[0] = std::nan("");
    CHECK(m::Compensate(target, bad, params, &command) == -1);
    CHECK(command == target);
  }
  SUBCASE("singular: the pipe cutter's axes move its working point only along z") {
    namespace p = weilgen_models::pipe_cutter;
    const Description dp = load_machine_file(test::machine_path("pipe_cutter"));
    const auto pp = to_array<p::kNumParams>(default_params(dp));
    std::mt19937 r2(3);
    const auto t = to_array<p::kNumAxes>(test::random_pose(dp, r2));
    std::array<double, p::kNumErrors> e{};
    e.fill(1e-3);
    std::array<double, p::kNumAxes> c{};
    CHECK(p::Compensate(t, e, pp, &c) == -1);
    CHECK(c == t);
  }
}

TEST_CASE("every header's compensation templates compile strictly (double and float) and run") {
  const auto dir = test::fresh_dir("compensation_strict");
  std::ofstream out(dir / "strict.cpp");
  out << "#include \"five_axis_ac.hpp\"\n#include \"gantry_grinder.hpp\"\n"
         "#include \"pipe_cutter.hpp\"\n#include \"two_axis.hpp\"\n#include \"vmc_3axis.hpp\"\n"
         "#include <cstdio>\n"
         "template <typename S, typename M> int use() {\n"
         "  std::array<S, M::kNumAxes> t{}, c{};\n"
         "  std::array<S, M::kNumErrors> e{};\n"
         "  std::array<S, M::kNumParams> p{};\n"
         "  std::array<S, 3> pos{};\n"
         "  std::array<S, 9> rot{};\n"
         "  std::array<S, 6 * M::kNumAxes> j{};\n"
         "  M::template pose<S>(t, p, &pos, &rot);\n"
         "  M::template jacobian<S>(t, p, &j);\n"
         "  const auto at = [](const std::array<S, M::kNumAxes>&, "
         "std::array<S, M::kNumErrors>* out) { out->fill(S(1e-4)); };\n"
         "  return M::template compensate<S>(t, at, p, &c, 10, S(1e-4)) + "
         "M::template compensate<S>(t, e, p, &c, 10, S(1e-4));\n"
         "}\n"
         "#define MODEL(ns) struct ns { \\\n"
         "  static constexpr std::size_t kNumAxes = weilgen_models::ns::kNumAxes; \\\n"
         "  static constexpr std::size_t kNumErrors = weilgen_models::ns::kNumErrors; \\\n"
         "  static constexpr std::size_t kNumParams = weilgen_models::ns::kNumParams; \\\n"
         "  template <typename S, typename... A> static void pose(A... a) { "
         "weilgen_models::ns::NominalPose<S>(a...); } \\\n"
         "  template <typename S, typename... A> static void jacobian(A... a) { "
         "weilgen_models::ns::NominalJacobian<S>(a...); } \\\n"
         "  template <typename S, typename... A> static int compensate(A... a) { "
         "return weilgen_models::ns::Compensate<S>(a...); } \\\n"
         "};\n"
         "MODEL(five_axis_ac) MODEL(gantry_grinder) MODEL(pipe_cutter) MODEL(two_axis) "
         "MODEL(vmc_3axis)\n"
         "int main() {\n"
         "  std::printf(\"%d %d %d %d %d\\n\", use<double, five_axis_ac>() + "
         "use<float, five_axis_ac>(), use<double, gantry_grinder>() + use<float, "
         "gantry_grinder>(), use<double, pipe_cutter>() + use<float, pipe_cutter>(), "
         "use<double, two_axis>() + use<float, two_axis>(), use<double, vmc_3axis>() + "
         "use<float, vmc_3axis>());\n"
         "}\n";
  out.close();
  const std::string exe = (dir / "strict").string();
  const test::Run c =
      test::run(std::string(WEILGEN_CXX) +
                " -std=c++17 -O1 -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Werror "
                "-fno-exceptions -fno-rtti -I" +
                std::string(WEILGEN_SOURCE_DIR) + "/generated " + (dir / "strict.cpp").string() +
                " -o " + exe);
  REQUIRE_MESSAGE(c.status == 0, c.out);
  const test::Run r = test::run(exe);
  REQUIRE(r.status == 0);
  // Pose-independent errors of 1e-4 at the zero pose: the Cartesian machines and the five-axis
  // machine converge (>= 1 per call, two calls per scalar type), the pipe cutter is singular.
  int five = 0, gantry = 0, pipe = 0, two = 0, vmc = 0;
  REQUIRE(std::sscanf(r.out.c_str(), "%d %d %d %d %d", &five, &gantry, &pipe, &two, &vmc) == 5);
  CHECK(five >= 4);
  CHECK(gantry >= 4);
  CHECK(pipe == -4);
  CHECK(two >= 4);
  CHECK(vmc >= 4);
}
