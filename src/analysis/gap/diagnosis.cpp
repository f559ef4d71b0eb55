// The gap diagnosis as named steps (docs/gap.md §1–5; docs/architecture.md, "The gap
// diagnosis"): GapSearch::run fits the baseline, tests the held-out gap, builds the candidates,
// searches greedily, summarises and decides; diagnose() wraps it in the rounds that remove gross
// readings.
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>

#include "effects.hpp"
#include "internal.hpp"
#include "scoring.hpp"
#include "verdict.hpp"
#include "weilgen/analysis/per_output_rms.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen {

using namespace gap_detail;

void GapOptions::validate() const {
  if (!(alpha > 0 && alpha < 0.5)) throw std::invalid_argument("--alpha must be in (0, 0.5)");
  if (!(explain_fraction > 0 && explain_fraction <= 1))
    throw std::invalid_argument("gap: explain_fraction must be in (0, 1]");
  if (max_effects < 1) throw std::invalid_argument("gap: max_effects must be >= 1");
  for (const std::string& n : effects)
    if (std::find(gap_effect_names().begin(), gap_effect_names().end(), n) ==
        gap_effect_names().end())
      throw std::invalid_argument("--effects: unknown effect '" + n +
                                  "' (the library: " + join(gap_effect_names()) + ")");
}

GapDiagnosis::GapDiagnosis(GapOptions options) : options_(std::move(options)) {
  options_.validate();
}

namespace {

// Diagnoses that may end in removing gross readings against the accepted effects (each such
// round removes at least one reading; the second normally finds none).
constexpr int kGrossRounds = 4;

// The shape degrees of freedom the data leave along the coordinate of shape variant `v` beyond
// the baseline design (its block factors F, rank rank0): the rank that one free value per
// distinct position adds, each observation seeing it with the shaped error's sensitivity (or its
// weight in the output).
std::size_t shape_dof_free(const BlockFactors& F, std::size_t rank0, const GapData& d,
                           const Variant& v) {
  const auto& obs = d.points.observations;
  const auto axis = static_cast<std::size_t>(v.shape_axis);
  auto weight = [&](std::size_t i) {
    return v.shape_weight ? (*v.shape_weight)[static_cast<Index>(i)]
                          : observation_weight(obs[i], v.shape_output);
  };
  std::vector<double> levels;
  for (std::size_t i = 0; i < obs.size(); ++i)
    if (weight(i) != 0) levels.push_back(d.points.poses[obs[i].row][axis]);
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  MatrixXd G = MatrixXd::Zero(static_cast<Index>(obs.size()), static_cast<Index>(levels.size()));
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const double w = weight(i);
    if (w == 0) continue;
    const double q = d.points.poses[obs[i].row][axis];
    const auto l = std::lower_bound(levels.begin(), levels.end(), q) - levels.begin();
    G(static_cast<Index>(i), l) = w;
  }
  const std::size_t r = joint_rank(F, G);
  return r > rank0 ? r - rank0 : 0;
}

// The held-out residual `res` (leverage `lev`) summarised against the floor's variance s2 (µm²):
// RMS and largest per output and over all, and the RMS a right model would leave,
// sqrt(σ² mean(1 + h)).
HeldoutSummary summarise(const std::vector<PointObservation>& obs, const VectorXd& res,
                         const VectorXd& lev, double s2) {
  PerOutputRms<kObservationKinds> residual, ideal;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const double v = res[static_cast<Index>(i)];
    if (!std::isfinite(v)) continue;
    const auto o = static_cast<std::size_t>(obs[i].output);
    residual.add(o, v);
    ideal.add_square(o, s2 * (1 + lev[static_cast<Index>(i)]));
  }
  HeldoutSummary s;
  s.rms = residual.rms_per_output();
  s.max = residual.max_per_output();
  s.rms_um = residual.rms();
  s.ideal = ideal.rms_per_output();
  s.ideal_um = ideal.rms();
  return s;
}

// The (coordinate, shaped quantity) a shape effect acts along: its axis and the shaped error's
// name, or the output's index when it shapes an output.
using ShapeKey = std::pair<int, std::string>;
ShapeKey shape_key(const Variant& v) {
  return {v.shape_axis, v.shape_key.empty() ? std::to_string(v.shape_output) : v.shape_key};
}

