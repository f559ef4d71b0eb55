// The standard normal space of a reliability problem, the limit state of one failure side, the
// random streams and small helpers shared by the reliability methods.
#include <algorithm>
#include <cmath>

#include "reliability_detail.hpp"
#include "splitmix64.hpp"
#include "weilgen/uq/reliability.hpp"

namespace weilgen::reliability_detail {

namespace {
// Central differences: step = cbrt(machine epsilon) times the input's scale.
constexpr double kRelativeStep = 6e-6;

std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
}  // namespace

StandardSpace::StandardSpace(const ReliabilityProblem& problem) : problem_(problem) {
  double ref = 0;
  for (const auto& d : problem.inputs) {
    mean_.push_back(d.mean());
    stddev_.push_back(d.stddev());
  }
  for (std::size_t i = 0; i < problem.inputs.size(); ++i) {
    if (!problem.inputs[i].is_constant()) {
      active_.push_back(i);
      ref = std::max(ref, problem.inputs[i].stddev());
    }
  }
  if (!(ref > 0)) ref = 1;
  fd_step_.resize(problem.inputs.size());
  for (std::size_t i = 0; i < problem.inputs.size(); ++i) {
    const InputDistribution& d = problem.inputs[i];
    // A constant input has no spread of its own: its mean's magnitude or the largest spread.
    fd_step_[i] =
        kRelativeStep * (d.is_constant() ? std::max(std::abs(d.mean()), ref) : d.stddev());
  }
}

void StandardSpace::to_x(const double* u, double* x) const {
  const auto& in = problem_.inputs;
  std::size_t k = 0;
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (k < active_.size() && active_[k] == i) {
      x[i] = in[i].from_standard_normal(u[k]);
      ++k;
    } else {
      x[i] = mean_[i];
    }
  }
}

double StandardSpace::response(unsigned thread, const double* x, std::size_t& count) const {
  ++count;
  if (problem_.linear) {
    const LinearForm& f = *problem_.linear;
    double r = f.constant;
    for (std::size_t i = 0; i < f.coefficients.size(); ++i) r += f.coefficients[i] * x[i];
    return r;
  }
  return problem_.response(thread, x);
}

void StandardSpace::gradient_x(unsigned thread, const double* x, double* grad,
                               std::size_t& count) const {
  const std::size_t n = num_inputs();
  if (problem_.linear) {
    std::copy(problem_.linear->coefficients.begin(), problem_.linear->coefficients.end(), grad);
    return;
  }
  if (problem_.gradient) {
    problem_.gradient(thread, x, grad);
    return;
  }
  std::vector<double> xw(x, x + n);
  for (std::size_t i = 0; i < n; ++i) {
    const double h = fd_step_[i];
    xw[i] = x[i] + h;
    const double rp = response(thread, xw.data(), count);
    xw[i] = x[i] - h;
    const double rm = response(thread, xw.data(), count);
    xw[i] = x[i];
    grad[i] = (rp - rm) / (2 * h);
  }
}

double LimitState::value(unsigned thread, const double* u, double* x, std::size_t& count) const {
  space->to_x(u, x);
  return tolerance - side * space->response(thread, x, count);
}

double LimitState::value_gradient(unsigned thread, const double* u, double* grad_u, double* x,
                                  double* grad_x, std::size_t& count) const {
  space->to_x(u, x);
  const double g = tolerance - side * space->response(thread, x, count);
  space->gradient_x(thread, x, grad_x, count);
  const auto& act = space->active();
  const auto& in = space->problem().inputs;
  for (std::size_t k = 0; k < act.size(); ++k)
    grad_u[k] = -side * grad_x[act[k]] * in[act[k]].dx_du(u[k]);
  return g;
}

Rng::Rng(std::uint64_t seed, std::uint64_t stream, std::uint64_t block) {
  std::uint64_t st = seed;
  std::uint64_t h = splitmix64(st);
  st = h ^ (stream * 0xd1b54a32d192ed03ULL);
  h = splitmix64(st);
  st = h ^ (block * 0x8cb92ba72f3d8dd7ULL);
  for (auto& s : s_) s = splitmix64(st);
}

std::uint64_t Rng::next() {
  const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
  const std::uint64_t t = s_[1] << 17;
  s_[2] ^= s_[0];
  s_[3] ^= s_[1];
  s_[1] ^= s_[2];
  s_[0] ^= s_[3];
  s_[2] ^= t;
  s_[3] = rotl(s_[3], 45);
  return result;
}

double Rng::uniform() {
  // 53 random bits, shifted by half a step: never 0, never 1.
  return (static_cast<double>(next() >> 11) + 0.5) * 0x1.0p-53;
}

double Rng::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  const double r = std::sqrt(-2.0 * std::log(uniform()));
  const double a = 6.283185307179586477 * uniform();
  spare_ = r * std::sin(a);
  has_spare_ = true;
  return r * std::cos(a);
}

double confidence_z(double confidence) { return normal_quantile(0.5 + 0.5 * confidence); }

void append_note(std::string& note, const std::string& text) {
  if (text.empty()) return;
  if (!note.empty()) note += "; ";
  note += text;
}

}  // namespace weilgen::reliability_detail
