// Internals of the gap diagnosis shared by its files (not a public API): the linear engine
// (the baseline factored in blocks, the fits of every split, extra columns fitted by
// projection), the F-test helpers, the noise floor and the localisation.
#pragma once

#include <limits>
#include <memory>
#include <numeric>
#include <vector>

#include "weilgen/analysis/gap.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/uq/dense.hpp"

namespace weilgen::gap_detail {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using Index = Eigen::Index;

// Upper tail of F(d1, d2); 1 for degenerate inputs.
double f_sf(double f, double d1, double d2);
// Distinct finite values.
std::size_t distinct(const std::vector<double>& v);

// ---- The linear engine (docs/gap.md, "Baseline"; docs/performance.md, "Gap diagnosis") ----
// The design is factored once per block of observations: A_b = Q_b R_b with Q_b orthonormal
// (n_b × k_b, k_b the block's numerical rank) and R_b (k_b × p). A block never straddles a
// held-out part, so every split's training part is a union of blocks and its fit is the
// column-equilibrated SVD of the stacked R_b (a few hundred rows whatever the number of
// observations): the same SVD as that of the training rows of A, to rounding. Extra columns E
// are projected once per block (Q_bᵀ E_b) and the projections serve every split.
struct BlockFactors {
  std::vector<std::vector<std::size_t>> rows;  // observation indices of each block, ascending
  std::vector<int> part;                       // the block's part of the partition
  std::vector<MatrixXd> Q, R;
  std::vector<VectorXd> qty;  // Q_bᵀ y_b
  Index cols = 0;             // p
  unsigned threads = 1;       // for the loops over the blocks (factor_blocks' `threads`)
};

// Factors A (rows × p) in blocks: each part of `parts` (observation indices) is cut into
// blocks of at most kBlockRows rows; blocks are factored in parallel (the blocks do not depend
// on the thread count, so neither do the results).
inline constexpr std::size_t kBlockRows = 4096;
std::shared_ptr<const BlockFactors> factor_blocks(
    const MatrixXd& A, const VectorXd& y, const std::vector<std::vector<std::size_t>>& parts,
    unsigned threads);

// The fit of the blocks of some parts (a split's training part, or all data): θ (minimum norm,
// rank cut 1e-9 on equilibrated columns), the pseudo-inverse's right factor VS (A⁺ = VS Uᵀ),
// U = blockdiag(Q_b) · UM, and R_b θ per block for the residual of projected columns.
struct FoldFit {
  std::vector<std::size_t> blocks;                // the training blocks
  MatrixXd UM, VS;                                // (Σ k_b × rank), (p × rank)
  std::vector<VectorXd> Rtheta;                   // per training block (same order as `blocks`)
  std::vector<VectorXd> qty;                      // per training block: Q_bᵀ y_b
  VectorXd theta, res_train, res_test, lev_test;  // res_* in the split's train/test order
  VectorXd lev_train;   // leverage of each training row (only when asked for)
  double train_ss = 0;  // |res_train|²
  std::size_t rank = 0;
};

// The fit of `s` (its training rows must be a union of blocks, its test rows too).
FoldFit fit_split(const BlockFactors& F, const MatrixXd& A, const VectorXd& y, const Split& s,
                  bool train_leverage = false);

// One fit on all rows (gross readings): factored in blocks on `threads` cores; with the
// leverage of every row.
FoldFit fit_all_rows(const MatrixXd& A, const VectorXd& y, const Split& s, unsigned threads = 1);

inline MatrixXd rows_of(const MatrixXd& M, const std::vector<std::size_t>& idx) {
  MatrixXd R(static_cast<Index>(idx.size()), M.cols());
  for (std::size_t i = 0; i < idx.size(); ++i)
    R.row(static_cast<Index>(i)) = M.row(static_cast<Index>(idx[i]));
  return R;
}
inline VectorXd rows_of(const VectorXd& v, const std::vector<std::size_t>& idx) {
  VectorXd R(static_cast<Index>(idx.size()));
  for (std::size_t i = 0; i < idx.size(); ++i)
    R[static_cast<Index>(i)] = v[static_cast<Index>(idx[i])];
  return R;
}

// The split that trains on every observation (and holds none out).
inline Split all_rows(std::size_t n) {
  Split s;
  s.train.resize(n);
  std::iota(s.train.begin(), s.train.end(), 0);
  return s;
}

// The least-squares system over the design: A (the model's coefficient columns, plus the
// accepted effects' columns) against the measured values y, fitted on all rows and on every
// split, factored once in the splits' blocks.
class DesignLeastSquares {
 public:
  DesignLeastSquares(const GapData& d, MatrixXd design, VectorXd values, unsigned threads_)
      : data(d), A(std::move(design)), y(std::move(values)), threads(threads_) {}
  const GapData& data;
  MatrixXd A;  // baseline (plus accepted effects)
  VectorXd y;
  unsigned threads = 1;
  std::vector<Split> splits;
  std::shared_ptr<const BlockFactors> factors;  // of A, in blocks of the splits' parts
  std::vector<FoldFit> folds;
  double full_sse = 0;
  std::size_t full_rank = 0;
  FoldFit full;  // the fit on all data

