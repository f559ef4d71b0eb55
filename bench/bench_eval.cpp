// Evaluation cost per pose: the generated closed forms (generated/<machine>.hpp, order 1 as
// shipped) against what a competent engineer writes by hand, side by side per shipped machine, in
// one run (docs/performance.md, "Evaluation"). One benchmark iteration is one pose
// (items/s = poses/s):
//
//   generated_dev           Deviation (position + orientation)
//   generated_coeff         Coefficients (6 x n first-order coefficients)
//   generated_dev+coeff     Deviation then Coefficients: two calls
//   generated_combined      DeviationAndCoefficients: the same outputs in one call
//   generated_pack          DeviationAndCoefficients<Pack<kLanes>>: kLanes poses per call, one per
//                           SIMD lane (kLanes = 8 with AVX-512, 4 with AVX, else 2: what the
//                           build's flags give); one iteration = kLanes poses, the summary divides
//                           by kLanes
//   output_floor_pack       its store floor: the same number of packs stored, one full-width store
//                           each (no loads: a table of the pipe cutter's would not stay in L1)
//   output_floor_pack+sincos  the same plus Pack's sin and cos of every rotary axis
//   output_floor            the load/store floor of those outputs: their 6 + 6n values, computed
//                           before timing, copied from an L1-resident table into the same arrays
//                           by 16-byte loads and stores (no code producing them can be faster)
//   output_floor+sincos     the same copy plus sin and cos of every rotary axis value of the
//                           pose: no code computing the outputs with the C library's sin/cos
//                           can be faster on a machine with rotary axes
//   eigen_dev               (a) the exact deviation from a fixed-size Eigen chain compiled from the
//                           machine description at set-up (3x3 rotations and 3-vectors, no
//                           allocation): actual and nominal pose, AngleAxis of R R0^T
//   analytic_coeff          (b) the hand-derived first-order Jacobian: one nominal pass recording
//                           the pose of every error, each column from the adjoint (twist) formula
//   eigen_dev+analytic_coeff (a) + (b) sharing the nominal pass
//   extra_chain_dev+fd_coeff labelled extra, the old baseline: weilgen::NumericChain (written for
//                           clarity, not speed) with central differences (2n + 3 chain evaluations)
//
// Poses (axes within their ranges, errors of realistic size) are drawn once, before timing, and
// cycled through; no timed loop allocates. Before timing, every machine is checked: the Eigen
// chain's deviation equals NumericChain::deviation to rounding, the analytic Jacobian equals the
// generated Coefficients to rounding, the generated deviation equals the exact one to O(e^2),
// DeviationAndCoefficients equals the two separate calls. After the run a Markdown table of CPU
// ns/pose and ratios is printed, with DeviationAndCoefficients against both floors.
// pipe_cutter's output transform (linked jaws, derived quantities) is not a serial chain: its
// baseline is written by hand for it (pipe_cutter_baseline.hpp).
#include <benchmark/benchmark.h>
#include <unistd.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "five_axis_ac.hpp"
#include "gantry_grinder.hpp"
#include "head_head_bc.hpp"
#include "pipe_cutter.hpp"
#include "pipe_cutter_baseline.hpp"
#include "two_axis.hpp"
#include "vmc_3axis.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/model/numeric_chain.hpp"

namespace {

constexpr std::size_t kNumPoses = 1024;  // power of two: the pose index wraps with a mask
#if defined(__AVX512F__)
constexpr std::size_t kLanes = 8;  // doubles per SIMD register of the build's target
#elif defined(__AVX__)
constexpr std::size_t kLanes = 4;
#else
constexpr std::size_t kLanes = 2;
#endif
using Lanes = weilgen_models::Pack<kLanes>;
constexpr double kFdStep = 1e-6;  // central-difference step, base units (mm, rad)

using Eigen::Matrix3d;
using Eigen::Vector3d;

// ---- (a), (b): the hand-written baseline ----------------------------------------------------

// A serial machine's chain compiled once from its description into a list of steps, evaluated
// with fixed-size Eigen types (a rigid pose as a 3x3 rotation and a 3-vector, the product of
// Isometry3d without the homogeneous row). Body transform as in docs/generator.md:
// Offset · E_before · E_axis · J(q) · E_axis^-1 · E_after; P = W^-1 T.
class FixedChain {
 public:
  struct Pose {
    Matrix3d R = Matrix3d::Identity();
    Vector3d p = Vector3d::Zero();
  };
  // Per error step: its pose in the base frame at zero error, recorded by the nominal pass.
  struct Workspace {
    std::vector<Pose> at;
  };

