// Evaluation cost per pose: the generated closed forms (generated/<machine>.hpp) against the
// straightforward exact numeric Eigen chain (weilgen/model/numeric_chain.hpp), side by side per shipped
// machine, in one run. One benchmark iteration is one pose (items/s = poses/s):
//
//   generated_dev         Deviation (position + orientation)
//   generated_coeff       Coefficients (position + orientation, 6 x n)
//   generated_dev+coeff   (a) both: the deviation and its 6 x n first-order coefficients
//   chain_dev+fd_coeff    (b) the same information from the numeric chain: NumericChain::deviation
//                         plus the 6 x n coefficients by central differences of the chain at zero
//                         error (nominal + 2n perturbed chain evaluations)
//   chain_dev             (c) NumericChain::deviation alone
//
// Poses (axes within their ranges, errors of realistic size) are drawn once, before timing, and
// cycled through; the generated loop does not allocate. Before timing, the generated model is
// checked against the chain on a few poses (same axis/error order, coefficients equal to the
// central differences), so that both sides compute the same thing. After the run, a Markdown table
// of CPU ns/pose and speed-ups (chain / generated) is printed.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "five_axis_ac.hpp"
#include "gantry_grinder.hpp"
#include "two_axis.hpp"
#include "vmc_3axis.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/model/numeric_chain.hpp"

namespace {

constexpr std::size_t kNumPoses = 1024;  // power of two: the pose index wraps with a mask
constexpr double kFdStep = 1e-6;         // central-difference step, base units (mm, rad)

// One generated model namespace as a type, so that the benchmarks can be templates.
#define WEILGEN_BENCH_MODEL(NS)                                               \
  struct NS##_model {                                                         \
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
  }

WEILGEN_BENCH_MODEL(gantry_grinder);
WEILGEN_BENCH_MODEL(vmc_3axis);
WEILGEN_BENCH_MODEL(two_axis);
WEILGEN_BENCH_MODEL(five_axis_ac);

#undef WEILGEN_BENCH_MODEL

// The precomputed poses of one machine, in the generated layout and in the chain's layout.
template <typename M>
struct PoseSet {
  std::vector<std::array<double, M::kNumAxes>> axes;
  std::vector<std::array<double, M::kNumErrors>> errors;
  std::array<double, M::kNumParams> params{};
  std::vector<std::vector<double>> chain_axes;
  std::vector<std::vector<double>> chain_errors;
  weilgen::NumericChain chain;