  // The fit on all data (its rank sizes the splits; its SSE is the F tests' reference).
  void fit_full();
  // Factors A in the splits' blocks and fits every split (and all data again, from the same
  // factors) in parallel.
  void fit_folds();
  // Held-out residual and leverage per observation.
  void heldout(VectorXd& r, VectorXd& h) const {
    r = VectorXd::Constant(y.size(), kNaN);
    h = VectorXd::Zero(y.size());
    for (std::size_t f = 0; f < splits.size(); ++f)
      for (std::size_t i = 0; i < splits[f].test.size(); ++i) {
        r[static_cast<Index>(splits[f].test[i])] = folds[f].res_test[static_cast<Index>(i)];
        h[static_cast<Index>(splits[f].test[i])] = folds[f].lev_test[static_cast<Index>(i)];
      }
  }
};

// The covariance of the held-out residuals under the null hypothesis (the model right, white
// noise of variance σ²; docs/gap.md, "Noise floor"): an observation k held out by split f has
// r_k = e_k − a_kᵀ A_f⁺ e_f, so Cov(r_k, r_l) = σ² c(k, l) with
//   c(k, l) = δ_kl + a_kᵀ G_f a_l                  (k and l held out by the same split f),
//   c(k, l) = a_kᵀ G_f N_fg G_g a_l − [k trains g] a_kᵀ G_g a_l − [l trains f] a_kᵀ G_f a_l
//                                                 (k held out by f, l by g),
// G_f = A_f⁺A_f⁺ᵀ = VS_f VS_fᵀ (so c(k, k) = 1 + h_k) and N_fg = Σ a_i a_iᵀ over the rows both
// splits train on. Built from the engine's fits (its splits and folds must be current).
//
// `estimable`: the same for the part of the held-out residual each split's training part can
// predict (docs/gap.md, "The held-out gap test"). A held-out row a_k of split f has a part b_k
// outside the span of f's training rows; the minimum-norm fit predicts nothing along it, so r_k
// carries b_kᵀθ of the true errors θ, which no noise model contains. The residuals of split f are
// projected off the span of B_f = [b_kᵀ] (M_f = I − U_f U_fᵀ, U_f its left singular vectors,
// cut kEstimableCut of A_test's largest on equilibrated columns): M_f r_f is free of θ, and its
// covariance is the above with every held-out row a_k replaced by the rows of M_f A_test and δ_kl
// by (M_f)_kl.
inline constexpr double kEstimableCut = 1e-6;
class HeldoutCovariance {
 public:
  explicit HeldoutCovariance(const DesignLeastSquares& e, bool estimable = false);
  // Replaces the held-out residual `r` by M r (split by split) and sets `h` so that
  // c(k, k) = 1 + h_k; `removed`: the directions taken out over all splits (the degrees of
  // freedom the gap test loses). Without `estimable`, M = I.
  void estimable(VectorXd& r, VectorXd& h, std::size_t& removed) const;
  // c(k, l); NaN when k or l is not held out.
  double operator()(std::size_t k, std::size_t l) const;
  // c(·, l) prepared for many k (O(p) per k instead of O(p · rank)).
  struct Column {
    std::size_t obs = 0;
    VectorXd Gg_al;           // G_g a_l
    std::vector<VectorXd> u;  // per split f ≠ g: C_fg w_l − [l trains f] VS_fᵀ a_l
  };
  Column column(std::size_t l) const;
  double operator()(std::size_t k, const Column& c) const;
  // Var(d_i − d̄)/σ² of the centred successive differences d_i = r_{i+1} − r_i of the held-out
  // residuals of `obs` (in sequence order; d̄ their mean); with one difference, Var(d_0)/σ².
  std::vector<double> difference_variances(const std::vector<std::size_t>& obs) const;