  explicit FixedChain(const weilgen::Description& d) : num_errors_(d.errors.size()) {
    if (!d.linked_axes().empty() || d.output)
      throw std::invalid_argument(d.name + ": not a serial chain (links or an output transform)");
    const std::map<std::string, double> params = d.parameter_defaults();
    const std::vector<int> axes = d.axes();
    auto vec = [](const weilgen::Vec3& v) { return Vector3d(v[0], v[1], v[2]); };
    auto eval = [&](const std::array<weilgen::Expr, 3>& e) {
      return Vector3d(e[0].eval(params), e[1].eval(params), e[2].eval(params));
    };
    auto branch = [&](const weilgen::PointSpec& end, bool tool, std::vector<Step>& steps) {
      auto fixed = [&](const Pose& f) {
        if (!steps.empty() && steps.back().kind == Step::Fixed) {  // merge neighbours
          Step& b = steps.back();
          b.fixed.p += b.fixed.R * f.p;
          b.fixed.R = b.fixed.R * f.R;
        } else {
          Step s;
          s.kind = Step::Fixed;
          s.fixed = f;
          steps.push_back(s);
        }
      };
      auto errors = [&](int body, weilgen::ErrorPlacement where, bool inverse) {
        std::vector<int> list;
        for (int e : d.bodies[static_cast<std::size_t>(body)].errors)
          if (d.errors[static_cast<std::size_t>(e)].placement == where) list.push_back(e);
        if (inverse) std::reverse(list.begin(), list.end());
        for (int e : list) {
          const weilgen::ErrorDef& def = d.errors[static_cast<std::size_t>(e)];
          Step s;
          s.kind = def.effect == weilgen::ErrorEffect::Rotation ? Step::ErrorRotation
                                                                : Step::ErrorTranslation;
          s.u = vec(def.direction).normalized();
          s.index = e;
          s.sign = (inverse ? -1.0 : 1.0);
          s.jac_sign = s.sign * (tool ? 1.0 : -1.0);
          s.slot = num_slots_++;
          steps.push_back(s);
        }
      };
      for (int b : d.chain_to(end.body)) {
        const weilgen::Body& body = d.bodies[static_cast<std::size_t>(b)];
        Pose off;
        off.p = eval(body.offset.translation);
        for (const auto& r : body.offset.rotations)
          off.R = off.R * Eigen::AngleAxisd(r.angle_deg.eval(params) * M_PI / 180.0,
                                            vec(r.axis).normalized())
                              .toRotationMatrix();
        fixed(off);
        errors(b, weilgen::ErrorPlacement::Before, false);
        errors(b, weilgen::ErrorPlacement::Axis, false);
        if (body.joint.type != weilgen::JointType::Fixed) {
          Step s;
          s.kind =
              body.joint.type == weilgen::JointType::Prismatic ? Step::Prismatic : Step::Revolute;
          s.u = vec(body.joint.axis).normalized();
          s.to_base = body.joint.to_base;
          s.index = static_cast<int>(std::find(axes.begin(), axes.end(), b) - axes.begin());
          s.through = eval(body.joint.through);
          steps.push_back(s);
        }
        errors(b, weilgen::ErrorPlacement::Axis, true);
        errors(b, weilgen::ErrorPlacement::After, false);
      }
      Pose point;
      point.p = eval(end.point);
      fixed(point);
    };
    branch(d.tool, true, tool_);
    branch(d.workpiece, false, work_);
  }

  Workspace workspace() const { return Workspace{std::vector<Pose>(num_slots_)}; }

  // The exact deviation (dx, dy, dz mm; da, db, dc rad), as NumericChain::deviation computes it.
  void deviation(const double* axes, const double* errors, double* out6) const {
    const Pose actual =
        relative(run(tool_, axes, errors, nullptr), run(work_, axes, errors, nullptr));
    const Pose nominal =
        relative(run(tool_, axes, nullptr, nullptr), run(work_, axes, nullptr, nullptr));
    finish(actual, nominal, out6);
  }

  // d(deviation)/d(error) at zero error, row-major [6][n].
  void coefficients(Workspace& ws, const double* axes, double* coeff) const {
    const Pose t = run(tool_, axes, nullptr, &ws), w = run(work_, axes, nullptr, &ws);
    jacobian(ws, t, w, coeff);
  }

  // Both, sharing the nominal pass.
  void deviation_and_coefficients(Workspace& ws, const double* axes, const double* errors,
                                  double* out6, double* coeff) const {
    const Pose t = run(tool_, axes, nullptr, &ws), w = run(work_, axes, nullptr, &ws);
    const Pose actual =
        relative(run(tool_, axes, errors, nullptr), run(work_, axes, errors, nullptr));
    finish(actual, relative(t, w), out6);
    jacobian(ws, t, w, coeff);
  }

 private:
  struct Step {
    enum Kind { Fixed, Prismatic, Revolute, ErrorTranslation, ErrorRotation } kind = Fixed;
    Pose fixed;
    Vector3d u = Vector3d::Zero(), through = Vector3d::Zero();
    double to_base = 1, sign = 1, jac_sign = 1;
    int index = -1;        // axis index (joints) or error index
    std::size_t slot = 0;  // error steps: index into Workspace::at
  };

  // The branch's pose in the base frame; errors == nullptr: nominal (error steps skipped, their
  // poses recorded into ws when given).
  static Pose run(const std::vector<Step>& steps, const double* axes, const double* errors,
                  Workspace* ws) {
    Pose m;
    for (const Step& s : steps) {
      switch (s.kind) {
        case Step::Fixed:
          m.p += m.R * s.fixed.p;
          m.R = m.R * s.fixed.R;
          break;
        case Step::Prismatic:
          m.p += (axes[s.index] * s.to_base) * (m.R * s.u);
          break;
        case Step::Revolute: {
          const Matrix3d r = Eigen::AngleAxisd(axes[s.index] * s.to_base, s.u).toRotationMatrix();
          m.p += m.R * (s.through - r * s.through);
          m.R = m.R * r;
          break;
        }
        case Step::ErrorTranslation:
          if (errors) m.p += (s.sign * errors[s.index]) * (m.R * s.u);
          if (ws) ws->at[s.slot] = m;
          break;
        case Step::ErrorRotation:
          if (errors)
            m.R = m.R * Eigen::AngleAxisd(s.sign * errors[s.index], s.u).toRotationMatrix();
          if (ws) ws->at[s.slot] = m;
          break;
      }
    }
    return m;
  }

  static Pose relative(const Pose& t, const Pose& w) {  // W^-1 T
    Pose p;
    p.R = w.R.transpose() * t.R;
    p.p = w.R.transpose() * (t.p - w.p);
    return p;
  }

  static void finish(const Pose& actual, const Pose& nominal, double* out6) {
    const Vector3d dp = actual.p - nominal.p;
    const Eigen::AngleAxisd aa(Matrix3d(actual.R * nominal.R.transpose()));
    const Vector3d w = aa.angle() * aa.axis();
    for (int i = 0; i < 3; ++i) {
      out6[i] = dp[i];
      out6[3 + i] = w[i];
    }
  }