// One diagnosis of data whose gross readings were taken out (docs/gap.md §1–5). The steps run
// once, in the order of run(); the object holds what they pass on.
class GapSearch {
 public:
  GapSearch(const GapOptions& opt, const Model& model, const ErrorParameterisation& param,
            const GapData& data)
      : opt_(opt), model_(model), param_(param), data_(data), obs_(data.points.observations) {}
  GapSearch(const GapSearch&) = delete;
  GapSearch& operator=(const GapSearch&) = delete;

  GapResult run(const HoldoutScheme& scheme, const std::string& reason) {
    fit_baseline(scheme, reason);
    test_baseline_gap();
    build_candidates();
    search();
    summarise_final();
    decide();
    add_effect_regions();
    return R_;
  }
  // The design of the baseline and the accepted effects (gross readings are found against it).
  const MatrixXd& design() const { return e_->A; }

 private:
  // §1–2: the baseline fitted on all data and on every split, its held-out residual, the noise
  // floor from the part the splits can predict, the baseline's summary and where the residual
  // concentrates.
  void fit_baseline(const HoldoutScheme& scheme, const std::string& reason) {
    R_.holdout = scheme.str();
    R_.holdout_reason = reason;
    R_.observations = obs_.size();
    R_.count = data_.points.count;
    R_.parameters = param_.size();
    VectorXd values(static_cast<Index>(obs_.size()));
    for (std::size_t i = 0; i < obs_.size(); ++i) values[static_cast<Index>(i)] = obs_[i].value;
    e_ = std::make_unique<DesignLeastSquares>(data_, design_matrix(model_, param_, data_.points),
                                              values, opt_.threads);
    e_->fit_full();
    R_.rank = e_->full_rank;
    e_->splits = make_splits(data_, scheme, R_.rank + 5);
    if (scheme.kind != HoldoutScheme::Kind::Forward) {  // the folds actually used (K <= groups)
      HoldoutScheme used = scheme;
      used.folds = static_cast<int>(e_->splits.size());
      R_.holdout = used.str();
    }
    e_->fit_folds();
    e_->heldout(r_, h_);
    // The floor from the part of the held-out residual its splits can predict (a fold's
    // undetermined directions would count as noise). The baseline's covariance serves the gap
    // test too; it is built again only when an accepted effect changes the fits.
    base_cov_ = std::make_unique<HeldoutCovariance>(*e_, true);
    {
      VectorXd m = r_, lev;
      std::size_t removed = 0;
      base_cov_->estimable(m, lev, removed);
      R_.noise = noise_floor(data_, m, *base_cov_);
    }
    s2_ = R_.noise.sigma_um * R_.noise.sigma_um;
    R_.baseline = summarise(obs_, r_, h_, s2_);
    base_ = heldout_gap(r_, h_);
    base_estimable_ = estimable_gap(*base_cov_, r_);
    cur_gap_ = base_estimable_;
    gap_stats(cur_gap_, R_.noise.dof, R_.baseline.excess_um, R_.baseline.p_value);
    R_.where = localise(data_, r_, h_, R_.noise, opt_.alpha);
    R_.residual_before.assign(r_.data(), r_.data() + r_.size());
    cur_r_ = r_, cur_h_ = h_;
    base_full_sse_ = e_->full_sse;
    F0_ = e_->factors;
    rank0_ = e_->full_rank;
  }

  // Σ r² and its expectation σ²(1 + h) over the held-out residuals.
  Gap heldout_gap(const VectorXd& res, const VectorXd& lev) const {
    Gap g;
    for (Index i = 0; i < res.size(); ++i)
      if (std::isfinite(res[i])) g.ss += res[i] * res[i], g.expected += s2_ * (1 + lev[i]), ++g.n;
    return g;
  }
  // The same on the part of each held-out residual its split can predict
  // (HeldoutCovariance::estimable of the engine's fits when `cov` was built): the significance
  // of a gap and its excess.
  Gap estimable_gap(const HeldoutCovariance& cov, const VectorXd& res) const {
    VectorXd m = res, lev;
    std::size_t removed = 0;
    cov.estimable(m, lev, removed);
    Gap g = heldout_gap(m, lev);
    g.removed = removed;
    return g;
  }