 private:
  double cross(std::size_t k, std::size_t l) const;
  const DesignLeastSquares* e_;
  std::vector<int> split_;        // the split holding each observation out (-1: none)
  std::vector<std::size_t> pos_;  // its row in that split's test part
  // The held-out row of k (M_f A_test's with `estimable`).
  auto row(std::size_t k) const {
    return rows_[static_cast<std::size_t>(split_[k])].row(static_cast<Index>(pos_[k]));
  }
  std::vector<MatrixXd> rows_;  // per split: A_test (M_f A_test with `estimable`)
  std::vector<MatrixXd> U_;     // per split: U_f (no columns without `estimable`)
  std::vector<MatrixXd> W_;     // per split: rows_ VS (rows w_{k,f}ᵀ; h_k = |w_{k,f}|²)
  std::vector<std::vector<char>> train_;  // per split: trains on observation i
  std::vector<std::vector<MatrixXd>> C_;  // C_fg = VS_fᵀ N_fg VS_g
};

// Groups of extra columns (a variant's, observations × q each) seen through block factors:
// G_b = Q_bᵀ E_b for all groups at once (one pass over the blocks), and per group E_bᵀE_b and
// E_bᵀy_b.
// The fit from these sums (fit_extra) reads a column's part outside the model's span as the
// difference |E|² − |P|²; when that part is small (below 1e-3 of the column) the difference has
// lost digits, and the exact projection (project_exact: one group, the rest E_b − Q_b G_b
// formed and orthogonalised twice, its Gram matrix summed directly) takes over.
struct Projection {
  std::vector<MatrixXd> G;                 // per block: k_b × m
  std::vector<std::vector<MatrixXd>> EtE;  // per block, per group: q × q
  std::vector<std::vector<VectorXd>> Ety;  // per block, per group: q
  std::vector<Index> start, width;         // each group's columns
  bool exact = false;                      // one group; Perp and Perpy hold the rest's sums
  std::vector<MatrixXd> Perp;              // per block: (E_b − Q_b G_b)ᵀ(E_b − Q_b G_b)
  std::vector<VectorXd> Perpy;             // per block: (E_b − Q_b G_b)ᵀ y_b
};
Projection project(const BlockFactors& F, const std::vector<MatrixXd>& groups, const VectorXd& y);
Projection project_exact(const BlockFactors& F, const MatrixXd& E, const VectorXd& y);

// The least-squares fit of one group of projected columns to the training residual of split
// fold `ff` (the joint fit [A_train E_train], by projection): the columns' coefficients c, their
// projection P = Uᵀ E_train onto the model's span, and the training SSE after. A column whose
// part outside the model's span and the group's other columns is below 1e-6 of its norm is
// dropped (coefficient 0); no usable column: `usable` false. `ill_conditioned`: a kept column's
// part is below 1e-3 of it and the projection is not exact (fit again from project_exact).
struct ExtraFit {
  bool usable = false, ill_conditioned = false;
  VectorXd coef;
  MatrixXd P;
  double train_sse = 0;
};
ExtraFit fit_extra(const FoldFit& ff, const Projection& pr, std::size_t group);
// fit_extra, again from the exact projection of the group's columns E_group (computed once
// into `exact` when a fit needs it).
ExtraFit fit_extra(const FoldFit& ff, const Projection& pr, std::size_t group,
                   const BlockFactors& F, const Eigen::Ref<const MatrixXd>& E_group,
                   const VectorXd& y, Projection& exact);

// The held-out residual after the extra columns of `fit` (split `s`, fit `ff`): res_test −
// (E_test − A_test·VS·P)·c.
VectorXd heldout_after(const FoldFit& ff, const Split& s, const MatrixXd& A, const MatrixXd& E,
                       const ExtraFit& fit);

// The joint least-squares fit of [A E] on all data, from A's block factors (docs/gap.md, the
// nested F test): its rank (equilibrated SVD, cut 1e-9), SSE and the coefficients of E.
struct JointFit {
  std::size_t rank = 0;
  double sse = 0;
  VectorXd coef;  // of E's columns (minimum-norm joint solution)
};
JointFit joint_fit(const BlockFactors& F, const MatrixXd& A, const VectorXd& y, const MatrixXd& E);
// The part of a fitted combination E c of shape terms that the data determine. In the metric of
// the shapes (z = L c, LᵀL = EᵀE) the eigen-directions of the Gram matrix of E's part outside
// A's span (from the fit on all data, `full`) are shapes with a fraction λ of their squared norm
// outside it; those with λ < kDeterminedFraction² are nearly absorbed by the model (their
// coefficient is traded against the model's errors and can be anything). When the fitted shape's
// part along them is more than kAbsurd times the rest (RMS over the observations), returns c
// with them left out and their number in `absorbed`; else c whole (absorbed 0).
inline constexpr double kDeterminedFraction = 0.1, kAbsurd = 10;
VectorXd determined_part(const BlockFactors& F, const FoldFit& full, const MatrixXd& E,
                         const VectorXd& c, std::size_t& absorbed);
// The rank of [A E] alone (the same cut).
std::size_t joint_rank(const BlockFactors& F, const MatrixXd& E);

// Baseline θ of a split in the parameterisation's full size (effects may append columns).
inline std::vector<double> split_theta(const VectorXd& theta, std::size_t np) {
  return std::vector<double>(theta.data(), theta.data() + static_cast<Index>(np));
}

struct Gap {
  double ss = 0, expected = 0;  // Σ r², Σ σ²(1 + h)
  std::size_t n = 0;
  std::size_t removed = 0;  // directions projected out (estimable_heldout): n − removed dof
};

// Excess RMS over the floor and the F-test p-value of a set of held-out residuals.
inline void gap_stats(const Gap& g, double dof, double& excess, double& p) {
  excess = g.n ? std::sqrt(std::max(0.0, (g.ss - g.expected) / static_cast<double>(g.n))) : 0;
  p = g.n > g.removed ? f_sf(g.ss / g.expected, static_cast<double>(g.n - g.removed), dof) : 1;
}

// Gross readings in the residual `res` of a fit on all of `d` whose leverages are `lev`
// (docs/gap.md, "Outliers").
std::vector<GapOutlier> find_outliers(const GapData& d, const VectorXd& res, const VectorXd& lev);

// Gross readings of `d` against the model whose design is `A` (row i: observation i; the
// baseline, or the baseline and the accepted effects), in rounds until a round finds none.
std::vector<GapOutlier> gross_readings(const MatrixXd& A, const GapData& d, unsigned threads);

// `d` without the observations `gross` (sorted by observation); `kept` receives the indices
// into `d` of the observations kept, in order.
GapData without_readings(const GapData& d, const std::vector<GapOutlier>& gross,
                         std::vector<std::size_t>& kept);

// The noise floor of the held-out residual (docs/gap.md, "Noise floor"); `cov` its covariance
// under the null hypothesis (the small-scale estimate is unbiased under it).
NoiseFloor noise_floor(const GapData& d, const VectorXd& heldout, const HeldoutCovariance& cov);

// Where the held-out residual concentrates (docs/gap.md, "Where").
std::vector<GapRegion> localise(const GapData& d, const VectorXd& r, const VectorXd& h,
                                const NoiseFloor& nf, double alpha);

}  // namespace weilgen::gap_detail