  // Error k acts at pose A_k (base frame) as exp(e ξ^) with ξ a translation or rotation along u.
  // dP·P0^-1 = ±(Ad_{W0^-1 A_k} ξ)^ (+ on the tool side; − on the workpiece side, where W is
  // inverted; an axis error's inverse step counts with the opposite sign), so in the base frame
  // with w = R_A u: translation dp = w; rotation dω = w, dp = w × (p_T − p_A). Rotated into the
  // workpiece frame by R_W^T at the end.
  void jacobian(const Workspace& ws, const Pose& t, const Pose& w, double* coeff) const {
    const std::size_t n = num_errors_;
    std::fill(coeff, coeff + 6 * n, 0.0);
    const auto add = [&](const std::vector<Step>& steps) {
      for (const Step& s : steps) {
        if (s.kind != Step::ErrorTranslation && s.kind != Step::ErrorRotation) continue;
        const Pose& a = ws.at[s.slot];
        const Vector3d u = s.jac_sign * (a.R * s.u);
        const auto j = static_cast<std::size_t>(s.index);
        if (s.kind == Step::ErrorTranslation) {
          for (int i = 0; i < 3; ++i) coeff[i * n + j] += u[i];
        } else {
          const Vector3d v = u.cross(t.p - a.p);
          for (int i = 0; i < 3; ++i) {
            coeff[i * n + j] += v[i];
            coeff[(3 + i) * n + j] += u[i];
          }
        }
      }
    };
    add(tool_);
    add(work_);
    // Into the workpiece frame: every column (position and orientation part) times R_W^T.
    const Matrix3d rt = w.R.transpose();
    for (std::size_t half = 0; half < 2; ++half) {
      double* c = coeff + 3 * half * n;
      for (std::size_t j = 0; j < n; ++j) {
        const Vector3d v = rt * Vector3d(c[j], c[n + j], c[2 * n + j]);
        c[j] = v[0];
        c[n + j] = v[1];
        c[2 * n + j] = v[2];
      }
    }
  }

  std::size_t num_errors_;
  std::size_t num_slots_ = 0;
  std::vector<Step> tool_, work_;
};

// ---- the generated models -------------------------------------------------------------------

// One generated model namespace as a type, so that the benchmarks can be templates.
#define WEILGEN_BENCH_MODEL(NS, BASELINE)                                     \
  struct NS##_model {                                                         \
    using Baseline = BASELINE;                                                \
    static constexpr const char* kName = #NS;                                 \
    static constexpr std::size_t kNumAxes = weilgen_models::NS::kNumAxes;     \
    static constexpr std::size_t kNumErrors = weilgen_models::NS::kNumErrors; \
    static constexpr std::size_t kNumParams = weilgen_models::NS::kNumParams; \
    static constexpr const auto& kAxes = weilgen_models::NS::kAxes;           \
    static constexpr const auto& kErrors = weilgen_models::NS::kErrors;       \
    static constexpr const auto& kParams = weilgen_models::NS::kParams;       \
    template <typename... Args>                                               \
    static void Deviation(const Args&... args) {                              \
      weilgen_models::NS::Deviation<double>(args...);                         \
    }                                                                         \
    template <typename... Args>                                               \
    static void Coefficients(const Args&... args) {                           \
      weilgen_models::NS::Coefficients<double>(args...);                      \
    }                                                                         \
    template <typename... Args>                                               \
    static void DeviationAndCoefficients(const Args&... args) {               \
      weilgen_models::NS::DeviationAndCoefficients<double>(args...);          \
    }                                                                         \
    template <typename... Args>                                               \
    static void DeviationAndCoefficientsPack(const Args&... args) {           \
      weilgen_models::NS::DeviationAndCoefficients<Lanes>(args...);           \
    }                                                                         \
  }

WEILGEN_BENCH_MODEL(gantry_grinder, FixedChain);
WEILGEN_BENCH_MODEL(vmc_3axis, FixedChain);
WEILGEN_BENCH_MODEL(two_axis, FixedChain);
WEILGEN_BENCH_MODEL(five_axis_ac, FixedChain);
WEILGEN_BENCH_MODEL(head_head_bc, FixedChain);
WEILGEN_BENCH_MODEL(pipe_cutter, PipeCutterBaseline);

#undef WEILGEN_BENCH_MODEL

// The precomputed poses of one machine, in the generated layout and in the chain's layout.
template <typename M>
struct PoseSet {
  std::vector<std::array<double, M::kNumAxes>> axes;
  std::vector<std::array<double, M::kNumErrors>> errors;
  std::array<double, M::kNumParams> params{};
  // The same poses kLanes at a time, pose p in lane p % kLanes of pack p / kLanes.
  std::vector<std::array<Lanes, M::kNumAxes>> pack_axes;
  std::vector<std::array<Lanes, M::kNumErrors>> pack_errors;
  std::array<Lanes, M::kNumParams> pack_params{};
  std::vector<std::vector<double>> chain_axes;
  std::vector<std::vector<double>> chain_errors;
  weilgen::NumericChain chain;
  typename M::Baseline fixed;

