// Writes examples/data/vmc_3axis_points.csv: synthetic volumetric point measurements of the
// vmc_3axis machine for `weilgen identify` (docs/identify.md), from the EXACT numeric chain (not
// the generated model) with a known error set:
//
//   build/bench/experiments/weilgen_exp_make_points_data examples/data/vmc_3axis_points.csv
//       examples/data/vmc_3axis_ballbar.csv        (both on one command line)
//
// The second file is a ballbar trace of the same machine (same truth): XY circle, centre
// X=250, Y=-200, Z=-150, R = 100 mm, ccw, 1° steps, dr = |P(θ) − C| − R from the exact tool
// position relative to the workpiece, with N(0, 0.2²) µm noise.
//
// Truth (seed 20210601): each PIGE a normal deviate with the machine file's sigma; each PDGE a
// cubic in u = (2q - a - b)/(b - a) on its axis travel [a, b], e(q) = sigma · Σ_k g_k u^k with
// g_k standard normal deviates (k = 0..3). The truth's coefficients are written as `# truth:`
// comment lines. Poses: X = 0:500:6, Y = -400:0:5, Z = -300:0:4 (120 poses), tool_length 0;
// measured dx, dy, dz (µm) with N(0, 0.3²) noise. t_s: 20 s per pose.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bench/experiments/normal_deviates.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/model/numeric_chain.hpp"

int main(int argc, char** argv) {
  using namespace weilgen;
  const Description desc = load_machine_file(resolve_machine("vmc_3axis"));
  std::FILE* out = argc > 1 ? std::fopen(argv[1], "w") : stdout;
  if (!out) {
    std::fprintf(stderr, "cannot write %s\n", argv[1]);
    return 1;
  }
  bench::NormalDeviates rng(20210601);
  constexpr double kNoiseUm = 0.3;
  const std::size_t ne = desc.errors.size();
  // Truth coefficients, declared units (µm, µrad), cubic in u for PDGEs.
  std::vector<std::vector<double>> truth(ne);
  std::fprintf(out,
               "# Synthetic volumetric point measurements of vmc_3axis, written by\n"
               "# bench/experiments/make_points_data.cpp (seed 20210601) from the exact numeric\n"
               "# chain; noise N(0, 0.3^2) um. PDGE e(q) = sum_k c_k u^k, u on the axis travel.\n"
               "# machine: vmc_3axis\n");
  for (std::size_t k = 0; k < ne; ++k) {
    const ErrorDef& e = desc.errors[k];
    const double sigma = e.distribution.b;
    const bool pdge = e.dependence == Dependence::PDGE;
    for (int t = 0; t < (pdge ? 4 : 1); ++t) truth[k].push_back(sigma * rng());
    std::fprintf(out, "# truth %s (%s, %s):", e.name.c_str(), pdge ? "poly:3" : "constant",
                 e.unit.c_str());
    for (double c : truth[k]) std::fprintf(out, " %.6g", c);
    std::fprintf(out, "\n");
  }
  std::fprintf(out, "X,Y,Z,t_s,dx_um,dy_um,dz_um\n");
  NumericChain chain(desc);
  const std::vector<int> axes = desc.axes();  // Y, X, Z
  auto pose = [&](double X, double Y, double Z) {
    std::vector<double> q;
    for (int b : axes) {
      const std::string& c = desc.bodies[static_cast<std::size_t>(b)].joint.coordinate;
      q.push_back(c == "X" ? X : c == "Y" ? Y : Z);
    }
    return q;
  };
  auto errors = [&](double X, double Y, double Z) {
    std::vector<double> err(ne);
    for (std::size_t k = 0; k < ne; ++k) {
      const ErrorDef& e = desc.errors[k];
      const Joint& j = desc.bodies[static_cast<std::size_t>(e.body)].joint;
      double v = truth[k][0];
      if (truth[k].size() > 1) {
        const double pos = j.coordinate == "X" ? X : j.coordinate == "Y" ? Y : Z;
        const double u = (2 * pos - j.min - j.max) / (j.max - j.min);
        v = truth[k][0] + u * (truth[k][1] + u * (truth[k][2] + u * truth[k][3]));
      }
      err[k] = v * e.to_base;
    }
    return err;
  };
  double t = 0;
  for (int iz = 0; iz < 4; ++iz)
    for (int iy = 0; iy < 5; ++iy)
      for (int ix = 0; ix < 6; ++ix) {
        const double X = 100.0 * ix, Y = -100.0 * iy, Z = -100.0 * iz;
        const std::array<double, 6> d = chain.deviation(pose(X, Y, Z), errors(X, Y, Z));
        std::fprintf(out, "%g,%g,%g,%g,%.4f,%.4f,%.4f\n", X, Y, Z, t, d[0] * 1e3 + kNoiseUm * rng(),
                     d[1] * 1e3 + kNoiseUm * rng(), d[2] * 1e3 + kNoiseUm * rng());
        t += 20;
      }
  if (out != stdout) std::fclose(out);
  if (argc < 3) return 0;
  std::FILE* bb = std::fopen(argv[2], "w");
  if (!bb) {
    std::fprintf(stderr, "cannot write %s\n", argv[2]);
    return 1;
  }
  std::fprintf(bb,
               "# Synthetic ballbar trace of vmc_3axis (NOT measured), written by\n"
               "# bench/experiments/make_points_data.cpp with the same truth as\n"
               "# vmc_3axis_points.csv; dr = |P - C| - R from the exact chain, N(0, 0.2^2) um.\n"
               "# machine: vmc_3axis\n# plane: XY\n# centre: X=250, Y=-200, Z=-150\n"
               "# radius: 100 mm\n# feed: ccw\nangle_deg,dr_um\n");
  const std::vector<double> zero(ne, 0.0);
  const Eigen::Vector3d centre =
      chain.tool_in_workpiece(pose(250, -200, -150), zero).block<3, 1>(0, 3);
  for (int a = 0; a < 360; ++a) {
    const double th = a * M_PI / 180, X = 250 + 100 * std::cos(th), Y = -200 + 100 * std::sin(th);
    const Eigen::Vector3d p =
        chain.tool_in_workpiece(pose(X, Y, -150), errors(X, Y, -150)).block<3, 1>(0, 3);
    const Eigen::Vector3d v = p - centre;
    const double dr = (std::hypot(v[0], v[1]) - 100) * 1e3;  // in the plane
    std::fprintf(bb, "%d,%.4f\n", a, dr + 0.2 * rng());
  }
  return std::fclose(bb);
}