  // The gap is significant when the held-out test says so, or on overwhelming evidence the
  // lack of fit on all data: a structure mostly in directions a fold cannot predict, which the
  // held-out test leaves out (estimable_gap), while on all data the model plainly cannot follow
  // it.
  void test_baseline_gap() {
    const LackOfFit lof = lack_of_fit(*e_, data_);
    R_.baseline_lack_of_fit_p = lof.p_value;
    R_.baseline_lack_of_fit_along = lof.along;
    gap_significant_ =
        R_.baseline.p_value < opt_.alpha || R_.baseline_lack_of_fit_p < overwhelming(opt_.alpha);
  }

  // §4: the library's candidates for these data (an effect without its columns, e.g. reversal
  // without a direction, gives none).
  void build_candidates() {
    ctx_.data = &data_;
    ctx_.model = &model_;
    ctx_.param = &param_;
    ctx_.threads = opt_.threads;
    auto chain = std::make_shared<NumericChain>(model_.description());
    chain->set_parameters(model_.parameters());
    ctx_.chain = chain;
    candidates_ = effect_candidates(ctx_, opt_.effects.empty() ? gap_effect_names() : opt_.effects);
    used_.assign(candidates_.size(), false);
  }

  // The greedy explanation (docs/gap.md, "Greedy explanation"): per round every unused candidate
  // is scored against the current model, the best significant one picked and accepted.
  void search() {
    for (int round = 0; round < opt_.max_effects; ++round) {
      std::vector<Evaluated> ev = evaluate_round();
      if (round == 0)
        for (const Evaluated& x : ev) R_.effects.push_back(x.fit);
      const Evaluated* pick = pick_candidate(ev);
      // Only overwhelming evidence of one effect stands for a gap the floor test over all
      // held-out data is too weak to show (a small shape along one axis among many
      // observations). Not for a model refitted per split: its p comes from the held-out residual
      // whole, whose part a fold cannot predict such a refit can partly reach on effect-free
      // data, while the gap test leaves that part out.
      if (round == 0 && pick && !gap_significant_ && !pick->regularised &&
          pick->fit.p_value < overwhelming(opt_.alpha))
        gap_significant_ = true;
      if (!pick || !gap_significant_) break;
      // A round entered on the lack of fit alone seeks the structure all data show: a shape that
      // uses every shape dof the data leave along its coordinate fits any structure there, so it
      // cannot be that explanation.
      if (by_lack_of_fit_ && !pick->fit.distinguishable) break;
      if (!accept(*pick)) break;
    }
  }

  // Every unused candidate scored against the current model, described, its shape checked;
  // ranked by held-out SSE.
  std::vector<Evaluated> evaluate_round() {
    ScoringContext sc;
    sc.engine = e_.get();
    sc.np = param_.size();
    sc.base_r = &cur_r_;
    sc.base_h = &cur_h_;
    sc.s2 = s2_;
    sc.alpha = opt_.alpha;
    sc.n_candidates = static_cast<double>(std::max<std::size_t>(1, candidates_.size()));
    sc.threads = opt_.threads;
    std::vector<Evaluated> all = evaluate_candidates(candidates_, used_, sc);
    std::vector<Evaluated> ev;
    for (std::size_t k = 0; k < candidates_.size(); ++k) {
      if (used_[k]) continue;
      Evaluated x = std::move(all[k]);
      if (!std::isfinite(x.heldout_sse)) continue;
      if (candidates_[k].determined_part) {
        x.fit.terms = static_cast<std::size_t>(x.coef.size());
        const VectorXd c =
            determined_part(*e_->factors, e_->full, x.columns, x.coef, x.fit.terms_absorbed);
        candidates_[k].describe(x.variant, c, x.fit);
      } else {
        candidates_[k].describe(x.variant, x.coef, x.fit);
      }
      check_shape(x.variant, x.fit);
      ev.push_back(std::move(x));
      ev.back().fit.name = candidates_[k].name;
    }
    std::stable_sort(ev.begin(), ev.end(), [](const Evaluated& a, const Evaluated& b) {
      return a.heldout_sse < b.heldout_sse;
    });
    return ev;
  }