  PoseSet()
      : chain(weilgen::load_machine_file(weilgen::resolve_machine(M::kName))),
        fixed(chain.description()) {
    std::mt19937 rng(20240611u);
    for (std::size_t k = 0; k < M::kNumParams; ++k) params[k] = M::kParams[k].default_value;
    axes.resize(kNumPoses);
    errors.resize(kNumPoses);
    for (std::size_t p = 0; p < kNumPoses; ++p) {
      for (std::size_t k = 0; k < M::kNumAxes; ++k)
        axes[p][k] = std::uniform_real_distribution<double>(M::kAxes[k].min, M::kAxes[k].max)(rng);
      // Translations within +-10 um, rotations within +-50 urad (base units mm, rad).
      for (std::size_t k = 0; k < M::kNumErrors; ++k)
        errors[p][k] = std::uniform_real_distribution<double>(-1, 1)(rng) *
                       (M::kErrors[k].rotation ? 50e-6 : 10e-3);
      chain_axes.emplace_back(axes[p].begin(), axes[p].end());
      chain_errors.emplace_back(errors[p].begin(), errors[p].end());
    }
    pack_axes.resize(kNumPoses / kLanes);
    pack_errors.resize(kNumPoses / kLanes);
    for (std::size_t p = 0; p < kNumPoses; ++p) {
      for (std::size_t k = 0; k < M::kNumAxes; ++k)
        pack_axes[p / kLanes][k].Set(p % kLanes, axes[p][k]);
      for (std::size_t k = 0; k < M::kNumErrors; ++k)
        pack_errors[p / kLanes][k].Set(p % kLanes, errors[p][k]);
    }
    for (std::size_t k = 0; k < M::kNumParams; ++k) pack_params[k] = Lanes(params[k]);
  }
};

template <typename M>
const PoseSet<M>& poses() {
  static const PoseSet<M> set;
  return set;
}

// Deviation of `actual` from `nominal` exactly as NumericChain::deviation computes it.
std::array<double, 6> deviation_between(const Eigen::Matrix4d& actual,
                                        const Eigen::Matrix4d& nominal) {
  const Eigen::Vector3d dp = actual.block<3, 1>(0, 3) - nominal.block<3, 1>(0, 3);
  const Eigen::Matrix3d dr = actual.block<3, 3>(0, 0) * nominal.block<3, 3>(0, 0).transpose();
  const Eigen::AngleAxisd aa(dr);
  const Eigen::Vector3d w = aa.angle() * aa.axis();
  return {dp[0], dp[1], dp[2], w[0], w[1], w[2]};
}

// The 6 x n first-order coefficients at zero error, row-major [output][error], by central
// differences of the chain: 2n + 1 chain evaluations. `scratch` holds n zeros on entry and exit.
void fd_coefficients(const weilgen::NumericChain& chain, const std::vector<double>& axes,
                     std::vector<double>& scratch, std::vector<double>& coeff) {
  const std::size_t n = scratch.size();
  const Eigen::Matrix4d nominal = chain.tool_in_workpiece(axes, scratch);
  for (std::size_t j = 0; j < n; ++j) {
    scratch[j] = kFdStep;
    const std::array<double, 6> plus =
        deviation_between(chain.tool_in_workpiece(axes, scratch), nominal);
    scratch[j] = -kFdStep;
    const std::array<double, 6> minus =
        deviation_between(chain.tool_in_workpiece(axes, scratch), nominal);
    scratch[j] = 0.0;
    for (std::size_t o = 0; o < 6; ++o) coeff[o * n + j] = (plus[o] - minus[o]) / (2 * kFdStep);
  }
}

// ---- benchmarks: one iteration = one pose ----