  PoseSet() : chain(weilgen::load_machine_file(weilgen::resolve_machine(M::kName))) {
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

template <typename M>
void BM_ChainDeviation(benchmark::State& state) {
  const PoseSet<M>& s = poses<M>();
  std::size_t p = 0;
  for (auto _ : state) {
    std::array<double, 6> dev = s.chain.deviation(s.chain_axes[p], s.chain_errors[p]);
    benchmark::DoNotOptimize(dev);
    p = (p + 1) & (kNumPoses - 1);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
}

// ---- the generated model and the chain must compute the same thing ----

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
  double coeff_diff = 0, coeff_max = 0, dev_diff = 0, dev_max = 0;
  std::vector<double> scratch(M::kNumErrors, 0.0), coeff(6 * M::kNumErrors, 0.0);
  for (std::size_t p = 0; p < 16; ++p) {
    std::array<double, 3> position{}, orientation{};
    std::array<double, 3 * M::kNumErrors> position_coeff{}, orientation_coeff{};
    M::Deviation(s.axes[p], s.errors[p], s.params, &position, &orientation);
    M::Coefficients(s.axes[p], s.params, &position_coeff, &orientation_coeff);
    const std::array<double, 6> dev = s.chain.deviation(s.chain_axes[p], s.chain_errors[p]);
    fd_coefficients(s.chain, s.chain_axes[p], scratch, coeff);
    for (std::size_t o = 0; o < 6; ++o) {
      const double g = o < 3 ? position[o] : orientation[o - 3];
      dev_diff = std::max(dev_diff, std::abs(g - dev[o]));
      dev_max = std::max(dev_max, std::abs(dev[o]));
      for (std::size_t j = 0; j < M::kNumErrors; ++j) {
        const std::size_t r = (o % 3) * M::kNumErrors + j;
        const double c = o < 3 ? position_coeff[r] : orientation_coeff[r];
        coeff_diff = std::max(coeff_diff, std::abs(c - coeff[o * M::kNumErrors + j]));
        coeff_max = std::max(coeff_max, std::abs(c));
      }
    }
  }
  // Order-1 model against the exact chain: the difference is second order in the errors.
  ok = coeff_diff <= 1e-6 * std::max(1.0, coeff_max) && dev_diff <= 1e-3 * dev_max;
  std::fprintf(stderr,
               "check %-15s max|coeff - FD| = %.2e (max|coeff| %.3g), max|dev - chain| = %.2e "
               "(max|dev| %.3g): %s\n",
               M::kName, coeff_diff, coeff_max, dev_diff, dev_max, ok ? "ok" : "MISMATCH");
  return ok;
}

template <typename M>
void register_machine() {
  const std::string m = M::kName;
  benchmark::RegisterBenchmark((m + "/generated_dev").c_str(), BM_GeneratedDeviation<M>);
  benchmark::RegisterBenchmark((m + "/generated_coeff").c_str(), BM_GeneratedCoefficients<M>);
  benchmark::RegisterBenchmark((m + "/generated_dev+coeff").c_str(),
                               BM_GeneratedDeviationCoefficients<M>);
  benchmark::RegisterBenchmark((m + "/chain_dev+fd_coeff").c_str(),
                               BM_ChainDeviationFdCoefficients<M>);
  benchmark::RegisterBenchmark((m + "/chain_dev").c_str(), BM_ChainDeviation<M>);
}

// The console output, then a Markdown summary: CPU ns per pose (the median over repetitions
// when --benchmark_repetitions is given) and the speed-ups of the generated code.
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
    std::ostringstream rows;
    for (const auto& [machine, n] : machines_) {
      const auto get = [&](const std::string& what) {
        const auto it = cpu_ns_.find(machine + "/" + what);
        return it == cpu_ns_.end() ? 0.0 : it->second;
      };
      const double a = get("generated_dev+coeff"), b = get("chain_dev+fd_coeff");
      const double dev = get("generated_dev"), c = get("chain_dev");
      if (a == 0 || b == 0 || dev == 0 || c == 0) continue;  // filtered out
      rows << std::fixed << "| " << machine << " | " << n << " | " << std::setprecision(1) << a
           << " | " << std::setprecision(0) << b << " | " << b / a << "x | " << std::setprecision(1)
           << dev << " | " << std::setprecision(0) << c << " | " << c / dev << "x |\n";
    }
    if (rows.str().empty()) return;
    std::ostream& out = GetOutputStream();
    out << "\nCPU time per pose (ns); speed-up = chain / generated\n\n"
        << "| machine | n errors | (a) generated dev+coeff | (b) chain dev+FD coeff | "
           "speed-up (b)/(a) | generated dev | (c) chain dev | speed-up (c)/dev |\n"
        << "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n"
        << rows.str();
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

  bool ok = check_agreement<gantry_grinder_model>();
  ok = check_agreement<vmc_3axis_model>() && ok;
  ok = check_agreement<two_axis_model>() && ok;
  ok = check_agreement<five_axis_ac_model>() && ok;
  if (!ok) return 1;

  SummaryReporter reporter(color);
  register_machine<gantry_grinder_model>();
  reporter.add_machine(gantry_grinder_model::kName, gantry_grinder_model::kNumErrors);
  register_machine<vmc_3axis_model>();
  reporter.add_machine(vmc_3axis_model::kName, vmc_3axis_model::kNumErrors);
  register_machine<two_axis_model>();
  reporter.add_machine(two_axis_model::kName, two_axis_model::kNumErrors);
  register_machine<five_axis_ac_model>();
  reporter.add_machine(five_axis_ac_model::kName, five_axis_ac_model::kNumErrors);

  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