  // A shape along one coordinate must leave the data shape degrees of freedom beyond it, or it
  // fits any shape there (a step as well as a bump) and cannot be named.
  void check_shape(const Variant& v, EffectFit& fit) {
    if (v.shape_axis < 0) return;
    const ShapeKey key = shape_key(v);
    if (!dof_free_.count(key)) dof_free_[key] = shape_dof_free(*F0_, rank0_, data_, v);
    fit.shape_dof_free = dof_free_[key];
    fit.shape_dof_used = dof_used_[key] + fit.extra_parameters + v.refine.size();
    if (fit.shape_dof_used >= fit.shape_dof_free) {
      const std::string along = data_.axes[static_cast<std::size_t>(v.shape_axis)];
      fit.distinguishable = false;
      fit.indistinct_reason =
          "the data leave " + std::to_string(fit.shape_dof_free) +
          " shape degrees of freedom along " + along + " beyond the model and the fitted shape" +
          (dof_used_[key] ? "s use " : " uses ") + std::to_string(fit.shape_dof_used) +
          ": any shape would fit as well (a step, a bump, a period); measure "
          "more positions along " +
          along;
    }
  }

  // The best significant candidate, passing over a shape that only imitates: one that leaves a
  // material structure along its own coordinate (LackOfFit::material) gives way to the best
  // significant candidate that follows the held-out data about as well (kAboutAsWell) and leaves
  // none. A structure along another coordinate is another effect for a later round; when every
  // one leaves a structure, the best stays and the verdict judges it.
  const Evaluated* pick_candidate(const std::vector<Evaluated>& ev) {
    const Evaluated* pick = nullptr;
    for (const Evaluated& x : ev)
      if (x.fit.significant) {
        pick = &x;
        break;
      }
    if (!pick || pick->regularised) return pick;
    auto structure = [&](const Evaluated& x) { return lack_of_fit(*e_, data_, &x.columns); };
    const LackOfFit lp = structure(*pick);
    const bool along_itself =
        pick->variant.shape_axis >= 0 &&
        data_.axes[static_cast<std::size_t>(pick->variant.shape_axis)] == lp.along;
    if (!lp.material(base_full_sse_, opt_) || !along_itself) return pick;
    for (const Evaluated& x : ev) {
      if (&x == pick || !x.fit.significant || x.regularised ||
          x.fit.explained_fraction < kAboutAsWell * pick->fit.explained_fraction)
        continue;
      if (!structure(x).material(base_full_sse_, opt_)) {
        passed_over_.emplace_back(
            pick->fit.name,
            pick->fit.name + " follows the held-out data about as well but " +
                "leaves a structure along " + lp.along + " (" + percent(lp.share(base_full_sse_)) +
                " of the structure, lack of fit p = " + format_significant(lp.p_value, 2) + ")");
        return &x;
      }
    }
    return pick;
  }

  // Accepts `x`: its columns join the model, which is refitted on every split. False when the
  // search ends with it: a regularised model, or what is left is no longer significant by the
  // test that started the search (the held-out gap, or on overwhelming evidence the lack of fit
  // on all data: a structure mostly in directions a fold cannot predict still stands out there
  // after another effect took the held-out gap to the floor).
  bool accept(const Evaluated& x) {
    const EffectFit fit = x.fit;
    MatrixXd AE(e_->A.rows(), e_->A.cols() + x.columns.cols());
    AE << e_->A, x.columns;
    e_->A = AE;
    e_->fit_folds();
    lof_after_.reset();
    e_->heldout(cur_r_, cur_h_);
    const HeldoutCovariance cov(*e_, true);
    R_.explanation.push_back(fit);
    // A regularised model's columns joined the design as fitted on all data, so the folds' refit
    // would see held-out rows through them: its own held-out residual (each fold's columns
    // fitted on that fold's training part) is the honest one, and the search ends with it.
    if (x.regularised) {
      cur_r_ = x.heldout;
      cur_gap_ = estimable_gap(cov, cur_r_);
      accepted_shape_.emplace_back(-1, -1);
      return false;
    }
    if (x.variant.shape_axis >= 0) {
      accepted_shape_.emplace_back(x.variant.shape_axis, x.variant.shape_output);
      dof_used_[shape_key(x.variant)] = fit.shape_dof_used;
    } else {
      accepted_shape_.emplace_back(-1, -1);
    }
    for (std::size_t k = 0; k < candidates_.size(); ++k)
      if (candidates_[k].name == fit.name && !effect_repeatable(fit.name)) used_[k] = true;
    cur_gap_ = estimable_gap(cov, cur_r_);
    double excess_um = 0, p = 1;
    gap_stats(cur_gap_, R_.noise.dof, excess_um, p);
    by_lack_of_fit_ = p >= opt_.alpha;
    if (!by_lack_of_fit_) return true;
    lof_after_ = lack_of_fit(*e_, data_);
    return lof_after_->p_value < overwhelming(opt_.alpha);
  }

