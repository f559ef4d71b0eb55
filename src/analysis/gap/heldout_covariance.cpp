// The covariance of the held-out residuals under the null hypothesis (internal.hpp,
// HeldoutCovariance; docs/gap.md, "Noise floor"). Everything is read from the splits' fits: no
// observations × observations matrix is formed.
#include <algorithm>
#include <cmath>

#include "internal.hpp"

namespace weilgen::gap_detail {

HeldoutCovariance::HeldoutCovariance(const DesignLeastSquares& e, bool estimable) : e_(&e) {
  const std::size_t n = static_cast<std::size_t>(e.y.size());
  const std::size_t K = e.splits.size();
  split_.assign(n, -1);
  pos_.assign(n, 0);
  W_.resize(K);
  U_.resize(K);
  rows_.resize(K);
  train_.assign(K, std::vector<char>(n, 0));
  const BlockFactors& F = *e.factors;
  std::vector<MatrixXd> RtR(F.R.size());
  MatrixXd all = MatrixXd::Zero(F.cols, F.cols);
  for (std::size_t b = 0; b < F.R.size(); ++b) all += RtR[b] = F.R[b].transpose() * F.R[b];
  // Equilibrated columns: the cut does not depend on the errors' units.
  VectorXd scale = e.A.colwise().norm();
  for (Index j = 0; j < scale.size(); ++j) scale[j] = scale[j] > 0 ? 1 / scale[j] : 1.0;
  const auto D = scale.asDiagonal();
  for (std::size_t f = 0; f < K; ++f) {
    const Split& s = e.splits[f];
    const FoldFit& ff = e.folds[f];
    for (std::size_t i : s.train) train_[f][i] = 1;
    for (std::size_t i = 0; i < s.test.size(); ++i)
      if (split_[s.test[i]] < 0) split_[s.test[i]] = static_cast<int>(f), pos_[s.test[i]] = i;
    rows_[f] = rows_of(e.A, s.test);
    U_[f].resize(rows_[f].rows(), 0);
    if (estimable) {
      // B_f = A_test P, P = I − G_f N_f (A_f⁺A_f = G_f N_f projects onto the training rows'
      // span); its left singular vectors from D BᵀB D = D Pᵀ T P D, T = A_testᵀA_test: nothing
      // grows with the held-out rows but the final products.
      MatrixXd N = MatrixXd::Zero(F.cols, F.cols);
      for (std::size_t b : ff.blocks) N += RtR[b];
      const MatrixXd T = all - N;
      const MatrixXd P = MatrixXd::Identity(F.cols, F.cols) - ff.VS * (ff.VS.transpose() * N);
      const Eigen::SelfAdjointEigenSolver<MatrixXd> top(MatrixXd(D * T * D),
                                                        Eigen::EigenvaluesOnly);
      const Eigen::SelfAdjointEigenSolver<MatrixXd> eig(MatrixXd(D * P.transpose() * T * P * D));
      const double cut = kEstimableCut * kEstimableCut * top.eigenvalues().maxCoeff();
      std::vector<Index> keep;
      for (Index j = 0; j < eig.eigenvalues().size(); ++j)
        if (eig.eigenvalues()[j] > cut) keep.push_back(j);
      U_[f].resize(rows_[f].rows(), static_cast<Index>(keep.size()));
      for (std::size_t j = 0; j < keep.size(); ++j)
        U_[f].col(static_cast<Index>(j)) = rows_[f] * (P * (D * eig.eigenvectors().col(keep[j]))) /
                                           std::sqrt(eig.eigenvalues()[keep[j]]);
      rows_[f] -= U_[f] * (U_[f].transpose() * rows_[f]);  // M_f A_test
    }
    W_[f] = rows_[f] * ff.VS;
  }
  if (K < 2) return;
  // N_fg = Σ a_i a_iᵀ over the rows both splits train on = Σ R_bᵀ R_b over their common blocks
  // (A_b = Q_b R_b, Q_b orthonormal).
  C_.assign(K, std::vector<MatrixXd>(K));
  for (std::size_t f = 0; f < K; ++f)
    for (std::size_t g = 0; g < K; ++g) {
      if (f == g) continue;
      MatrixXd N = MatrixXd::Zero(F.cols, F.cols);
      const auto& bf = e.folds[f].blocks;
      for (std::size_t b : e.folds[g].blocks)
        if (std::binary_search(bf.begin(), bf.end(), b)) N += RtR[b];
      C_[f][g] = e.folds[f].VS.transpose() * N * e.folds[g].VS;
    }
}

// c(k, l) with k held out by f and l by g ≠ f:
//   a_kᵀ G_f N_fg G_g a_l − [k trains g] a_kᵀ G_g a_l − [l trains f] a_kᵀ G_f a_l,
// a_kᵀ G_f = w_{k,f}ᵀ VS_fᵀ with w_{k,f} = VS_fᵀ a_k (W_f's row for k).
double HeldoutCovariance::cross(std::size_t k, std::size_t l) const {
  const auto f = static_cast<std::size_t>(split_[k]), g = static_cast<std::size_t>(split_[l]);
  const auto wk = W_[f].row(static_cast<Index>(pos_[k]));
  const auto wl = W_[g].row(static_cast<Index>(pos_[l]));
  double c = wk.dot(C_[f][g] * wl.transpose());
  if (train_[g][k]) c -= (row(k) * e_->folds[g].VS).dot(wl);
  if (train_[f][l]) c -= wk.dot(row(l) * e_->folds[f].VS);
  return c;
}

double HeldoutCovariance::operator()(std::size_t k, std::size_t l) const {
  const int f = split_[k], g = split_[l];
  if (f < 0 || g < 0) return kNaN;
  if (f != g) return cross(k, l);
  const auto fs = static_cast<std::size_t>(f);
  const auto pk = static_cast<Index>(pos_[k]), pl = static_cast<Index>(pos_[l]);
  return (k == l ? 1.0 : 0.0) - U_[fs].row(pk).dot(U_[fs].row(pl)) +
         W_[fs].row(pk).dot(W_[fs].row(pl));
}

HeldoutCovariance::Column HeldoutCovariance::column(std::size_t l) const {
  Column c;
  c.obs = l;
  const auto g = static_cast<std::size_t>(split_[l]);
  const auto wl = W_[g].row(static_cast<Index>(pos_[l]));
  c.Gg_al = e_->folds[g].VS * wl.transpose();
  c.u.resize(W_.size());
  for (std::size_t f = 0; f < W_.size(); ++f) {
    if (f == g) continue;
    c.u[f] = C_[f][g] * wl.transpose();
    if (train_[f][l]) c.u[f] -= e_->folds[f].VS.transpose() * row(l).transpose();
  }
  return c;
}

double HeldoutCovariance::operator()(std::size_t k, const Column& c) const {
  const int f = split_[k], g = split_[c.obs];
  if (f < 0 || g < 0) return kNaN;
  if (f == g) return (*this)(k, c.obs);
  const auto fk = static_cast<std::size_t>(f);
  double v = W_[fk].row(static_cast<Index>(pos_[k])).dot(c.u[fk].transpose());
  if (train_[static_cast<std::size_t>(g)][k]) v -= row(k).dot(c.Gg_al);
  return v;
}

void HeldoutCovariance::estimable(VectorXd& r, VectorXd& h, std::size_t& removed) const {
  h = VectorXd::Zero(r.size());
  removed = 0;
  for (std::size_t f = 0; f < e_->splits.size(); ++f) {
    const std::vector<std::size_t>& test = e_->splits[f].test;
    const VectorXd rt = rows_of(r, test);
    const VectorXd Mr = rt - U_[f] * (U_[f].transpose() * rt);
    for (std::size_t i = 0; i < test.size(); ++i) {
      const auto o = static_cast<Index>(test[i]), ii = static_cast<Index>(i);
      r[o] = Mr[ii];
      h[o] = W_[f].row(ii).squaredNorm() - U_[f].row(ii).squaredNorm();
    }
    removed += static_cast<std::size_t>(U_[f].cols());
  }
}

std::vector<double> HeldoutCovariance::difference_variances(
    const std::vector<std::size_t>& obs) const {
  std::vector<double> v;
  if (obs.size() < 2) return v;
  const std::size_t k = obs.size() - 1;
  auto diff = [&](std::size_t i) {
    const std::size_t a = obs[i], b = obs[i + 1];
    return (*this)(a, a) + (*this)(b, b) - 2 * (*this)(a, b);
  };
  if (k == 1) return {diff(0)};
  // d_i − d̄ = r_{i+1} − r_i − (r_L − r_F)/k, F and L the sequence's first and last.
  const std::size_t F = obs.front(), L = obs.back();
  const Column cF = column(F), cL = column(L);
  const double kk = static_cast<double>(k);
  const double ends = (*this)(L, L) + (*this)(F, F) - 2 * (*this)(F, L);
  v.resize(k);
  for (std::size_t i = 0; i < k; ++i) {
    const std::size_t a = obs[i], b = obs[i + 1];
    const double mixed = (*this)(b, cL) - (*this)(b, cF) - (*this)(a, cL) + (*this)(a, cF);
    v[i] = diff(i) + ends / (kk * kk) - 2 * mixed / kk;
  }
  return v;
}

}  // namespace weilgen::gap_detail
