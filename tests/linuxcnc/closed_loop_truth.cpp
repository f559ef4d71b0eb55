// The simulated machine of CTest linuxcnc_closed_loop (closed_loop.py): not weilgen's generated
// model but the exact numeric chain (src/model/numeric_chain.*: Eigen 4x4 products, exact
// rotations, written independently of the generator), with errors that vary along their axes
// in shapes the identification's bases do not hold exactly, plus constants.
//
//   closed_loop_truth MACHINE.yaml SEED
// stdin: one pose per line, the model's axes (Description::axes() order, mm / deg).
// stdout per pose, %.17g: the deviation dx dy dz (mm) da db dc (rad) of the actual tool pose from
// the nominal one at that pose, the actual tool point (mm) and tool axis (z of the tool frame),
// and the nominal tool point and tool axis, all in the workpiece frame (18 numbers).
//
// The truth's errors, for error k with scale s (its machine-file sigma in base units; 5 um or
// 10 urad without one) and normal draws g, h from a generator seeded with SEED and k:
//   constant (PIGE, or no joint):  s g0
//   along a linear axis, u = (2q - a - b) / (b - a) over its travel [a, b]:
//     s (g0 + g1 u + g2 u^2 / 2 + g3 u^3 / 3 + 0.15 sin(3.7 u + phi))
//   along a rotary axis, angle t:
//     s (g0 + g1 cos t + h1 sin t + (g2 cos 2t + h2 sin 2t) / 2 + 0.15 cos(3 t + phi))
// A cubic polynomial (poly:3) or two harmonics (fourier:2) capture all but the last term: that
// term, the measurement noise and the model's first-order truncation set the floor of what
// compensation can reach.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "weilgen/base/constants.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/model/numeric_chain.hpp"

using namespace weilgen;

namespace {

struct TruthError {
  int axis = -1;  // index into the model's axes, -1 for a constant
  bool rotary = false;
  double a = 0, b = 1;  // travel of a linear axis
  double s = 0;
  double g[4] = {0, 0, 0, 0}, h[3] = {0, 0, 0}, phi = 0;
};

double scale_of(const ErrorDef& e) {
  const Distribution& d = e.distribution;
  double v = 0;
  if (d.kind == Distribution::Kind::Normal || d.kind == Distribution::Kind::TruncatedNormal)
    v = d.b;
  else if (d.kind == Distribution::Kind::Uniform)
    v = (d.hi - d.lo) / std::sqrt(12.0);
  if (v > 0) return v * e.to_base;
  return e.effect == ErrorEffect::Rotation ? 1e-5 : 5e-3;
}

std::vector<TruthError> truth_errors(const Description& d, unsigned long seed) {
  const std::vector<int> axes = d.axes();
  std::vector<TruthError> out;
  for (std::size_t k = 0; k < d.errors.size(); ++k) {
    const ErrorDef& e = d.errors[k];
    std::mt19937_64 rng(seed * 1000003ULL + k);
    std::normal_distribution<double> n(0.0, 1.0);
    TruthError t;
    t.s = scale_of(e);
    for (double& g : t.g) g = n(rng);
    for (double& h : t.h) h = n(rng);
    t.phi = 2 * kPi * std::uniform_real_distribution<double>(0, 1)(rng);
    const Body& body = d.bodies[static_cast<std::size_t>(e.body)];
    if (e.dependence == Dependence::PDGE && body.joint.type != JointType::Fixed)
      for (std::size_t i = 0; i < axes.size(); ++i)
        if (axes[i] == e.body) {
          t.axis = static_cast<int>(i);
          t.rotary = body.joint.type == JointType::Revolute;
          t.a = body.joint.min;
          t.b = body.joint.max;
        }
    out.push_back(t);
  }
  return out;
}

std::vector<double> errors_at(const std::vector<TruthError>& truth, const Description& d,
                              const std::vector<double>& q) {
  const std::vector<int> axes = d.axes();
  std::vector<double> e(truth.size());
  for (std::size_t k = 0; k < truth.size(); ++k) {
    const TruthError& t = truth[k];
    double v = t.g[0];
    if (t.axis >= 0 && !t.rotary) {
      const double u = (2 * q[static_cast<std::size_t>(t.axis)] - t.a - t.b) / (t.b - t.a);
      v += t.g[1] * u + t.g[2] * u * u / 2 + t.g[3] * u * u * u / 3 +
           0.15 * std::sin(3.7 * u + t.phi);
    } else if (t.axis >= 0) {
      const Joint& j =
          d.bodies[static_cast<std::size_t>(axes[static_cast<std::size_t>(t.axis)])].joint;
      const double a = q[static_cast<std::size_t>(t.axis)] * j.to_base;
      v += t.g[1] * std::cos(a) + t.h[0] * std::sin(a) +
           (t.g[2] * std::cos(2 * a) + t.h[1] * std::sin(2 * a)) / 2 +
           0.15 * std::cos(3 * a + t.phi);
    }
    e[k] = t.s * v;
  }
  return e;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: closed_loop_truth MACHINE.yaml SEED < poses\n");
    return 2;
  }
  try {
    const Description d = load_machine_file(argv[1]);
    const std::vector<TruthError> truth = truth_errors(d, std::stoul(argv[2]));
    const NumericChain chain(d);
    const std::size_t n = d.axes().size();
    const std::vector<double> zero(d.errors.size(), 0.0);
    for (std::string line; std::getline(std::cin, line);) {
      std::istringstream in(line);
      std::vector<double> q(n);
      for (double& v : q) in >> v;
      if (!in) continue;
      const std::vector<double> e = errors_at(truth, d, q);
      const std::array<double, 6> dev = chain.deviation(q, e);
      const Eigen::Matrix4d actual = chain.tool_in_workpiece(q, e);
      const Eigen::Matrix4d nominal = chain.tool_in_workpiece(q, zero);
      for (double v : dev) std::printf("%.17g ", v);
      for (const Eigen::Matrix4d* m : {&actual, &nominal})
        for (int c : {3, 2})
          for (int r = 0; r < 3; ++r) std::printf("%.17g ", (*m)(r, c));
      std::printf("\n");
    }
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "closed_loop_truth: %s\n", ex.what());
    return 3;
  }
  return 0;
}
