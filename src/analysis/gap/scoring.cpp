// Scoring the candidate effects (scoring.hpp; docs/gap.md, "Which effect"). Each variant's
// columns are fitted on every split's training residual by projection off the model's span
// (engine.cpp): the joint least-squares fit [A E] without refactoring A. The grid of every
// candidate's variants is scored in parallel, in batches that share one pass over the blocks;
// then each candidate (in parallel) refines its best variant and gets its statistics.
#include "scoring.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "weilgen/analysis/per_output_rms.hpp"
#include "weilgen/base/parallel.hpp"

namespace weilgen::gap_detail {

namespace {

// Variants of one candidate scored by one task, and projected together (one pass over the
// blocks) up to this many columns.
constexpr std::size_t kBatch = 32;
constexpr Index kBatchColumns = 32;

// Columns that depend on nothing but the variant (not on θ, not fitted on a training part).
bool is_plain(const Candidate& c, const Variant& v) { return !v.needs_theta && !c.fitted_columns; }

// The score of one variant: the training SSE summed over the splits and, when asked, the
// held-out residual after (NaN for observations no split holds out).
struct Score {
  bool usable = false;
  double train_sse = INFINITY;
  VectorXd after;
  MatrixXd columns;  // a plain variant's full-data columns
};

// The columns of a θ-dependent variant for the fit `ff` (on the rows `train`): at its θ, then
// (theta_iterations) at the θ of the joint fit [A E] with those columns; a candidate's own
// nonlinear refit instead when it has one.
MatrixXd theta_columns(const Candidate& c, const Variant& v, const DesignLeastSquares& e,
                       const FoldFit& ff, std::size_t np, const std::vector<std::size_t>& train) {
  if (c.refit) return c.columns(v, c.refit(train, ff.theta, e.A, e.y));
  MatrixXd E = c.columns(v, split_theta(ff.theta, np));
  for (int it = 0; it < v.theta_iterations; ++it) {
    Projection exact;
    const ExtraFit x = fit_extra(ff, project(*e.factors, {E}, e.y), 0, *e.factors, E, e.y, exact);
    if (!x.usable) break;
    E = c.columns(v, split_theta(VectorXd(ff.theta - ff.VS * (x.P * x.coef)), np));
  }
  return E;
}

// A θ-dependent variant's columns per split and, last, on all data (theta_columns), computed
// before the candidates are evaluated (evaluate_candidates); empty: compute them when needed.
using SplitColumns = std::vector<MatrixXd>;

Score score(const Candidate& c, const Variant& v, const ScoringContext& sc, bool want_after,
            const SplitColumns* pre = nullptr) {
  const DesignLeastSquares& e = *sc.engine;
  Score s;
  const bool plain = is_plain(c, v);
  Projection shared, shared_exact;
  if (plain) {
    s.columns = c.columns(v, {});
    shared = project(*e.factors, {s.columns}, e.y);
  }
  if (want_after) s.after = VectorXd::Constant(e.y.size(), kNaN);
  double sse = 0;
  for (std::size_t f = 0; f < e.splits.size(); ++f) {
    const Split& split = e.splits[f];
    const FoldFit& ff = e.folds[f];
    MatrixXd E;
    Projection own, own_exact;
    if (!plain) {
      E = c.fitted_columns       ? c.fitted_columns(v, split.train, ff.res_train)
          : pre && !pre->empty() ? (*pre)[f]
                                 : theta_columns(c, v, e, ff, sc.np, split.train);
      own = project(*e.factors, {E}, e.y);
    }
    const ExtraFit x = plain ? fit_extra(ff, shared, 0, *e.factors, s.columns, e.y, shared_exact)
                             : fit_extra(ff, own, 0, *e.factors, E, e.y, own_exact);
    if (!x.usable) return Score{};  // the model already spans these columns
    sse += x.train_sse;
    if (want_after) {
      const VectorXd a = heldout_after(ff, split, e.A, plain ? s.columns : E, x);
      for (std::size_t i = 0; i < split.test.size(); ++i)
        s.after[static_cast<Index>(split.test[i])] = a[static_cast<Index>(i)];
    }
  }
  s.usable = true;
  s.train_sse = sse;
  return s;
}

// The training SSE of plain variants [begin, end) of `c` (infinity: not usable), projected
// kBatchColumns columns at a time.
void score_batch(const Candidate& c, std::size_t begin, std::size_t end, const ScoringContext& sc,
                 std::vector<double>& sse) {
  const DesignLeastSquares& e = *sc.engine;
  std::vector<MatrixXd> cols;
  Index width = 0;
  std::size_t first = begin;
  for (std::size_t k = begin; k < end; ++k) {
    cols.push_back(c.columns(c.variants[k], {}));
    width += cols.back().cols();
    if (width < kBatchColumns && k + 1 < end) continue;
    const Projection pr = project(*e.factors, cols, e.y);
    for (std::size_t g = 0; g < cols.size(); ++g) {
      double total = 0;
      Projection exact;
      for (std::size_t f = 0; f < e.splits.size() && std::isfinite(total); ++f) {
        const ExtraFit x = fit_extra(e.folds[f], pr, g, *e.factors, cols[g], e.y, exact);
        total = x.usable ? total + x.train_sse : INFINITY;
      }
      sse[first + g] = total;
    }
    cols.clear();
    width = 0;
    first = k + 1;
  }
}

// One candidate: its best grid variant (`grid`: the plain variants' training SSE, already
// scored; null: score them here), refined, then held-out before/after and the nested F test.
// `pre`: per variant, its θ-dependent columns when already computed (SplitColumns).
Evaluated evaluate_one(const Candidate& c, const ScoringContext& sc,
                       const std::vector<double>* grid, const std::vector<SplitColumns>& pre) {
  const DesignLeastSquares& e = *sc.engine;
  Evaluated best;
  double best_train = INFINITY;
  bool have_after = false;
  MatrixXd best_shared;
  const SplitColumns* best_pre = nullptr;
  for (std::size_t k = 0; k < c.variants.size(); ++k) {
    Score s;
    const SplitColumns* own = k < pre.size() ? &pre[k] : nullptr;
    if (grid) {
      s.train_sse = (*grid)[k];
    } else {
      s = score(c, c.variants[k], sc, true, own);
      if (!s.usable) continue;
    }
    if (!(s.train_sse < best_train)) continue;
    best_train = s.train_sse;
    best_pre = own;
    best.variant = c.variants[k];
    if (!grid) {
      best.heldout = std::move(s.after);
      best_shared = std::move(s.columns);
      have_after = true;
    }
  }
  // Continuous hyper-parameters (a period, a lag, a bump's centre and width) are refined between
  // their grid neighbours by golden section on the training SSE, one after the other, twice; the
  // p-value keeps the grid's multiplicity.
  if (std::isfinite(best_train) && !best.variant.refine.empty()) {
    Variant v = best.variant;
    auto sse_at = [&](std::size_t k, double x) {
      Variant t = v;
      t.hyper[k] = x;
      const Score s = score(c, t, sc, false);
      return s.usable ? s.train_sse : static_cast<double>(INFINITY);
    };
    const double g = (std::sqrt(5.0) - 1) / 2;
    for (int pass = 0; pass < 2; ++pass)
      for (const auto& r : v.refine) {
        double lo = r.lo, hi = r.hi;
        double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
        double f1 = sse_at(r.index, x1), f2 = sse_at(r.index, x2);
        for (int it = 0; it < 30 && hi - lo > 1e-6 * std::abs(hi); ++it) {
          if (f1 < f2) {
            hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = sse_at(r.index, x1);
          } else {
            lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = sse_at(r.index, x2);
          }
        }
        const double x = f1 < f2 ? x1 : x2;
        if (std::min(f1, f2) < sse_at(r.index, v.hyper[r.index])) v.hyper[r.index] = x;
      }
    Score s = score(c, v, sc, true);
    if (s.usable && s.train_sse < best_train) {
      best_train = s.train_sse;
      best_pre = nullptr;
      best.variant = v;
      best.heldout = std::move(s.after);
      best_shared = std::move(s.columns);
      have_after = true;
    }
  }
  best.fit.name = c.name;
  best.regularised = c.fitted_columns || c.refit;
  if (!std::isfinite(best_train)) return best;
  if (!have_after) {
    Score s = score(c, best.variant, sc, true, best_pre);
    best.heldout = std::move(s.after);
    best_shared = std::move(s.columns);
  }
  best.fit.variant = best.variant.label;
  const std::size_t n = static_cast<std::size_t>(e.y.size());
  best.columns = c.fitted_columns
                     ? c.fitted_columns(best.variant, all_rows(n).train, e.full.res_train)
                 : best.variant.needs_theta
                     ? (best_pre && !best_pre->empty()
                            ? best_pre->back()
                            : theta_columns(c, best.variant, e, e.full, sc.np, all_rows(n).train))
                     : std::move(best_shared);
  best.fit.tested_variants = static_cast<double>(c.variants.size());
  // Held-out before/after.
  const VectorXd& base_r = *sc.base_r;
  const VectorXd& base_h = *sc.base_h;
  Gap before, afterg;
  PerOutputRms<kObservationKinds> rms_before, rms_after;
  const auto& obs = e.data.points.observations;
  for (Index i = 0; i < e.y.size(); ++i) {
    if (!std::isfinite(best.heldout[i])) continue;
    const auto o = static_cast<std::size_t>(obs[static_cast<std::size_t>(i)].output);
    rms_before.add(o, base_r[i]);
    rms_after.add(o, best.heldout[i]);
    before.ss += base_r[i] * base_r[i];
    afterg.ss += best.heldout[i] * best.heldout[i];
    before.expected += sc.s2 * (1 + base_h[i]);
    ++before.n;
  }
  best.heldout_sse = afterg.ss;
  best.fit.rms_before = rms_before.rms_per_output();
  best.fit.rms_after = rms_after.rms_per_output();
  const double nn = static_cast<double>(before.n);
  best.fit.heldout_rms_before_um = std::sqrt(before.ss / nn);
  best.fit.heldout_rms_after_um = std::sqrt(afterg.ss / nn);
  best.fit.shrink_pct = 100 * (1 - best.fit.heldout_rms_after_um / best.fit.heldout_rms_before_um);
  const double excess_before = std::max(0.0, before.ss - before.expected);
  // Of the excess over the floor; of the whole held-out SS when the floor already exceeds it.
  const double denominator = excess_before > 0 ? excess_before : before.ss;
  best.fit.explained_fraction =
      denominator > 0 ? std::clamp((before.ss - afterg.ss) / denominator, 0.0, 1.0) : 0;
  // Nested-model F test on all data, corrected for variants and candidates: the joint fit
  // [A E] from A's block factors.
  const JointFit f1 = joint_fit(*e.factors, e.A, e.y, best.columns);
  const double q = static_cast<double>(f1.rank) - static_cast<double>(e.full_rank);
  const double d2 = static_cast<double>(e.y.size()) - static_cast<double>(f1.rank);
  best.fit.extra_parameters = static_cast<std::size_t>(std::max(0.0, q));
  if (q > 0 && d2 > 0) {
    best.fit.f_statistic = ((e.full_sse - f1.sse) / q) / (f1.sse / d2);
    best.fit.p_value = std::min(
        1.0, f_sf(best.fit.f_statistic, q, d2) * best.fit.tested_variants * sc.n_candidates);
  }
  if (best.regularised && q > 0 && before.n > static_cast<std::size_t>(q) + 1) {
    // A model fitted per split (with regularisation, or a nonlinear refit) has more effective
    // parameters than columns, so its in-sample F test flatters it; its held-out improvement
    // does not: test that instead.
    const double dh = nn - q;
    best.fit.f_statistic = ((before.ss - afterg.ss) / q) / (afterg.ss / dh);
    best.fit.p_value = std::min(
        1.0, f_sf(best.fit.f_statistic, q, dh) * best.fit.tested_variants * sc.n_candidates);
  }
  // Held-out improvement must also beat chance: the drop in held-out SS against the floor.
  const double heldout_gain = (before.ss - afterg.ss) / sc.s2;
  best.fit.significant = best.fit.p_value < sc.alpha && heldout_gain > 0;
  best.coef = f1.coef;  // full-data coefficients, for the description
  return best;
}

}  // namespace

std::vector<Evaluated> evaluate_candidates(const std::vector<Candidate>& candidates,
                                           const std::vector<bool>& used,
                                           const ScoringContext& sc) {
  const std::size_t nc = candidates.size();
  std::vector<Evaluated> out(nc);
  // The grid: batches of plain variants, every candidate's at once.
  struct Batch {
    std::size_t candidate, begin, end;
  };
  std::vector<Batch> batches;
  std::vector<std::vector<double>> grid(nc);
  std::vector<char> batched(nc, 0);
  for (std::size_t k = 0; k < nc; ++k) {
    const Candidate& c = candidates[k];
    if (used[k]) continue;
    batched[k] = std::all_of(c.variants.begin(), c.variants.end(),
                             [&](const Variant& v) { return is_plain(c, v); });
    if (!batched[k]) continue;
    grid[k].assign(c.variants.size(), INFINITY);
    for (std::size_t b = 0; b < c.variants.size(); b += kBatch)
      batches.push_back({k, b, std::min(c.variants.size(), b + kBatch)});
  }
  parallel_blocks(batches.size(), 1, sc.threads,
                  [&](std::size_t t, std::size_t, std::size_t, unsigned) {
                    const Batch& b = batches[t];
                    score_batch(candidates[b.candidate], b.begin, b.end, sc, grid[b.candidate]);
                  });
  // The θ-dependent variants' columns (a nonlinear refit, or columns at the split's θ) of the
  // candidates without refinement: one task per variant and split, so that a slow candidate's
  // splits (higher_order's refit of the exact chain) share the cores instead of running one
  // after the other on one of them.
  const DesignLeastSquares& e = *sc.engine;
  const std::size_t n = static_cast<std::size_t>(e.y.size()), ns = e.splits.size();
  std::vector<std::vector<SplitColumns>> pre(nc);
  struct Task {
    std::size_t candidate, variant, split;  // split ns: all data
  };
  std::vector<Task> tasks;
  for (std::size_t k = 0; k < nc; ++k) {
    const Candidate& c = candidates[k];
    if (used[k] || batched[k] || c.fitted_columns ||
        std::any_of(c.variants.begin(), c.variants.end(),
                    [](const Variant& v) { return !v.refine.empty(); }))
      continue;
    pre[k].resize(c.variants.size());
    for (std::size_t v = 0; v < c.variants.size(); ++v) {
      if (!c.variants[v].needs_theta) continue;
      pre[k][v].resize(ns + 1);
      for (std::size_t f = 0; f <= ns; ++f) tasks.push_back({k, v, f});
    }
  }
  parallel_blocks(
      tasks.size(), 1, sc.threads, [&](std::size_t t, std::size_t, std::size_t, unsigned) {
        const Task& task = tasks[t];
        const Candidate& c = candidates[task.candidate];
        const bool all = task.split == ns;
        pre[task.candidate][task.variant][task.split] =
            theta_columns(c, c.variants[task.variant], e, all ? e.full : e.folds[task.split], sc.np,
                          all ? all_rows(n).train : e.splits[task.split].train);
      });
  // Then each candidate, the longest first (refinement, columns that depend on θ or are fitted
  // per split): the order only balances the cores.
  std::vector<std::size_t> order, rest;
  for (std::size_t k = 0; k < nc; ++k) {
    if (used[k]) continue;
    const bool refine = std::any_of(candidates[k].variants.begin(), candidates[k].variants.end(),
                                    [](const Variant& v) { return !v.refine.empty(); });
    (refine || !batched[k] ? order : rest).push_back(k);
  }
  order.insert(order.end(), rest.begin(), rest.end());
  parallel_blocks(
      order.size(), 1, sc.threads, [&](std::size_t t, std::size_t, std::size_t, unsigned) {
        const std::size_t k = order[t];
        out[k] = evaluate_one(candidates[k], sc, batched[k] ? &grid[k] : nullptr, pre[k]);
      });
  for (std::size_t k = 0; k < nc; ++k) out[k].fit.name = candidates[k].name;
  return out;
}

}  // namespace weilgen::gap_detail