template <typename M>
void BM_GeneratedDeviation(benchmark::State& state) {
  const PoseSet<M>& s = poses<M>();
  std::array<double, 3> position{}, orientation{};
  std::size_t p = 0;
  for (auto _ : state) {
    M::Deviation(s.axes[p], s.errors[p], s.params, &position, &orientation);
    benchmark::DoNotOptimize(position);
    benchmark::DoNotOptimize(orientation);
    p = (p + 1) & (kNumPoses - 1);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}

template <typename M>
void BM_GeneratedCoefficients(benchmark::State& state) {
  const PoseSet<M>& s = poses<M>();
  std::array<double, 3 * M::kNumErrors> position_coeff{}, orientation_coeff{};
  std::size_t p = 0;
  for (auto _ : state) {
    M::Coefficients(s.axes[p], s.params, &position_coeff, &orientation_coeff);
    benchmark::DoNotOptimize(position_coeff);
    benchmark::DoNotOptimize(orientation_coeff);
    p = (p + 1) & (kNumPoses - 1);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}

template <typename M>
void BM_GeneratedDeviationCoefficients(benchmark::State& state) {
  const PoseSet<M>& s = poses<M>();
  std::array<double, 3> position{}, orientation{};
  std::array<double, 3 * M::kNumErrors> position_coeff{}, orientation_coeff{};
  std::size_t p = 0;
  for (auto _ : state) {
    M::Deviation(s.axes[p], s.errors[p], s.params, &position, &orientation);
    M::Coefficients(s.axes[p], s.params, &position_coeff, &orientation_coeff);
    benchmark::DoNotOptimize(position);
    benchmark::DoNotOptimize(orientation);
    benchmark::DoNotOptimize(position_coeff);
    benchmark::DoNotOptimize(orientation_coeff);
    p = (p + 1) & (kNumPoses - 1);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}

template <typename M>
void BM_GeneratedCombined(benchmark::State& state) {
  const PoseSet<M>& s = poses<M>();
  std::array<double, 3> position{}, orientation{};
  std::array<double, 3 * M::kNumErrors> position_coeff{}, orientation_coeff{};
  std::size_t p = 0;
  for (auto _ : state) {
    M::DeviationAndCoefficients(s.axes[p], s.errors[p], s.params, &position, &orientation,
                                &position_coeff, &orientation_coeff);
    benchmark::DoNotOptimize(position);
    benchmark::DoNotOptimize(orientation);
    benchmark::DoNotOptimize(position_coeff);
    benchmark::DoNotOptimize(orientation_coeff);
    p = (p + 1) & (kNumPoses - 1);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}

// kLanes poses per iteration, in the layout Pack wants (built before timing, as the per-pose
// benchmarks' inputs are): the outputs stay in packs, lane l the pose of lane l.
template <typename M>
void BM_GeneratedPack(benchmark::State& state) {
  const PoseSet<M>& s = poses<M>();
  std::array<Lanes, 3> position{}, orientation{};
  std::array<Lanes, 3 * M::kNumErrors> position_coeff{}, orientation_coeff{};
  std::size_t p = 0;
  for (auto _ : state) {
    M::DeviationAndCoefficientsPack(s.pack_axes[p], s.pack_errors[p], s.pack_params, &position,
                                    &orientation, &position_coeff, &orientation_coeff);
    benchmark::DoNotOptimize(position);
    benchmark::DoNotOptimize(orientation);
    benchmark::DoNotOptimize(position_coeff);
    benchmark::DoNotOptimize(orientation_coeff);
    p = (p + 1) & (kNumPoses / kLanes - 1);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * kLanes));
}

// The load/store floor of DeviationAndCoefficients' outputs: per pose, its 6 + 6n outputs
// (computed before timing) copied from a table into the same four arrays the generated function
// writes. No code that computes these outputs can store them faster; the table's loads are what
// the generated code spends reading its n + axes inputs instead. The table holds the first
// kFloorRows poses (a few KiB, in L1 like the generated code's inputs and constants: all 1024
// would be 1-2 MiB and measure the cache instead).
constexpr std::size_t kFloorRows = 4;

// dst = src by 16-byte loads and stores (what a compiler emits for a known small array; a plain
// assignment of these sizes becomes `rep movsq`, whose start-up costs more than the copy).
template <std::size_t N>
void copy_block(std::array<double, N>& dst, const std::array<double, N>& src) {
#if defined(__SSE2__)
  std::size_t i = 0;
#pragma GCC unroll 256
  for (; i + 2 <= N; i += 2) _mm_storeu_pd(dst.data() + i, _mm_loadu_pd(src.data() + i));
  if (i < N) dst[i] = src[i];
#else
  for (std::size_t i = 0; i < N; ++i) dst[i] = src[i];
#endif
}

template <typename M>
struct OutputTable {
  struct Row {
    std::array<double, 3> position, orientation;
    std::array<double, 3 * M::kNumErrors> position_coeff, orientation_coeff;
  };
  std::vector<Row> rows;
  OutputTable() : rows(kFloorRows) {
    const PoseSet<M>& s = poses<M>();
    for (std::size_t p = 0; p < kFloorRows; ++p)
      M::DeviationAndCoefficients(s.axes[p], s.errors[p], s.params, &rows[p].position,
                                  &rows[p].orientation, &rows[p].position_coeff,
                                  &rows[p].orientation_coeff);
  }
};

// The same floor for Pack<kLanes>: kLanes poses' outputs stored as packs, one full-width store
// each, of a value that changes per iteration (one iteration = kLanes poses). A copy from a table
// would measure the cache instead: the pipe cutter's outputs are 27 KiB per call at 8 lanes, a
// table of them and the destination do not fit in L1 together. No code writing these outputs as
// packs can store them faster.
template <std::size_t N>
void fill_packs(std::array<Lanes, N>& dst, const Lanes& value) {
#pragma GCC unroll 256
  for (std::size_t i = 0; i < N; ++i) dst[i] = value;
}

// kSinCos: plus Pack's sin and cos of every revolute axis (in rad), as the generated code calls
// them, over the same packs of poses as generated_pack.
template <typename M, bool kSinCos>
void BM_OutputFloorPack(benchmark::State& state) {
  [[maybe_unused]] const PoseSet<M>& s = poses<M>();
  std::array<Lanes, 3> position{}, orientation{};
  std::array<Lanes, 3 * M::kNumErrors> position_coeff{}, orientation_coeff{};
  double p = 0;
  std::size_t pack = 0;
  for (auto _ : state) {
    Lanes value(p);
    if constexpr (kSinCos) {
      using std::cos;
      using std::sin;
      for (std::size_t k = 0; k < M::kNumAxes; ++k)
        if (M::kAxes[k].revolute) {
          const Lanes angle = s.pack_axes[pack][k] * Lanes(M::kAxes[k].to_base);
          value += cos(angle) + sin(angle);
        }
      pack = (pack + 1) & (kNumPoses / kLanes - 1);
    }
    fill_packs(position, value);
    fill_packs(orientation, value);
    fill_packs(position_coeff, value);
    fill_packs(orientation_coeff, value);
    benchmark::DoNotOptimize(position);
    benchmark::DoNotOptimize(orientation);
    benchmark::DoNotOptimize(position_coeff);
    benchmark::DoNotOptimize(orientation_coeff);
    p += 1;
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * kLanes));
}

// kSinCos: the output floor plus what no code can skip on a machine with rotary axes, sin and
// cos of every revolute axis value of the pose (in rad), called as the generated code calls them
// (the compiler pairs them into one sincos there and here alike). The axis values cycle through
// the same 1024 poses as the generated benchmarks (the cost of sin/cos depends on the argument).
// Without revolute axes the two floors are the same loop.
template <typename M, bool kSinCos>
void BM_OutputFloor(benchmark::State& state) {
  static const OutputTable<M> table;
  [[maybe_unused]] const PoseSet<M>& s = poses<M>();
  std::array<double, 3> position{}, orientation{};
  std::array<double, 3 * M::kNumErrors> position_coeff{}, orientation_coeff{};
  std::size_t p = 0;
  for (auto _ : state) {
    if constexpr (kSinCos)
      for (std::size_t k = 0; k < M::kNumAxes; ++k)
        if (M::kAxes[k].revolute) {
          const double angle = s.axes[p][k] * M::kAxes[k].to_base;
          double c = std::cos(angle), si = std::sin(angle);
          benchmark::DoNotOptimize(c);
          benchmark::DoNotOptimize(si);
        }
    const auto& row = table.rows[p & (kFloorRows - 1)];
    copy_block(position, row.position);
    copy_block(orientation, row.orientation);
    copy_block(position_coeff, row.position_coeff);
    copy_block(orientation_coeff, row.orientation_coeff);
    benchmark::DoNotOptimize(position);
    benchmark::DoNotOptimize(orientation);
    benchmark::DoNotOptimize(position_coeff);
    benchmark::DoNotOptimize(orientation_coeff);
    p = (p + 1) & (kNumPoses - 1);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}

template <typename M>
void BM_EigenDeviation(benchmark::State& state) {
  const PoseSet<M>& s = poses<M>();
  std::array<double, 6> dev{};
  std::size_t p = 0;
  for (auto _ : state) {
    s.fixed.deviation(s.axes[p].data(), s.errors[p].data(), dev.data());
    benchmark::DoNotOptimize(dev);
    p = (p + 1) & (kNumPoses - 1);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}

template <typename M>
void BM_AnalyticCoefficients(benchmark::State& state) {
  const PoseSet<M>& s = poses<M>();
  auto ws = s.fixed.workspace();
  std::array<double, 6 * M::kNumErrors> coeff{};
  std::size_t p = 0;
  for (auto _ : state) {
    s.fixed.coefficients(ws, s.axes[p].data(), coeff.data());
    benchmark::DoNotOptimize(coeff);
    p = (p + 1) & (kNumPoses - 1);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}

template <typename M>
void BM_EigenDeviationAnalyticCoefficients(benchmark::State& state) {
  const PoseSet<M>& s = poses<M>();
  auto ws = s.fixed.workspace();
  std::array<double, 6> dev{};
  std::array<double, 6 * M::kNumErrors> coeff{};
  std::size_t p = 0;
  for (auto _ : state) {
    s.fixed.deviation_and_coefficients(ws, s.axes[p].data(), s.errors[p].data(), dev.data(),
                                       coeff.data());
    benchmark::DoNotOptimize(dev);
    benchmark::DoNotOptimize(coeff);
    p = (p + 1) & (kNumPoses - 1);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}

template <typename M>
void BM_ChainDeviationFdCoefficients(benchmark::State& state) {
  const PoseSet<M>& s = poses<M>();
  std::vector<double> scratch(M::kNumErrors, 0.0), coeff(6 * M::kNumErrors, 0.0);
  std::size_t p = 0;
  for (auto _ : state) {
    std::array<double, 6> dev = s.chain.deviation(s.chain_axes[p], s.chain_errors[p]);
    fd_coefficients(s.chain, s.chain_axes[p], scratch, coeff);
    benchmark::DoNotOptimize(dev);
    benchmark::DoNotOptimize(coeff.data());
    benchmark::ClobberMemory();
    p = (p + 1) & (kNumPoses - 1);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}

// ---- every side must compute the same thing ----

template <typename M>
bool check_agreement() {
  const PoseSet<M>& s = poses<M>();
  const weilgen::Description& d = s.chain.description();
  bool ok = d.errors.size() == M::kNumErrors && d.axes().size() == M::kNumAxes &&
            d.parameters.size() == M::kNumParams;
  for (std::size_t k = 0; ok && k < M::kNumErrors; ++k) ok = d.errors[k].name == M::kErrors[k].name;
  for (std::size_t k = 0; ok && k < M::kNumAxes; ++k)
    ok = d.bodies[d.axes()[k]].joint.coordinate == M::kAxes[k].name;
  for (std::size_t k = 0; ok && k < M::kNumParams; ++k)
    ok = d.parameters[k].name == M::kParams[k].name;
  if (!ok) {
    std::fprintf(stderr, "%s: generated metadata does not match the machine file\n", M::kName);
    return false;
  }
  constexpr std::size_t n = M::kNumErrors;
  double eigen_diff = 0, dev_max = 0, gen_diff = 0, coeff_diff = 0, coeff_max = 0, fd_diff = 0,
         combined_diff = 0, pack_diff = 0;
  auto ws = s.fixed.workspace();
  std::array<Lanes, 3> pack_position{}, pack_orientation{};
  std::array<Lanes, 3 * n> pack_pc{}, pack_oc{};
  std::vector<double> scratch(n, 0.0), fd(6 * n, 0.0);
  for (std::size_t p = 0; p < 64; ++p) {
    std::array<double, 3> position{}, orientation{}, position2{}, orientation2{};
    std::array<double, 3 * n> pc{}, oc{}, pc2{}, oc2{};
    M::Deviation(s.axes[p], s.errors[p], s.params, &position, &orientation);
    M::Coefficients(s.axes[p], s.params, &pc, &oc);
    M::DeviationAndCoefficients(s.axes[p], s.errors[p], s.params, &position2, &orientation2, &pc2,
                                &oc2);
    const std::size_t lane = p % kLanes;
    if (lane == 0)
      M::DeviationAndCoefficientsPack(s.pack_axes[p / kLanes], s.pack_errors[p / kLanes],
                                      s.pack_params, &pack_position, &pack_orientation, &pack_pc,
                                      &pack_oc);
    std::array<double, 6> eigen{}, eigen2{};
    std::array<double, 6 * n> analytic{}, analytic2{};
    s.fixed.deviation(s.axes[p].data(), s.errors[p].data(), eigen.data());
    s.fixed.coefficients(ws, s.axes[p].data(), analytic.data());
    s.fixed.deviation_and_coefficients(ws, s.axes[p].data(), s.errors[p].data(), eigen2.data(),
                                       analytic2.data());
    const std::array<double, 6> chain = s.chain.deviation(s.chain_axes[p], s.chain_errors[p]);
    if (p < 8) fd_coefficients(s.chain, s.chain_axes[p], scratch, fd);
    for (std::size_t o = 0; o < 6; ++o) {
      const double g = o < 3 ? position[o] : orientation[o - 3];
      const double g2 = o < 3 ? position2[o] : orientation2[o - 3];
      dev_max = std::max(dev_max, std::abs(chain[o]));
      eigen_diff =
          std::max({eigen_diff, std::abs(eigen[o] - chain[o]), std::abs(eigen2[o] - eigen[o])});
      gen_diff = std::max(gen_diff, std::abs(g - chain[o]));
      combined_diff = std::max(combined_diff, std::abs(g2 - g));
      pack_diff = std::max(
          pack_diff, std::abs((o < 3 ? pack_position[o] : pack_orientation[o - 3]).Get(lane) - g2));
      for (std::size_t j = 0; j < n; ++j) {
        const std::size_t r = (o % 3) * n + j;
        const double c = o < 3 ? pc[r] : oc[r], c2 = o < 3 ? pc2[r] : oc2[r];
        coeff_max = std::max(coeff_max, std::abs(c));
        coeff_diff = std::max({coeff_diff, std::abs(c - analytic[o * n + j]),
                               std::abs(analytic2[o * n + j] - analytic[o * n + j])});
        combined_diff = std::max(combined_diff, std::abs(c2 - c));
        pack_diff = std::max(pack_diff, std::abs((o < 3 ? pack_pc[r] : pack_oc[r]).Get(lane) - c2));
        if (p < 8) fd_diff = std::max(fd_diff, std::abs(c - fd[o * n + j]));
      }
    }
  }
  // Exact sides to rounding; the order-1 model against the exact chain to O(e^2).
  ok = eigen_diff <= 1e-12 * std::max(1.0, dev_max) && coeff_diff <= 1e-12 * coeff_max &&
       combined_diff <= 1e-12 * std::max(coeff_max, dev_max) &&
       pack_diff <= 1e-12 * std::max(coeff_max, dev_max) && gen_diff <= 1e-3 * dev_max &&
       fd_diff <= 1e-6 * std::max(1.0, coeff_max);
  std::fprintf(stderr,
               "check %-15s |eigen - NumericChain| %.1e, |analytic - Coefficients| %.1e (max "
               "|coeff| %.3g), |combined - separate| %.1e, |Pack<%zu> lane - combined| %.1e, "
               "|Deviation - exact| %.1e (max |dev| %.3g, O(e^2)), |Coefficients - FD| %.1e: %s\n",
               M::kName, eigen_diff, coeff_diff, coeff_max, combined_diff, kLanes, pack_diff,
               gen_diff, dev_max, fd_diff, ok ? "ok" : "MISMATCH");
  return ok;
}

template <typename M>
void register_machine() {
  const std::string m = M::kName;
  benchmark::RegisterBenchmark((m + "/generated_dev").c_str(), BM_GeneratedDeviation<M>);
  benchmark::RegisterBenchmark((m + "/generated_coeff").c_str(), BM_GeneratedCoefficients<M>);
  benchmark::RegisterBenchmark((m + "/generated_dev+coeff").c_str(),
                               BM_GeneratedDeviationCoefficients<M>);
  benchmark::RegisterBenchmark((m + "/generated_combined").c_str(), BM_GeneratedCombined<M>);
  benchmark::RegisterBenchmark((m + "/generated_pack").c_str(), BM_GeneratedPack<M>);
  benchmark::RegisterBenchmark((m + "/output_floor_pack").c_str(), BM_OutputFloorPack<M, false>);
  benchmark::RegisterBenchmark((m + "/output_floor_pack+sincos").c_str(),
                               BM_OutputFloorPack<M, true>);
  benchmark::RegisterBenchmark((m + "/output_floor").c_str(), BM_OutputFloor<M, false>);
  benchmark::RegisterBenchmark((m + "/output_floor+sincos").c_str(), BM_OutputFloor<M, true>);
  benchmark::RegisterBenchmark((m + "/eigen_dev").c_str(), BM_EigenDeviation<M>);
  benchmark::RegisterBenchmark((m + "/analytic_coeff").c_str(), BM_AnalyticCoefficients<M>);
  benchmark::RegisterBenchmark((m + "/eigen_dev+analytic_coeff").c_str(),
                               BM_EigenDeviationAnalyticCoefficients<M>);
  benchmark::RegisterBenchmark((m + "/extra_chain_dev+fd_coeff").c_str(),
                               BM_ChainDeviationFdCoefficients<M>);
}

// The console output, then a Markdown summary: CPU ns per pose (the median over repetitions
// when --benchmark_repetitions is given) and the ratios baseline / generated.
class SummaryReporter : public benchmark::ConsoleReporter {
 public:
  explicit SummaryReporter(bool color) : ConsoleReporter(color ? OO_ColorTabular : OO_Tabular) {}

  void ReportRuns(const std::vector<Run>& reports) override {
    ConsoleReporter::ReportRuns(reports);
    for (const Run& run : reports) {
      if (run.error_occurred) continue;
      const std::string name = run.run_name.function_name;
      const double ns = run.GetAdjustedCPUTime() * NanosecondsPer(run.time_unit);
      if (run.run_type == Run::RT_Aggregate) {
        if (run.aggregate_name == "median") {
          cpu_ns_[name] = ns;
          median_.insert(name);
        }
      } else if (median_.count(name) == 0) {
        cpu_ns_[name] = ns;
      }
    }
  }

  void Finalize() override {
    ConsoleReporter::Finalize();
    std::ostringstream main, extra, floors, packs;
    for (const auto& [machine, n] : machines_) {
      const std::string& key = machine;  // clang < 16 cannot capture a structured binding
      const auto get = [&](const std::string& what) {
        const auto it = cpu_ns_.find(key + "/" + what);
        return it == cpu_ns_.end() ? 0.0 : it->second;
      };
      const double dev = get("generated_dev"), coeff = get("generated_coeff"),
                   two = get("generated_dev+coeff"), one = get("generated_combined"),
                   a = get("eigen_dev"), b = get("analytic_coeff"),
                   ab = get("eigen_dev+analytic_coeff"), fd = get("extra_chain_dev+fd_coeff"),
                   floor = get("output_floor"), trig = get("output_floor+sincos"),
                   pack = get("generated_pack") / kLanes,
                   pack_floor = get("output_floor_pack") / kLanes,
                   pack_trig = get("output_floor_pack+sincos") / kLanes;
      if (dev == 0 || coeff == 0 || two == 0 || one == 0 || a == 0 || b == 0 || ab == 0)
        continue;  // filtered out
      main << std::fixed << std::setprecision(1) << "| " << machine << " | " << n << " | " << dev
           << " | " << a << " | **" << a / dev << "x** | " << coeff << " | " << b << " | **"
           << b / coeff << "x** | " << one << " | " << two << " | " << ab << " | **" << ab / one
           << "x** | " << floor << " | " << (floor > 0 ? one / floor : 0.0) << "x |\n";
      if (floor > 0 && trig > 0)
        floors << std::fixed << std::setprecision(1) << "| " << machine << " | " << one << " | "
               << ab << " | " << floor << " | " << one / floor << "x | " << trig << " | "
               << one / trig << "x | " << ab / trig << "x |\n";
      if (pack > 0)
        packs << std::fixed << std::setprecision(1) << "| " << machine << " | " << one << " | "
              << pack << " | " << ab << " | " << ab / one << "x | **" << ab / pack << "x** | "
              << pack_floor << " | " << (pack_floor > 0 ? pack / pack_floor : 0.0) << "x | "
              << pack_trig << " | " << (pack_trig > 0 ? pack / pack_trig : 0.0) << "x | " << trig
              << " |\n";
      if (fd != 0)
        extra << std::fixed << "| " << machine << " | " << std::setprecision(1) << one << " | "
              << std::setprecision(0) << fd << " | " << fd / one << "x |\n";
    }
    if (main.str().empty()) return;
    std::ostream& out = GetOutputStream();
    out << "\nCPU time per pose (ns); ratio = hand-written baseline / generated\n\n"
        << "| machine | n | generated Deviation | (a) Eigen chain deviation | (a) / Deviation | "
           "generated Coefficients | (b) analytic Jacobian | (b) / Coefficients | generated "
           "DeviationAndCoefficients | generated Deviation + Coefficients (2 calls) | (a) + (b) "
           "| (a + b) / DeviationAndCoefficients | output floor (copy of the 6 + 6n outputs) | "
           "DeviationAndCoefficients / floor |\n"
        << "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | "
           "---: | ---: |\n"
        << main.str();
    if (!floors.str().empty())
      out << "\nDeviationAndCoefficients against its floors (CPU ns per pose): the copy of its 6 + "
             "6n outputs, and that copy plus sin and cos of every rotary axis; (a + b) / floor is "
             "the highest ratio any code computing these outputs can reach\n\n"
          << "| machine | generated DeviationAndCoefficients | (a) + (b) | output floor | "
             "generated / floor | floor + sin/cos | generated / (floor + sin/cos) | (a + b) / "
             "(floor + sin/cos) |\n| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n"
          << floors.str();
    if (!packs.str().empty())
      out << "\nSeveral poses at once: DeviationAndCoefficients<Pack<" << kLanes
          << ">>, one pose per lane (CPU ns per pose = per call / " << kLanes << ")\n\n"
          << "| machine | generated DeviationAndCoefficients | Pack<" << kLanes
          << "> per pose | (a) + (b) | (a + b) / generated | (a + b) / Pack | output floor as "
             "packs | Pack / its floor | that floor + Pack sin/cos | Pack / (floor + sin/cos) | "
             "floor + sin/cos (one pose at a time) |\n| --- | ---: | ---: | ---: | ---: | ---: | "
             "---: | ---: | ---: | ---: | ---: |\n"
          << packs.str();
    if (!extra.str().empty())
      out << "\nExtra (not a competent baseline): the numeric chain with finite-difference "
             "coefficients\n\n"
          << "| machine | generated DeviationAndCoefficients | NumericChain dev + FD coeff | "
             "ratio |\n| --- | ---: | ---: | ---: |\n"
          << extra.str();
    out.flush();
  }

  void add_machine(const std::string& name, std::size_t num_errors) {
    machines_.emplace_back(name, num_errors);
  }

 private:
  static double NanosecondsPer(benchmark::TimeUnit unit) {
    switch (unit) {
      case benchmark::kSecond:
        return 1e9;
      case benchmark::kMillisecond:
        return 1e6;
      case benchmark::kMicrosecond:
        return 1e3;
      default:
        return 1.0;
    }
  }

  std::vector<std::pair<std::string, std::size_t>> machines_;
  std::map<std::string, double> cpu_ns_;
  std::set<std::string> median_;
};

template <typename M>
bool add(SummaryReporter& reporter) {
  if (!check_agreement<M>()) return false;
  register_machine<M>();
  reporter.add_machine(M::kName, M::kNumErrors);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  // (Read before Initialize, which removes the flags it knows.) A reporter passed to
  // RunSpecifiedBenchmarks does not see --benchmark_color: colour only on a terminal, and never
  // when asked not to.
  bool color = isatty(fileno(stdout)) != 0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--benchmark_color=false" || arg == "--benchmark_color=no") color = false;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;

  SummaryReporter reporter(color);
  bool ok = add<gantry_grinder_model>(reporter);
  ok = add<vmc_3axis_model>(reporter) && ok;
  ok = add<two_axis_model>(reporter) && ok;
  ok = add<five_axis_ac_model>(reporter) && ok;
  ok = add<head_head_bc_model>(reporter) && ok;
  ok = add<pipe_cutter_model>(reporter) && ok;
  if (!ok) return 1;

  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
