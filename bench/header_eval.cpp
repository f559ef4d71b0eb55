// Evaluation cost of one generated header (bench/bench_header.sh compiles this file against it):
// per call of Deviation, DeviationAndCoefficients, Coefficients and (models with higher terms)
// HigherOrder, CPU ns (the median of --repeats timed runs of --calls calls each, poses cycled
// from 64 drawn once: axes uniform in their ranges, errors uniform in ±10 µm / ±50 µrad), and a
// checksum of the outputs (the same model gives the same sums whatever the header's form).
//
//   g++ -std=c++17 -O2 -DWEILGEN_HEADER='"pipe_cutter_o3.hpp"' -DWEILGEN_NS=pipe_cutter_o3 \
//       -I DIR bench/header_eval.cpp -o header_eval && ./header_eval [--calls N] [--repeats R]
//       [--only Deviation|DeviationAndCoefficients|Coefficients|HigherOrder]
//
// --only runs one function once per pose of one pass (for callgrind: instructions per call are
// the program's count less that of --only none, divided by 64).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <random>
#include <string>
#include <vector>

#include WEILGEN_HEADER

namespace m = weilgen_models::WEILGEN_NS;

namespace {

constexpr std::size_t kPoses = 64;

struct Pose {
  std::array<double, m::kNumAxes> axes;
  std::array<double, m::kNumErrors> errors;
};

double cpu_seconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

}  // namespace

int main(int argc, char** argv) {
  long calls = 2000, repeats = 5;
  std::string only;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--calls") calls = std::atol(argv[i + 1]);
    if (a == "--repeats") repeats = std::atol(argv[i + 1]);
    if (a == "--only") only = argv[i + 1];
  }
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> unit(0, 1), sym(-1, 1);
  std::vector<Pose> poses(kPoses);
  for (Pose& p : poses) {
    for (std::size_t a = 0; a < m::kNumAxes; ++a)
      p.axes[a] = m::kAxes[a].min + (m::kAxes[a].max - m::kAxes[a].min) * unit(rng);
    for (std::size_t e = 0; e < m::kNumErrors; ++e)
      p.errors[e] = (m::kErrors[e].rotation ? 50e-6 : 10e-3) * sym(rng);
  }
  std::array<double, m::kNumParams> params{};
  for (std::size_t i = 0; i < m::kNumParams; ++i) params[i] = m::kParams[i].default_value;
  std::array<double, 3> pos{}, rot{};
  static std::array<double, 3 * m::kNumErrors> cp{}, cr{};
#if defined(WEILGEN_HIGHER)
  static std::array<double, m::kNumOutputs * m::kNumHigherTerms> terms{};
#endif
  double checksum = 0;
  const std::vector<std::string> names = {"Deviation", "DeviationAndCoefficients", "Coefficients",
                                          "HigherOrder"};
  // `which` indexes names (anything else: nothing), chosen before the loop.
  auto run = [&](std::size_t which, std::size_t k) {
    const Pose& p = poses[k % kPoses];
    switch (which) {
      case 0:
        m::Deviation(p.axes, p.errors, params, &pos, &rot);
        checksum += pos[0] + pos[1] + pos[2] + rot[0] + rot[1] + rot[2];
        break;
      case 1:
        m::DeviationAndCoefficients(p.axes, p.errors, params, &pos, &rot, &cp, &cr);
        checksum += pos[0] + rot[2] + cp[k % cp.size()] + cr[k % cr.size()];
        break;
      case 2:
        m::Coefficients(p.axes, params, &cp, &cr);
        checksum += cp[k % cp.size()] + cr[k % cr.size()];
        break;
#if defined(WEILGEN_HIGHER)
      case 3:
        m::HigherOrder(p.axes, params, &terms);
        checksum += terms[k % terms.size()];
        break;
#endif
      default:
        break;
    }
  };
#if defined(WEILGEN_HIGHER)
  const std::size_t functions = 4;
#else
  const std::size_t functions = 3;
#endif
  if (!only.empty()) {
    const std::size_t which =
        static_cast<std::size_t>(std::find(names.begin(), names.end(), only) - names.begin());
    for (std::size_t k = 0; k < kPoses; ++k) run(which, k);
    std::printf("checksum %.17g\n", checksum);
    return 0;
  }
  std::printf("| function | CPU ns per call (median of %ld x %ld calls) |\n| --- | ---: |\n",
              repeats, calls);
  for (std::size_t f = 0; f < functions; ++f) {
    std::vector<double> ns;
    for (long r = 0; r < repeats; ++r) {
      const double t0 = cpu_seconds();
      for (long c = 0; c < calls; ++c) run(f, static_cast<std::size_t>(c));
      ns.push_back((cpu_seconds() - t0) / static_cast<double>(calls) * 1e9);
    }
    std::sort(ns.begin(), ns.end());
    std::printf("| %s | %.0f |\n", names[f].c_str(), ns[ns.size() / 2]);
  }
  std::printf("checksum %.17g\n", checksum);
  return 0;
}
