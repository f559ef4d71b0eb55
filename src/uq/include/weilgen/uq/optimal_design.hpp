// Optimal exact designs by exchange (docs/planning.md, "How"): choose which candidate units (a
// pose, a circle, a position along a line: each a block of rows of the linear model) to measure so
// that the information matrix M = Σ_selected Z_jᵀ Z_j is best by a criterion:
//   D  maximise log det M;
//   A  minimise trace M⁻¹           (the sum of the parameters' variances);
//   E  maximise λ_min(M)            (the worst-determined direction);
//   I  minimise trace(W M⁻¹)        (the average prediction variance over rows w with W = avg w
//   wᵀ).
// The rows are in a coordinate system where every candidate set spans the space (the estimable
// space of the full candidate set; analysis/plan.cpp builds it), already divided by the noise.
//
// Algorithm: the modified Fedorov exchange (Cook & Nachtsheim 1980): for each selected unit in
// turn, the best swap with an unselected candidate, until a pass improves nothing; random restarts
// (restart 0 from the sequential D-optimal design, Wynn 1970; the others from random sets), the
// best restart wins. Moves are evaluated by rank-k updates of M⁻¹ (Woodbury) with per-candidate
// caches Z_j M⁻¹ Z_jᵀ and Z_j M⁻¹WM⁻¹ Z_jᵀ, so a swap costs O(k r) per candidate, not O(r³). M
// carries a ridge ε·I (1e-10 of the average candidate's information) so that a singular start has a
// finite criterion that rewards full rank. E has no cheap update: each swap's λ_min is computed
// exactly for the 8 candidates whose swap raises log det the most.
//
// Budget mode (unit costs and a budget instead of a size): a cost-weighted greedy start (gain per
// cost), then swaps and additions within the budget. Restarts are independent and run in parallel;
// each has its own random stream, so the result does not depend on the thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "weilgen/uq/dense.hpp"

namespace weilgen {

enum class DesignCriterion { D, A, E, I };
// "D", "A", "E", "I" (either case); std::invalid_argument "--criterion: ..." otherwise.
DesignCriterion parse_design_criterion(const std::string& text);
const char* design_criterion_name(DesignCriterion criterion);

struct DesignProblem {
  std::vector<Eigen::MatrixXd> units;  // candidate j: k_j × r rows (noise-weighted)
  Eigen::MatrixXd weight;              // r × r, I only: W (A uses the identity)
  std::vector<std::size_t> forced;     // always selected (count toward the size and the cost)
  // Budget mode when `cost` is not empty: one cost per unit (any unit of time) and the budget.
  std::vector<double> cost;
  double budget = 0;
};

struct ExchangeOptions {
  DesignCriterion criterion = DesignCriterion::D;
  std::size_t size = 0;  // units to select in count mode (forced ones included)
  std::size_t restarts = 8;
  std::uint64_t seed = 1;
  unsigned threads = 0;  // 0 = every core
  std::size_t max_passes = 200;
  // restarts >= 1, max_passes >= 1 (std::invalid_argument naming the field).
  void validate() const;
};

struct ExchangeResult {
  std::vector<std::size_t> selected;  // ascending
  // The criterion of the selection without the ridge: D log det M, A trace M⁻¹, I trace(W M⁻¹),
  // E λ_min(M) (−inf / +inf / 0 for a singular M).
  double value = 0;
  double log_det = 0;
  double cost = 0;               // budget mode: the selection's cost
  std::size_t best_restart = 0;  // which restart won
  std::vector<double> restart_values;
  std::size_t passes = 0, exchanges = 0;  // of the winning restart
};

class ExchangeDesign {
 public:
  explicit ExchangeDesign(ExchangeOptions options);  // validates
  const ExchangeOptions& options() const { return options_; }
  // std::invalid_argument for an inconsistent problem (sizes, forced beyond the size or budget,
  // more units asked than candidates).
  ExchangeResult run(const DesignProblem& problem) const;

 private:
  ExchangeOptions options_;
};

// How good any design of n units can be: the optimal continuous (approximate) design of the
// candidates by the multiplicative algorithm (Silvey, Titterington & Torsney 1978: w_j ← w_j d_j/r
// for D; the square-root update w_j ← w_j √(d_j/Φ) for A and I, Fellman 1974), and a bound that
// holds whatever the iterations reached, from the convexity of the criterion (the general
// equivalence theorem, Kiefer & Wolfowitz 1960): with M(ξ) = Σ w_j Z_jᵀ Z_j,
//   D:    log det M* ≤ log det M(ξ) + max_j tr(Z_j M⁻¹ Z_jᵀ) − r,
//   A, I: Φ(M*) ≥ 2 Φ(M(ξ)) − max_j tr(Z_j M⁻¹ W M⁻¹ Z_jᵀ).
// A design of n distinct units is n times a continuous design (weights 1/n on them), so its
// log det is at most bound + r log n, and its trace(W M⁻¹) at least bound / n. E: no bound (NaN).
struct ContinuousBound {
  double bound = 0;  // per unit (n = 1), as above
  double value = 0;  // the criterion of the last iterate (per unit)
  std::size_t iterations = 0;
  std::vector<double> weights;  // of the last iterate
  // The bound for n units, in ExchangeResult::value's terms.
  double for_units(std::size_t n, DesignCriterion criterion, std::size_t r) const;
};
ContinuousBound continuous_design(const DesignProblem& problem, DesignCriterion criterion,
                                  std::size_t iterations, unsigned threads = 0);

// The criterion of an information matrix (no ridge), as ExchangeResult::value.
double design_criterion(const Eigen::MatrixXd& information, DesignCriterion criterion,
                        const Eigen::MatrixXd& weight);

// The observability indices of kinematic calibration from the singular values σ_1 ≥ … ≥ σ_L of
// the (scaled) identification Jacobian with m observations (docs/planning.md gives the sources):
//   O1 = (σ_1 ⋯ σ_L)^(1/L) / √m   (Borm & Menq 1991)
//   O2 = σ_L / σ_1                 (Driels & Pathre 1990: the inverse condition number)
//   O3 = σ_L                       (Nahvi, Hollerbach & Hayward 1994: the smallest singular value)
//   O4 = σ_L² / σ_1                (Nahvi & Hollerbach 1996: the noise amplification index)
//   O5 = 1 / Σ 1/σ_i               (Sun & Hollerbach 2008)
struct ObservabilityIndices {
  double o1 = 0, o2 = 0, o3 = 0, o4 = 0, o5 = 0;
};
ObservabilityIndices observability_indices(const Eigen::VectorXd& singular_values,
                                           std::size_t observations);

}  // namespace weilgen
