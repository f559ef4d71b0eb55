// Internals of the gap diagnosis shared by its files (not a public API): the linear engine
// (the per-fold SVD fits of the baseline), the F-test helpers, the noise floor and the
// localisation.
#pragma once

#include <Eigen/Dense>
#include <limits>
#include <numeric>
#include <vector>

#include "weilgen/analysis/gap.hpp"

namespace weilgen::gap_detail {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using Index = Eigen::Index;
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Upper tail of F(d1, d2); 1 for degenerate inputs.
double f_sf(double f, double d1, double d2);
// Distinct finite values.
std::size_t distinct(const std::vector<double>& v);

// The training fit of one split: A_tr = U S Vᵀ (equilibrated, rank r), the pseudo-inverse as
// VS·Uᵀ, residuals and test leverages.
struct FoldFit {
  MatrixXd U, VS, W;  // W = A_test · VS
  VectorXd theta, res_train, res_test, lev_test;
  std::size_t rank = 0;
};

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

FoldFit fit_fold(const MatrixXd& A, const VectorXd& y, const Split& s);

// The split that trains on every observation (and holds none out).
inline Split all_rows(std::size_t n) {
  Split s;
  s.train.resize(n);
  std::iota(s.train.begin(), s.train.end(), 0);
  return s;
}

struct Engine {
  const GapData& data;
  MatrixXd A;  // baseline (plus accepted effects)
  VectorXd y;
  std::vector<Split> splits;
  std::vector<FoldFit> folds;
  double full_sse = 0;
  std::size_t full_rank = 0;
  FoldFit full;  // the fit on all data

  // The fit on all data (its rank sizes the splits; its SSE is the F tests' reference).
  void fit_full() {
    full = fit_fold(A, y, all_rows(static_cast<std::size_t>(y.size())));
    full_sse = full.res_train.squaredNorm();
    full_rank = full.rank;
  }
  void fit_folds() {
    folds.clear();
    for (const Split& s : splits) folds.push_back(fit_fold(A, y, s));
  }
  void refit() {
    fit_full();
    fit_folds();
  }
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

// Baseline θ of a split in the parameterisation's full size (effects may append columns).
inline std::vector<double> split_theta(const VectorXd& theta, std::size_t np) {
  return std::vector<double>(theta.data(), theta.data() + static_cast<Index>(np));
}

struct Gap {
  double ss = 0, expected = 0;  // Σ r², Σ σ²(1 + h)
  std::size_t n = 0;
};

// Excess RMS over the floor and the F-test p-value of a set of held-out residuals.
inline void gap_stats(const Gap& g, double dof, double& excess, double& p) {
  excess = g.n ? std::sqrt(std::max(0.0, (g.ss - g.expected) / static_cast<double>(g.n))) : 0;
  p = g.n ? f_sf((g.ss / g.expected), static_cast<double>(g.n), dof) : 1;
}

// Gross readings in the baseline's full-data residual `r` (docs/gap.md, "Outliers").
std::vector<GapOutlier> find_outliers(const GapData& d, const VectorXd& r);

// The noise floor of the held-out residual (docs/gap.md, "Noise floor").
NoiseFloor noise_floor(const GapData& d, const VectorXd& heldout);

// Where the held-out residual concentrates (docs/gap.md, "Where").
std::vector<GapRegion> localise(const GapData& d, const VectorXd& r, const VectorXd& h,
                                const NoiseFloor& nf, double alpha);

}  // namespace weilgen::gap_detail
