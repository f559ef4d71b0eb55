// Reliability of one scalar response r(x) of independent uncertain inputs x against a tolerance:
// R = P(|r(x)| <= t) (two-sided) or R = P(r(x) <= t) (upper). Generic: the engine knows nothing
// about machines; the caller supplies the response (and optionally its gradient or an exact linear
// form). Methods (docs/reliability.md has the formulas):
//   Exact               linear response, Normal inputs: r ~ N(m, s^2), closed form.
//   Form                HL-RF with an Armijo step (improved HL-RF) in standard normal space, one
//                       design point per failure side (plus a mirror lobe when one exists).
//   ImportanceSampling  Wang & Yuan 2021's axis-orthogonal importance sampling (eqs. 23-28): lines
//                       parallel to the design direction alpha, a 1-D root per line,
//                       P_f = mean Phi(-h). Exact with zero variance for a linear limit state.
//   MonteCarlo          crude sampling, Wilson interval.
//   Auto                Exact when applicable, otherwise ImportanceSampling.
// Sensitivities dR/dmu_i and dR/dsigma_i are analytic (Exact), FORM-based at the design points
// (default for the other methods) or, on request, differentiated IS estimates. Sampling is
// deterministic: the same seed gives bit-identical results for any thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "weilgen/uq/distribution.hpp"

namespace weilgen {

// Safe when |r(x)| <= t (TwoSided) or when r(x) <= t (Upper). The radial limit
// ||(dx, dy, dz)|| <= t is Upper on the norm.
enum class LimitKind { TwoSided, Upper };

enum class ReliabilityMethod { Auto, Exact, Form, ImportanceSampling, MonteCarlo };

// How the non-exact methods compute dR/dmu and dR/dsigma: from the FORM design points (the
// Wang & Yuan 2021, eqs. 31-33, generalised), or, for ImportanceSampling, by differentiating the
// sampling estimate itself (each line's root h moves by -(dg/dtheta) / (dg/ds)), which is
// consistent with the IS reliability also for curved limit states; it needs dr/dx at every root (2
// n extra evaluations per root without a gradient or linear form). MonteCarlo always uses FORM.
enum class SensitivityMethod { Form, Sampling };

// "auto", "exact", "form", "is", "mc".
const char* to_string(ReliabilityMethod method);
// "two-sided", "upper".
const char* to_string(LimitKind kind);
// Accepts the to_string names and "importance-sampling", "monte-carlo" (case-insensitive);
// throws std::invalid_argument listing the accepted names.
ReliabilityMethod parse_reliability_method(const std::string& name);

// r = constant + sum_i coefficients[i] * x_i (one coefficient per input).
struct LinearForm {
  double constant = 0;
  std::vector<double> coefficients;
};

struct ReliabilityProblem {
  std::vector<InputDistribution> inputs;  // independent inputs
  // r(thread, x): the response, x has inputs.size() values. Called concurrently with thread in
  // [0, resolve_threads(options.threads)) so the caller can keep per-thread workspaces.
  std::function<double(unsigned thread, const double* x)> response;
  // Optional exact gradient dr/dx (inputs.size() values). If empty (and there is no linear form),
  // central differences with steps relative to each input's stddev.
  std::function<void(unsigned thread, const double* x, double* gradient)> gradient;
  // Set when r is exactly linear; then `response` may be empty. When set it is used for every
  // evaluation (response and gradient are not called).
  std::optional<LinearForm> linear;
  LimitKind limit = LimitKind::TwoSided;
  double tolerance = 0;  // t > 0, in the response's unit
};

struct ReliabilityOptions {
  ReliabilityMethod method = ReliabilityMethod::Auto;
  std::size_t samples = 1u << 14;  // IS lines / MC samples
  bool qmc = false;                // not implemented: plain pseudo-random sampling (noted)
  std::uint64_t seed = 1;
  unsigned threads = 0;  // 0 = all cores
  double confidence = 0.95;
  SensitivityMethod sensitivities = SensitivityMethod::Form;
  int form_max_iterations = 100;
  // HL-RF stops when |g| / |grad g(0)| <= tol * max(1, |u|) and the HL-RF step is
  // <= sqrt(tol) * max(1, |u|): beta to about tol, the direction to about sqrt(tol).
  double form_tolerance = 1e-9;

  // Throws std::invalid_argument naming the field: confidence in (0, 1), FORM iterations >= 1,
  // FORM tolerance > 0.
  void validate() const;
};

// Bytes one ReliabilityAnalysis::run of `inputs` inputs holds at once (per-block sums of the
// importance-sampling lines and their derivatives): checked before a run.
double reliability_memory_bytes(const ReliabilityOptions& options, std::size_t inputs);

struct DesignPoint {
  // u and alpha are indexed like the inputs (0 for constant inputs); x holds every input.
  std::vector<double> u, x;
  std::vector<double> alpha;  // unit vector towards failure, -grad_u g / |grad_u g|
  // Signed: alpha . u*. +inf when no failure point was found on this side (P_f,side = 0), -inf
  // when the whole explored space fails.
  double beta = 0;
  bool converged = false;
  int iterations = 0;
  int side = +1;  // +1: the failure r > t; -1: the failure r < -t (two-sided limit)
};

struct ReliabilityResult {
  ReliabilityMethod method = ReliabilityMethod::Exact;  // the method used (never Auto)
  double reliability = 0, failure = 0;                  // R and 1 - R
  double ci_lo = 0, ci_hi = 0;  // confidence interval of R (equal to R for Exact and Form)
  double cov = 0;  // coefficient of variation of the failure-probability estimate (0: Exact, Form)
  // One per failure side (two for a two-sided limit), in the order side +1, side -1; a side
  // whose limit state has a second, mirror lobe (e.g. the radial limit at zero means) gets a
  // second point right after its first. Empty for Exact.
  std::vector<DesignPoint> design_points;
  // Per input: dR/dmean_i and dR/dstddev_i for the location-scale moves of InputDistribution.
  std::vector<double> dR_dmu, dR_dsigma;
  std::size_t evaluations = 0;  // response evaluations (gradients by differences included)
  std::string note;             // e.g. "FORM side +1: did not converge in 100 iterations"
};

// R of one problem by the options' method.
class ReliabilityAnalysis {
 public:
  explicit ReliabilityAnalysis(ReliabilityOptions options);  // validates the options
  const ReliabilityOptions& options() const { return options_; }

  // Throws std::invalid_argument for: no inputs, t <= 0 or not finite, no response and no
  // linear form, a linear form of the wrong size, samples == 0 for a sampling method, Exact
  // requested when the response is not linear or an input is not Normal.
  ReliabilityResult run(const ReliabilityProblem& problem) const;

 private:
  ReliabilityOptions options_;
};

// True when Exact applies: a linear form and every input Normal or constant.
bool exact_applicable(const ReliabilityProblem& problem);

}  // namespace weilgen
