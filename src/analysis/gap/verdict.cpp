// The verdict from the greedy explanation (docs/gap.md, "Verdict").
#include "verdict.hpp"

#include <optional>

#include "weilgen/base/format.hpp"

namespace weilgen {

std::string GapVerdict::str() const {
  switch (kind) {
    case Kind::None:
      return "none";
    case Kind::Effect:
      return effect;
    case Kind::Unexplained:
      break;
  }
  return "unexplained";
}

}  // namespace weilgen

namespace weilgen::gap_detail {

std::string percent(double fraction) { return format_fixed(100 * fraction, 0) + " %"; }

namespace {

// "p = 0.0031"
std::string p_is(double p) { return "p = " + format_significant(p, 2); }

// No significant gap: "none", with the candidates that came closest.
GapVerdict no_gap(const GapResult& R) {
  GapVerdict v;
  v.reason = "the held-out gap is at the noise floor (" + p_is(R.baseline.p_value) +
             ") and the model fits all data (lack of fit " + p_is(R.baseline_lack_of_fit_p) + ")";
  std::string close;
  for (const EffectFit& f : R.effects)
    if (f.p_value < kCloseCandidateP && close.size() < kCloseCandidatesText)
      close += (close.empty() ? "" : ", ") + f.name + " (" + p_is(f.p_value) +
               (f.significant ? ", significant in training but not needed" : "") + ")";
  if (!close.empty()) v.reason += "; closest candidates: " + close;
  return v;
}

GapVerdict unexplained(std::string why) {
  return {GapVerdict::Kind::Unexplained, "", std::move(why)};
}

GapVerdict named(const std::string& effect, std::string why) {
  return {GapVerdict::Kind::Effect, effect, std::move(why)};
}

// The verdict when the explanation cannot name its effect: an indistinguishable shape, or a
// shape that needs a second one along the same coordinate and output. Empty when it can.
std::optional<GapVerdict> unnameable(const GapResult& R, const GapOptions& opt,
                                     const std::vector<std::string>& axes,
                                     const std::vector<std::pair<int, int>>& shape) {
  const EffectFit& first = R.explanation.front();
  for (std::size_t k = 0; k < R.explanation.size(); ++k) {
    const EffectFit& f = R.explanation[k];
    if (f.distinguishable || (k > 0 && shape[k] != shape[0])) continue;
    if (shape[k].first < 0) return unexplained(f.name + " fits, but " + f.indistinct_reason);
    const std::string along = axes[static_cast<std::size_t>(shape[k].first)];
    const std::string out = observation_name(static_cast<std::size_t>(shape[k].second));
    return unexplained(f.name + " along " + along + " in " + out + " fits, but " +
                       f.indistinct_reason);
  }
  if (shape[0].first >= 0 && first.explained_fraction < opt.explain_fraction)
    for (std::size_t k = 1; k < R.explanation.size(); ++k)
      if (shape[k] == shape[0])
        return unexplained(first.name + " removes " + percent(first.explained_fraction) +
                           " of the excess and needs " + R.explanation[k].name +
                           " along the same coordinate and output: a shape outside the library");
  return std::nullopt;
}

}  // namespace

void decide_verdict(GapResult& R, const GapOptions& opt, const std::vector<std::string>& axes,
                    bool gap_significant, ExplainedShare& share,
                    const std::vector<std::pair<int, int>>& shape) {
  if (!gap_significant) {
    R.verdict = no_gap(R);
    return;
  }
  if (R.explanation.empty()) {
    if (R.baseline.p_value < opt.alpha)
      R.verdict =
          unexplained("a significant held-out gap that no candidate of the library removes");
    else
      R.verdict = unexplained(
          "the model leaves a structure along " + R.baseline_lack_of_fit_along +
          " on all data (lack of fit " + p_is(R.baseline_lack_of_fit_p) +
          ") that no candidate of the library removes; the held-out gap is at the floor (" +
          p_is(R.baseline.p_value) + ")");
    return;
  }
  if (auto v = unnameable(R, opt, axes, shape)) {
    R.verdict = *v;
    return;
  }
  const EffectFit& first = R.explanation.front();
  // Accepted on overwhelming evidence while the gap over all held-out data is at the floor: the
  // excess over the floor is mostly noise, so the share of it an effect removes says nothing.
  // The effect stands if nothing significant remains.
  const bool by_evidence = R.baseline.p_value >= opt.alpha;
  if (by_evidence && R.final.p_value >= opt.alpha) {
    std::string why = first.name + " is significant on its own (" + p_is(first.p_value) +
                      ") although the held-out gap over all data is at the noise floor (" +
                      p_is(R.baseline.p_value) + ")";
    if (R.baseline_lack_of_fit_p < overwhelming(opt.alpha))
      why += "; on all data the model alone leaves a structure along " +
             R.baseline_lack_of_fit_along + " (lack of fit " + p_is(R.baseline_lack_of_fit_p) + ")";
    R.verdict = named(first.name, std::move(why));
    return;
  }
  const double explained = share.larger();
  if (explained < kMinExplainedShare) {
    R.verdict = unexplained("the accepted effects remove only " + percent(explained) +
                            " of the excess held-out sum of squares");
    return;
  }
  if (R.final.p_value < opt.alpha) {
    if (explained < opt.explain_fraction) {
      R.verdict = unexplained("the accepted effects remove " + percent(explained) +
                              " of the excess and leave a significant gap");
      return;
    }
    if (R.final.rms_um > kMaxRmsOverIdeal * R.final.ideal_um) {
      R.verdict = unexplained(
          "the accepted effects leave a significant held-out RMS of more than twice what the "
          "noise floor explains");
      return;
    }
  }
  share.predictable_decides = share.all < kMinExplainedShare ||
                              (R.final.p_value < opt.alpha && share.all < opt.explain_fraction);
  R.verdict =
      named(first.name,
            first.name + " removes " + percent(first.explained_fraction) +
                " of the excess held-out sum of squares" +
                (R.explanation.size() > 1 ? ", the accepted effects " + percent(share.all) : "") +
                (share.predictable_decides
                     ? " (" + percent(share.predictable) + " of the part the folds can predict)"
                     : "") +
                (R.final.p_value >= opt.alpha ? "; the remaining gap is at the noise floor" : ""));
}

void check_lack_of_fit(GapResult& R, const GapOptions& opt, const ExplainedShare& share,
                       const LackOfFit& lof, double base_sse) {
  if (R.explanation.empty() || !R.verdict.names(R.explanation.front().name)) return;
  if (share.predictable_decides ? lof.p_value >= opt.alpha : !lof.material(base_sse, opt)) return;
  R.verdict = unexplained(
      R.explanation.front().name +
      (share.predictable_decides
           ? " removes " + percent(share.all) + " of the excess held-out sum of squares (" +
                 percent(share.predictable) + " of the part the folds can predict), but"
           : " fits, but") +
      " leaves a structure along " + lof.along + " (" + percent(lof.share(base_sse)) +
      " of the structure, lack of fit " + p_is(lof.p_value) +
      "): a shape outside the library, which it only imitates");
}

}  // namespace weilgen::gap_detail
