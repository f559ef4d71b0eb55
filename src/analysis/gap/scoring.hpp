// Scoring the candidate effects against the engine's current model (docs/gap.md, "Which
// effect"): every variant of every candidate on every split, the refinement of continuous
// hyper-parameters, the held-out residual after the chosen variant and the nested F test.
// Internal to the gap diagnosis.
#pragma once

#include "effects.hpp"
#include "internal.hpp"

namespace weilgen::gap_detail {

// One candidate, evaluated: its chosen (possibly refined) variant and what it does.
struct Evaluated {
  EffectFit fit;
  Variant variant;                // the chosen (possibly refined) variant
  MatrixXd columns;               // full-data columns of the chosen variant (for acceptance)
  VectorXd heldout;               // held-out residual after
  VectorXd coef;                  // full-data coefficients of the columns
  double heldout_sse = INFINITY;  // infinite: no usable variant
  bool regularised = false;       // fitted_columns: columns fitted per training part
};

// What every candidate is scored against: the engine (its splits and fits), the baseline's
// parameter count (effects read θ's first np entries), the held-out residual and leverage
// before, the noise floor's variance (µm²), alpha and the number of candidates (Bonferroni).
struct ScoringContext {
  const DesignLeastSquares* engine = nullptr;
  std::size_t np = 0;
  const VectorXd* base_r = nullptr;
  const VectorXd* base_h = nullptr;
  double s2 = 0, alpha = 0.01, n_candidates = 1;
  unsigned threads = 0;
};

// Every candidate k with !used[k], in parallel (the grid of all candidates' variants first,
// then each candidate's refinement and statistics); entry k belongs to candidate k (an unused
// or unusable one has heldout_sse = infinity). The same for any number of threads: every
// variant's score is computed alone and the choices are made in variant order.
std::vector<Evaluated> evaluate_candidates(const std::vector<Candidate>& candidates,
                                           const std::vector<bool>& used, const ScoringContext& sc);

}  // namespace weilgen::gap_detail
