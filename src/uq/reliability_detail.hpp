// Internals of the reliability methods shared by the reliability*.cpp files: the problem in
// standard normal space, limit states, FORM design points, random streams (not a public header:
// nothing outside src/uq/ includes it).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "weilgen/uq/reliability.hpp"

namespace weilgen {

namespace reliability_detail {

// The problem in standard normal space: u (the non-constant inputs only, in input order) maps to
// x (every input; constants at their mean), x to r. Evaluation counts go to the caller's counter
// so that parallel blocks count without sharing.
class StandardSpace {
 public:
  explicit StandardSpace(const ReliabilityProblem& problem);

  const ReliabilityProblem& problem() const { return problem_; }
  std::size_t dim() const { return active_.size(); }
  std::size_t num_inputs() const { return problem_.inputs.size(); }
  const std::vector<std::size_t>& active() const { return active_; }
  double mean(std::size_t i) const { return mean_[i]; }
  double stddev(std::size_t i) const { return stddev_[i]; }

  void to_x(const double* u, double* x) const;
  double response(unsigned thread, const double* x, std::size_t& count) const;
  // dr/dx for every input: the linear form, the caller's gradient or central differences.
  void gradient_x(unsigned thread, const double* x, double* grad, std::size_t& count) const;

 private:
  const ReliabilityProblem& problem_;
  std::vector<std::size_t> active_;
  std::vector<double> fd_step_, mean_, stddev_;
};

// One failure side: g(u) = t - side * r(x(u)); failure when g <= 0.
struct LimitState {
  const StandardSpace* space;
  int side;
  double tolerance;
  double value(unsigned thread, const double* u, double* x, std::size_t& count) const;
  // Value and gradient in u (dim values); x and dr/dx (num_inputs values) are left in x, grad_x.
  double value_gradient(unsigned thread, const double* u, double* grad_u, double* x, double* grad_x,
                        std::size_t& count) const;
};

// A design point as the sampling and the sensitivities need it (vectors of size dim() for u and
// alpha, num_inputs() for x and grad_x).
struct FormPoint {
  DesignPoint point;             // public form (full indexing)
  std::vector<double> u, alpha;  // active indexing
  std::vector<double> grad_x;    // dr/dx at x*
  double grad_norm = 0;          // |grad_u g| at u*, in the response's unit
  std::string note;
};

// HL-RF from `start` (dim values) for one side.
FormPoint run_form(const LimitState& g, const std::vector<double>& start,
                   const ReliabilityOptions& options, std::size_t& count);
// The design points of every side (plus mirror lobes), see ReliabilityResult::design_points.
std::vector<FormPoint> form_design_points(const StandardSpace& space,
                                          const ReliabilityOptions& options, std::size_t& count,
                                          std::string& note);
// P_f,FORM = sum over points of Phi(-beta).
double form_failure(const std::vector<FormPoint>& points);
// dR/dmu, dR/dsigma = -sum over points of dPhi(-beta)/dtheta (location-scale moves).
void form_sensitivities(const StandardSpace& space, const std::vector<FormPoint>& points,
                        std::vector<double>& dR_dmu, std::vector<double>& dR_dsigma);

ReliabilityResult exact_reliability(const ReliabilityProblem& problem);
ReliabilityResult form_reliability(const StandardSpace& space, const ReliabilityOptions& options);
ReliabilityResult importance_sampling(const StandardSpace& space,
                                      const ReliabilityOptions& options);
ReliabilityResult monte_carlo(const StandardSpace& space, const ReliabilityOptions& options);

// Deterministic random streams: xoshiro256** seeded by splitmix64 from (seed, stream, block).
class Rng {
 public:
  Rng(std::uint64_t seed, std::uint64_t stream, std::uint64_t block);
  std::uint64_t next();
  double uniform();  // in (0, 1)
  double normal();   // standard normal (Box-Muller)

 private:
  std::uint64_t s_[4];
  double spare_ = 0;
  bool has_spare_ = false;
};

// Two-sided standard normal quantile for a confidence level, e.g. 1.96 for 0.95.
double confidence_z(double confidence);
void append_note(std::string& note, const std::string& text);

}  // namespace reliability_detail
}  // namespace weilgen