  // §5: the held-out residual after the accepted effects, and their share of the baseline's
  // excess over the floor (of the whole held-out SS when the floor exceeds it), on all of the
  // held-out residual and on the part the folds can predict (ExplainedShare).
  void summarise_final() {
    R_.final = summarise(obs_, cur_r_, cur_h_, s2_);
    const Gap final_gap = heldout_gap(cur_r_, cur_h_);
    gap_stats(cur_gap_, R_.noise.dof, R_.final.excess_um, R_.final.p_value);
    R_.residual_after.assign(cur_r_.data(), cur_r_.data() + cur_r_.size());
    const double explained_ss = base_.ss - final_gap.ss;
    const double excess_ss = std::max(0.0, base_.ss - base_.expected);
    share_.all =
        excess_ss > 0 ? explained_ss / excess_ss : (base_.ss > 0 ? explained_ss / base_.ss : 0);
    const Gap& b = base_estimable_;
    const Gap f = estimable_gap(*base_cov_, cur_r_);
    const double excess = std::max(0.0, b.ss - b.expected);
    share_.predictable = excess > 0 ? (b.ss - f.ss) / excess : 0;
  }

  // The verdict (docs/gap.md, "Verdict"), the lack-of-fit check of a named effect, and the
  // candidates the pick passed over unless accepted later.
  void decide() {
    decide_verdict(R_, opt_, data_.axes, gap_significant_, share_, accepted_shape_);
    if (!R_.explanation.empty() && R_.verdict.names(R_.explanation.front().name))
      check_lack_of_fit(R_, opt_, share_, lof_after_ ? *lof_after_ : lack_of_fit(*e_, data_),
                        base_full_sse_);
    for (const auto& [name, why] : passed_over_) {
      const std::string& passed = name;  // clang < 16 cannot capture a structured binding
      if (std::none_of(R_.explanation.begin(), R_.explanation.end(),
                       [&](const EffectFit& f) { return f.name == passed; }))
        R_.verdict.reason += "; " + why;
    }
  }

  // The accepted effects' own regions lead the list: where the named cause acts, in the output
  // where it removed the most held-out sum of squares (what the data show of it; the output an
  // error moves most before the model absorbs part of it can be another on a rotary layout).
  void add_effect_regions() {
    std::array<std::size_t, kObservationKinds> per_output{};
    for (std::size_t i = 0; i < obs_.size(); ++i)
      if (std::isfinite(r_[static_cast<Index>(i)]))
        ++per_output[static_cast<std::size_t>(obs_[i].output)];
    std::vector<GapRegion> own;
    for (const EffectFit& f : R_.explanation) {
      if (!f.region) continue;
      GapRegion g = *f.region;
      g.source = "effect";
      double most = 0;
      for (std::size_t o = 0; o < kObservationKinds; ++o) {
        const double removed =
            static_cast<double>(per_output[o]) *
            (f.rms_before[o] * f.rms_before[o] - f.rms_after[o] * f.rms_after[o]);
        if (per_output[o] && std::isfinite(removed) && removed > most)
          most = removed, g.output = observation_name(o);
      }
      if (data_.circle) g.output = "dr";  // a trace's observations are dr
      g.p_value = f.p_value;
      g.significant = f.significant;
      for (std::size_t a = 0; a < data_.axes.size() && a < data_.axis_units.size(); ++a)
        if (data_.axes[a] == g.by) g.unit = data_.axis_units[a];
      own.push_back(g);
    }
    R_.where.insert(R_.where.begin(), own.begin(), own.end());
  }

