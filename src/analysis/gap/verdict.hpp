// Judging the greedy explanation (docs/gap.md, "Verdict", "Lack of fit"): the lack of fit of a
// model on all data and the verdict from the accepted effects. Internal to the gap diagnosis.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "internal.hpp"

namespace weilgen::gap_detail {

// The verdict's thresholds, each with its reason (docs/gap.md, "Verdict").
//
// The accepted effects together must remove at least this share of the excess held-out sum of
// squares: two effects at once each remove about half, so the set is judged together.
inline constexpr double kMinExplainedShare = 0.5;
// A significant gap after the effects is still explained when their RMS is at most this multiple
// of what a right model would leave at the floor (prediction error of the folds included).
inline constexpr double kMaxRmsOverIdeal = 2;
// A candidate "follows the held-out data about as well" as the best when it removes at least
// this share of the excess the best removes.
inline constexpr double kAboutAsWell = 0.5;
// The candidates below this p-value are named as the closest when the verdict is "none", up to
// this many characters of reason.
inline constexpr double kCloseCandidateP = 0.5;
inline constexpr std::size_t kCloseCandidatesText = 200;
// Overwhelming evidence: p below alpha to this power (a gap the held-out test cannot show, one
// candidate alone); at alpha itself a second test would double the false alarms.
inline constexpr int kOverwhelmingPower = 3;
inline double overwhelming(double alpha) {
  double a = 1;
  for (int k = 0; k < kOverwhelmingPower; ++k) a *= alpha;
  return a;
}

// What a model leaves along each coordinate (docs/gap.md, "Lack of fit"): one free offset per
// output and per bin of the coordinate (time and every axis that moves; its distinct positions,
// or kBins bins of equal count when it has more) joined to the model, a nested F test on all
// data, Bonferroni over the coordinates. An effect of the library leaves noise; a shape outside
// it that an effect only imitates leaves a structure there.
struct LackOfFit {
  static constexpr std::size_t kBins = 6;
  double p_value = 1;
  std::string along;         // "time" or an axis
  double excess_ss = 0;      // the bins' drop in SSE beyond the noise they fit (q σ²)
  double reference_sse = 0;  // SSE on all data of the model tested (with `extra`)

  // The bins' share of the structure: their excess over it plus the effects' drop in SSE on all
  // data (from the baseline's `base_sse` to reference_sse).
  double share(double base_sse) const {
    return excess_ss / (excess_ss + std::max(0.0, base_sse - reference_sse));
  }
  // Significant and material: more than 1 − explain_fraction of the structure, the share the
  // held-out test asks of an effect. A misfit of a right effect at high SNR is significant but
  // small.
  bool material(double base_sse, const GapOptions& opt) const {
    return p_value < opt.alpha && share(base_sse) > 1 - opt.explain_fraction;
  }
};

// The engine's current model, with `extra` columns joined first (a candidate not yet accepted).
LackOfFit lack_of_fit(const DesignLeastSquares& e, const GapData& d,
                      const MatrixXd* extra = nullptr);

// The accepted effects' share of the baseline's excess held-out sum of squares: over all
// held-out residuals, and over the part each split can predict (HeldoutCovariance::estimable).
// On a small set most of the held-out residual can lie in directions a fold cannot predict, where
// it carries the true errors: no effect removes that part, so the share over all of it
// understates what a right effect explains. The larger share is judged; when only the
// predictable part's meets the thresholds, the evidence is the weaker and the effect must leave
// no significant lack of fit on all data at all.
struct ExplainedShare {
  double all = 0, predictable = 0;
  bool predictable_decides = false;  // set by decide_verdict
  double larger() const { return std::max(all, predictable); }
};

// The verdict and its reason from the greedy explanation of `R` (its baseline, final summary,
// effects and explanation set). `shape`: each accepted effect's (coordinate, output) when it is a
// shape along a coordinate, else (-1, -1).
void decide_verdict(GapResult& R, const GapOptions& opt, const std::vector<std::string>& axes,
                    bool gap_significant, ExplainedShare& share,
                    const std::vector<std::pair<int, int>>& shape);

// A named effect must leave no structure along a coordinate that is significant and material
// (none significant at all when the predictable share decided): otherwise the verdict becomes
// unexplained, with `lof` (of the final model) as the reason.
void check_lack_of_fit(GapResult& R, const GapOptions& opt, const ExplainedShare& share,
                       const LackOfFit& lof, double base_sse);

// "42 %": a fraction as a whole percentage, for reasons.
std::string percent(double fraction);

}  // namespace weilgen::gap_detail