  const GapOptions& opt_;
  const Model& model_;
  const ErrorParameterisation& param_;
  const GapData& data_;
  const std::vector<PointObservation>& obs_;
  GapResult R_;
  std::unique_ptr<DesignLeastSquares> e_;  // the baseline, then with the accepted effects' columns
  // The baseline's held-out residual and leverage, its covariance, its gap (all of it and the
  // part the folds can predict), its SSE on all data, block factors and rank.
  VectorXd r_, h_;
  std::unique_ptr<HeldoutCovariance> base_cov_;
  Gap base_, base_estimable_;
  double base_full_sse_ = 0;
  std::shared_ptr<const BlockFactors> F0_;
  std::size_t rank0_ = 0;
  double s2_ = 0;  // the floor's variance (µm²)
  bool gap_significant_ = false;
  EffectContext ctx_;  // the candidates refer to it
  std::vector<Candidate> candidates_;
  std::vector<bool> used_;
  // The current model's held-out residual, leverage and gap (the baseline's at first).
  VectorXd cur_r_, cur_h_;
  Gap cur_gap_;
  // Shape effects: free shape dof per (coordinate, shaped quantity), and the dof the accepted
  // ones use; per accepted effect its (coordinate, output), (-1, -1) if none.
  std::map<ShapeKey, std::size_t> dof_free_, dof_used_;
  std::vector<std::pair<int, int>> accepted_shape_;
  // Candidates the pick passed over, and why (said unless accepted later).
  std::vector<std::pair<std::string, std::string>> passed_over_;
  bool by_lack_of_fit_ = false;  // this round goes on on the lack of fit alone
  // The lack of fit of the current model when computed after the last acceptance.
  std::optional<LackOfFit> lof_after_;
  ExplainedShare share_;
};

GapResult diagnose(const GapOptions& opt, const Model& model, const ErrorParameterisation& param,
                   const GapData& data, const HoldoutScheme& scheme, const std::string& reason,
                   int round);

// Diagnosed without the readings `gross`; the result keeps the indexing of `data` (residuals
// NaN for every gross reading) and reports `gross` with those the inner diagnosis found.
GapResult diagnose_without(const GapOptions& opt, const Model& model,
                           const ErrorParameterisation& param, const GapData& data,
                           const HoldoutScheme& scheme, const std::string& reason,
                           std::vector<GapOutlier> gross, int round) {
  std::vector<std::size_t> kept;
  GapResult inner =
      diagnose(opt, model, param, without_readings(data, gross, kept), scheme, reason, round + 1);
  auto spread = [&](const std::vector<double>& v) {
    std::vector<double> full(data.points.observations.size(), kNaN);
    for (std::size_t k = 0; k < kept.size() && k < v.size(); ++k) full[kept[k]] = v[k];
    return full;
  };
  inner.residual_before = spread(inner.residual_before);
  inner.residual_after = spread(inner.residual_after);
  for (GapOutlier& g : inner.outliers) g.observation = kept[g.observation];
  gross.insert(gross.end(), inner.outliers.begin(), inner.outliers.end());
  std::sort(gross.begin(), gross.end(),
            [](const GapOutlier& a, const GapOutlier& b) { return a.observation < b.observation; });
  inner.outliers = std::move(gross);
  return inner;
}

// Gross readings against the baseline first (docs/gap.md, "Outliers"), until none is left; after
// the search against the baseline and the accepted effects, whose residual is not inflated by an
// effect the baseline lacks. Each time the diagnosis runs again without them, so that they
// neither bias the effects nor fail the final gap test. `round` counts the diagnoses before this
// one that removed gross readings.
GapResult diagnose(const GapOptions& opt, const Model& model, const ErrorParameterisation& param,
                   const GapData& data, const HoldoutScheme& scheme, const std::string& reason,
                   int round) {
  if (round == 0)
    if (std::vector<GapOutlier> gross =
            gross_readings(design_matrix(model, param, data.points), data, opt.threads);
        !gross.empty())
      return diagnose_without(opt, model, param, data, scheme, reason, std::move(gross), round);
  GapSearch search(opt, model, param, data);
  GapResult R = search.run(scheme, reason);
  if (!R.explanation.empty() && round < kGrossRounds)
    if (std::vector<GapOutlier> gross = gross_readings(search.design(), data, opt.threads);
        !gross.empty())
      return diagnose_without(opt, model, param, data, scheme, reason, std::move(gross), round);
  return R;
}

}  // namespace

GapResult GapDiagnosis::run(const Model& model, const ErrorParameterisation& param,
                            const GapData& data, const HoldoutScheme& scheme,
                            const std::string& reason) const {
  return diagnose(options_, model, param, data, scheme, reason, 0);
}

}  // namespace weilgen
