// The linear engine of the gap diagnosis (internal.hpp): the baseline design factored once per
// block of observations, the fits of every split from those factors, and extra columns fitted
// by projection. Nothing here builds an observations × observations matrix or refactors the
// whole design for a candidate: per candidate column the work is one pass over the blocks
// (Q_bᵀ E_b), and per split a few products of (folds · rank) × rank matrices.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "internal.hpp"
#include "weilgen/base/parallel.hpp"
#include "weilgen/uq/lsq.hpp"
#include "weilgen/uq/test_statistics.hpp"

namespace weilgen::gap_detail {

double f_sf(double f, double d1, double d2) {
  if (!(f > 0) || !(d1 > 0) || !(d2 > 0) || !std::isfinite(f)) return f > 0 ? 0.0 : 1.0;
  return fisher_f_sf(f, d1, d2);
}

std::size_t distinct(const std::vector<double>& v) {
  std::set<double> s;
  for (double x : v)
    if (std::isfinite(x)) s.insert(x);
  return s.size();
}

namespace {

// Singular values of an equilibrated block below this fraction of its largest are dropped: far
// below the fits' rank cut (1e-9), far above rounding, so a block's structural null space (the
// model's unidentifiable combinations) costs no columns of Q_b.
constexpr double kBlockRankTolerance = 1e-13;
// A fit's rank cut on equilibrated columns (docs/gap.md, "Baseline").
constexpr double kRankTolerance = 1e-9;
// An extra column is usable when its part outside the model's span (and outside the variant's
// other columns) is at least this fraction of its norm.
constexpr double kUsableFraction = 1e-6;
// Below this fraction the sums |E|² − |P|² have lost more than 1e-10 of the part's square.
constexpr double kExactFraction = 1e-3;

// A_b = Q_b R_b for the rows `rows` of A: Householder QR, then the equilibrated SVD of the small
// triangle to find the block's rank k_b; Q_b = Q·U_k, R_b = U_kᵀ·R (an exactly zero column of
// A_b stays exactly zero in R_b).
void factor_one(const MatrixXd& A, const VectorXd& y, const std::vector<std::size_t>& rows,
                MatrixXd& Q, MatrixXd& R, VectorXd& qty) {
  MatrixXd Ab = rows_of(A, rows);
  const Index nb = Ab.rows(), m = std::min(nb, A.cols());
  Eigen::HouseholderQR<Eigen::Ref<MatrixXd>> qr(Ab);
  const MatrixXd Rt = qr.matrixQR().topRows(m).triangularView<Eigen::Upper>();
  const EquilibratedSvd svd(Rt, kBlockRankTolerance, /*full_v=*/false);
  const auto k = static_cast<Index>(svd.rank());
  Q = MatrixXd::Zero(nb, k);
  Q.topRows(m) = svd.U().leftCols(k);
  Q.applyOnTheLeft(qr.householderQ());
  R = svd.U().leftCols(k).transpose() * Rt;
  qty = Q.transpose() * rows_of(y, rows);
}

// The blocks whose rows are all training rows of `s` (rows in no block, such as the held-out
// part of a fit on one part, are simply not used).
std::vector<std::size_t> training_blocks(const BlockFactors& F, const Split& s, std::size_t n) {
  std::vector<char> test(n, 0);
  for (std::size_t i : s.test) test[i] = 1;
  std::vector<std::size_t> b;
  for (std::size_t k = 0; k < F.rows.size(); ++k)
    if (!F.rows[k].empty() && !test[F.rows[k][0]]) b.push_back(k);
  return b;
}

// The signature partition of the splits: observations held out by the same splits form one
// part, so every split's training and held-out parts are unions of parts.
std::vector<std::vector<std::size_t>> split_parts(const std::vector<Split>& splits, std::size_t n) {
  std::vector<std::vector<int>> held(n);
  for (std::size_t f = 0; f < splits.size(); ++f)
    for (std::size_t i : splits[f].test) held[i].push_back(static_cast<int>(f));
  std::map<std::vector<int>, std::size_t> index;
  std::vector<std::vector<std::size_t>> parts;
  for (std::size_t i = 0; i < n; ++i) {
    const auto [it, inserted] = index.emplace(held[i], parts.size());
    if (inserted) parts.emplace_back();
    parts[it->second].push_back(i);
  }
  return parts;
}

}  // namespace

std::shared_ptr<const BlockFactors> factor_blocks(
    const MatrixXd& A, const VectorXd& y, const std::vector<std::vector<std::size_t>>& parts,
    unsigned threads) {
  auto F = std::make_shared<BlockFactors>();
  F->cols = A.cols();
  F->threads = threads;
  for (std::size_t j = 0; j < parts.size(); ++j) {
    const std::size_t n = parts[j].size();
    const std::size_t pieces = std::max<std::size_t>(1, (n + kBlockRows - 1) / kBlockRows);
    for (std::size_t c = 0; c < pieces; ++c) {
      const auto b = static_cast<std::ptrdiff_t>(n * c / pieces);
      const auto e = static_cast<std::ptrdiff_t>(n * (c + 1) / pieces);
      if (e == b) continue;
      F->rows.emplace_back(parts[j].begin() + b, parts[j].begin() + e);
      F->part.push_back(static_cast<int>(j));
    }
  }
  const std::size_t nb = F->rows.size();
  F->Q.resize(nb);
  F->R.resize(nb);
  F->qty.resize(nb);
  parallel_blocks(nb, 1, threads, [&](std::size_t k, std::size_t, std::size_t, unsigned) {
    factor_one(A, y, F->rows[k], F->Q[k], F->R[k], F->qty[k]);
  });
  return F;
}

FoldFit fit_split(const BlockFactors& F, const MatrixXd& A, const VectorXd& y, const Split& s,
                  bool train_leverage) {
  FoldFit f;
  f.blocks = training_blocks(F, s, static_cast<std::size_t>(y.size()));
  Index rows = 0;
  for (std::size_t b : f.blocks) rows += F.R[b].rows();
  MatrixXd M(rows, F.cols);
  VectorXd z(rows);
  Index at = 0;
  for (std::size_t b : f.blocks) {
    M.middleRows(at, F.R[b].rows()) = F.R[b];
    z.segment(at, F.R[b].rows()) = F.qty[b];
    at += F.R[b].rows();
  }
  const EquilibratedSvd svd(M, kRankTolerance, /*full_v=*/false);
  f.rank = svd.rank();
  f.UM = svd.U().leftCols(static_cast<Index>(f.rank));
  f.VS = svd.pinv_right();
  f.theta = svd.solve(z);
  for (std::size_t b : f.blocks) {
    f.Rtheta.push_back(F.R[b] * f.theta);
    f.qty.push_back(F.qty[b]);
  }
  const VectorXd r = y - A * f.theta;
  f.res_train = rows_of(r, s.train);
  f.res_test = rows_of(r, s.test);
  f.train_ss = f.res_train.squaredNorm();
  // h_i = a_iᵀ (AᵀA)⁺ a_i = |VSᵀ a_i|².
  f.lev_test = (rows_of(A, s.test) * f.VS).rowwise().squaredNorm();
  if (train_leverage) {
    // h_i = |U row i|², U = blockdiag(Q_b) · UM.
    VectorXd h = VectorXd::Zero(y.size());
    at = 0;
    for (std::size_t b : f.blocks) {
      const VectorXd hb = (F.Q[b] * f.UM.middleRows(at, F.R[b].rows())).rowwise().squaredNorm();
      for (std::size_t i = 0; i < F.rows[b].size(); ++i)
        h[static_cast<Index>(F.rows[b][i])] = hb[static_cast<Index>(i)];
      at += F.R[b].rows();
    }
    f.lev_train = rows_of(h, s.train);
  }
  return f;
}

FoldFit fit_all_rows(const MatrixXd& A, const VectorXd& y, const Split& s, unsigned threads) {
  const auto F = factor_blocks(A, y, {s.train}, threads);
  return fit_split(*F, A, y, s, /*train_leverage=*/true);
}

void DesignLeastSquares::fit_full() {
  const std::size_t n = static_cast<std::size_t>(y.size());
  factors = factor_blocks(A, y, {all_rows(n).train}, threads);
  full = fit_split(*factors, A, y, all_rows(n));
  full_sse = full.train_ss;
  full_rank = full.rank;
}

void DesignLeastSquares::fit_folds() {
  const std::size_t n = static_cast<std::size_t>(y.size());
  factors = factor_blocks(A, y, split_parts(splits, n), threads);
  folds.assign(splits.size(), FoldFit{});
  // Every split and then all data, from the same factors.
  parallel_blocks(splits.size() + 1, 1, threads,
                  [&](std::size_t k, std::size_t, std::size_t, unsigned) {
                    if (k < splits.size())
                      folds[k] = fit_split(*factors, A, y, splits[k]);
                    else
                      full = fit_split(*factors, A, y, all_rows(n));
                  });
  full_sse = full.train_ss;
  full_rank = full.rank;
}

Projection project(const BlockFactors& F, const std::vector<MatrixXd>& groups, const VectorXd& y) {
  Projection pr;
  Index m = 0;
  for (const MatrixXd& g : groups) {
    pr.start.push_back(m);
    pr.width.push_back(g.cols());
    m += g.cols();
  }
  const std::size_t nb = F.rows.size();
  pr.G.resize(nb);
  pr.EtE.assign(nb, std::vector<MatrixXd>(groups.size()));
  pr.Ety.assign(nb, std::vector<VectorXd>(groups.size()));
  MatrixXd Eb;
  for (std::size_t b = 0; b < nb; ++b) {
    // The block's rows of every group side by side: one product with Q_b for all of them.
    const auto nr = static_cast<Index>(F.rows[b].size());
    Eb.resize(nr, m);
    for (std::size_t g = 0; g < groups.size(); ++g)
      for (Index c = 0; c < pr.width[g]; ++c)
        for (Index i = 0; i < nr; ++i)
          Eb(i, pr.start[g] + c) =
              groups[g](static_cast<Index>(F.rows[b][static_cast<std::size_t>(i)]), c);
    const VectorXd yb = rows_of(y, F.rows[b]);
    pr.G[b].noalias() = F.Q[b].transpose() * Eb;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      const auto cols = Eb.middleCols(pr.start[g], pr.width[g]);
      pr.EtE[b][g].noalias() = cols.transpose() * cols;
      pr.Ety[b][g].noalias() = cols.transpose() * yb;
    }
  }
  return pr;
}

Projection project_exact(const BlockFactors& F, const MatrixXd& E, const VectorXd& y) {
  Projection pr;
  pr.exact = true;
  pr.start = {0};
  pr.width = {E.cols()};
  const std::size_t nb = F.rows.size();
  pr.G.resize(nb);
  pr.EtE.assign(nb, std::vector<MatrixXd>(1));
  pr.Ety.assign(nb, std::vector<VectorXd>(1));
  pr.Perp.resize(nb);
  pr.Perpy.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    MatrixXd Eb = rows_of(E, F.rows[b]);
    const VectorXd yb = rows_of(y, F.rows[b]);
    pr.EtE[b][0].noalias() = Eb.transpose() * Eb;
    pr.Ety[b][0].noalias() = Eb.transpose() * yb;
    pr.G[b].noalias() = F.Q[b].transpose() * Eb;
    Eb.noalias() -= F.Q[b] * pr.G[b];
    const MatrixXd G2 = F.Q[b].transpose() * Eb;
    Eb.noalias() -= F.Q[b] * G2;
    pr.G[b] += G2;
    pr.Perp[b].noalias() = Eb.transpose() * Eb;
    pr.Perpy[b].noalias() = Eb.transpose() * yb;
  }
  return pr;
}

ExtraFit fit_extra(const FoldFit& ff, const Projection& pr, std::size_t group) {
  ExtraFit x;
  const Index j0 = pr.start[group], q = pr.width[group];
  const Index r = ff.UM.cols();
  // P = Uᵀ E_train, H = E_trainᵀ E_train, g = E_trainᵀ (y − A θ) over the training blocks.
  x.P = MatrixXd::Zero(r, q);
  MatrixXd H = MatrixXd::Zero(q, q);
  VectorXd g = VectorXd::Zero(q);
  Index at = 0;
  for (std::size_t k = 0; k < ff.blocks.size(); ++k) {
    const std::size_t b = ff.blocks[k];
    const auto Gb = pr.G[b].middleCols(j0, q);
    x.P.noalias() += ff.UM.middleRows(at, Gb.rows()).transpose() * Gb;
    H += pr.EtE[b][group];
    g += pr.Ety[b][group];
    g.noalias() -= Gb.transpose() * ff.Rtheta[k];
    at += Gb.rows();
  }
  // The columns scaled by their norms before projection, so that the usable test reads the
  // fraction of each column outside the span.
  VectorXd d = H.diagonal().cwiseMax(0.0).cwiseSqrt();
  for (Index k = 0; k < q; ++k)
    if (!(d[k] > 0)) d[k] = 1;
  MatrixXd Hperp;
  if (!pr.exact) {
    Hperp = H - x.P.transpose() * x.P;
  } else {
    // E_train − U P = (E_b − Q_b G_b) over the blocks plus blockdiag(Q_b)·(G − UM P): two
    // orthogonal parts, each summed from explicit small or orthogonalised factors.
    Hperp = MatrixXd::Zero(q, q);
    g.setZero();
    at = 0;
    for (std::size_t k = 0; k < ff.blocks.size(); ++k) {
      const std::size_t b = ff.blocks[k];
      const Index kb = pr.G[b].rows();
      const MatrixXd D = pr.G[b] - ff.UM.middleRows(at, kb) * x.P;
      Hperp += pr.Perp[b];
      Hperp.noalias() += D.transpose() * D;
      g += pr.Perpy[b];
      // The residual's part in block b's span: Q_bᵀ y_b − R_b θ.
      g.noalias() += D.transpose() * (ff.qty[k] - ff.Rtheta[k]);
      at += kb;
    }
  }
  MatrixXd S = d.cwiseInverse().asDiagonal() * Hperp * d.cwiseInverse().asDiagonal();
  VectorXd v = g.cwiseQuotient(d);
  // Cholesky of the projected Gram matrix with the pivoting of a column-pivoted QR (the largest
  // remaining column first): the triangle is that QR's R.
  std::vector<Index> piv(static_cast<std::size_t>(q));
  std::iota(piv.begin(), piv.end(), Index{0});
  Index rank = 0;
  for (; rank < q; ++rank) {
    Index j = rank;
    for (Index i = rank + 1; i < q; ++i)
      if (S(i, i) > S(j, j)) j = i;
    if (!(S(j, j) > kUsableFraction * kUsableFraction)) break;
    if (!pr.exact && S(j, j) < kExactFraction * kExactFraction) x.ill_conditioned = true;
    if (j != rank) {
      S.row(rank).swap(S.row(j));
      S.col(rank).swap(S.col(j));
      std::swap(v[rank], v[j]);
      std::swap(piv[static_cast<std::size_t>(rank)], piv[static_cast<std::size_t>(j)]);
    }
    const double l = std::sqrt(S(rank, rank));
    S(rank, rank) = l;
    for (Index i = rank + 1; i < q; ++i) S(i, rank) /= l;
    for (Index i = rank + 1; i < q; ++i)
      for (Index c = rank + 1; c <= i; ++c) {
        S(i, c) -= S(i, rank) * S(c, rank);
        S(c, i) = S(i, c);
      }
  }
  if (rank == 0) return x;
  x.usable = true;
  const auto L = S.topLeftCorner(rank, rank).triangularView<Eigen::Lower>();
  const VectorXd w = L.solve(v.head(rank));  // Qᵀ r of the QR
  const VectorXd cs = L.transpose().solve(w);
  x.coef = VectorXd::Zero(q);
  for (Index i = 0; i < rank; ++i) x.coef[piv[static_cast<std::size_t>(i)]] = cs[i];
  x.coef = x.coef.cwiseQuotient(d);
  x.train_sse = ff.train_ss - w.squaredNorm();
  return x;
}

ExtraFit fit_extra(const FoldFit& ff, const Projection& pr, std::size_t group,
                   const BlockFactors& F, const Eigen::Ref<const MatrixXd>& E_group,
                   const VectorXd& y, Projection& exact) {
  ExtraFit x = fit_extra(ff, pr, group);
  if (!x.ill_conditioned) return x;
  if (!exact.exact) exact = project_exact(F, MatrixXd(E_group), y);
  return fit_extra(ff, exact, 0);
}

VectorXd heldout_after(const FoldFit& ff, const Split& s, const MatrixXd& A, const MatrixXd& E,
                       const ExtraFit& fit) {
  const VectorXd v = ff.VS * (fit.P * fit.coef);  // the change of θ
  VectorXd after(static_cast<Index>(s.test.size()));
  for (std::size_t k = 0; k < s.test.size(); ++k) {
    const auto i = static_cast<Index>(s.test[k]);
    after[static_cast<Index>(k)] =
        ff.res_test[static_cast<Index>(k)] - (E.row(i).dot(fit.coef) - A.row(i).dot(v));
  }
  return after;
}

namespace {

// [A E] = [blockdiag(Q_b), Q_e] · N with N = [[R, G], [0, R_e]]: G_b = Q_bᵀ E_b (twice, so that
// the rest E_b − Q_b G_b is orthogonal to rounding), Q_e R_e the QR of the rest; z = the same
// basis' transpose times y (when y is given).
void joint_system(const BlockFactors& F, const VectorXd* y, const MatrixXd& E, MatrixXd& N,
                  VectorXd& z) {
  const std::size_t nb = F.rows.size();
  const Index q = E.cols(), p = F.cols;
  Index k = 0, n = 0;
  for (std::size_t b = 0; b < nb; ++b) k += F.R[b].rows(), n += F.Q[b].rows();
  MatrixXd rest(n, q);
  N = MatrixXd::Zero(k + q, p + q);
  VectorXd ys(y ? n : 0);
  z = VectorXd::Zero(k + q);
  // Every block fills its own rows of N, z, rest and ys: in parallel, the same numbers.
  std::vector<Index> at(nb + 1, 0), row(nb + 1, 0);
  for (std::size_t b = 0; b < nb; ++b)
    at[b + 1] = at[b] + F.R[b].rows(), row[b + 1] = row[b] + F.Q[b].rows();
  parallel_blocks(nb, 1, F.threads, [&](std::size_t b, std::size_t, std::size_t, unsigned) {
    const Index kb = F.R[b].rows(), m = F.Q[b].rows();
    MatrixXd Eb = rows_of(E, F.rows[b]);
    const MatrixXd G = F.Q[b].transpose() * Eb;
    Eb.noalias() -= F.Q[b] * G;
    const MatrixXd G2 = F.Q[b].transpose() * Eb;
    Eb.noalias() -= F.Q[b] * G2;
    N.block(at[b], 0, kb, p) = F.R[b];
    N.block(at[b], p, kb, q) = G + G2;
    z.segment(at[b], kb) = F.qty[b];
    rest.middleRows(row[b], m) = Eb;
    if (y) ys.segment(row[b], m) = rows_of(*y, F.rows[b]);
  });
  if (q > 0 && n > 0) {
    Eigen::HouseholderQR<MatrixXd> qr(rest);
    const Index m = std::min(n, q);
    N.block(k, p, m, q) = qr.matrixQR().topRows(m).triangularView<Eigen::Upper>();
    if (y) z.segment(k, m) = (qr.householderQ().adjoint() * ys).head(m);
  }
}

}  // namespace

JointFit joint_fit(const BlockFactors& F, const MatrixXd& A, const VectorXd& y, const MatrixXd& E) {
  MatrixXd N;
  VectorXd z;
  joint_system(F, &y, E, N, z);
  const EquilibratedSvd svd(N, kRankTolerance, /*full_v=*/false);
  const VectorXd theta = svd.solve(z);
  const Index p = F.cols, q = E.cols();
  JointFit j;
  j.rank = svd.rank();
  j.sse = (y - A * theta.head(p) - E * theta.tail(q)).squaredNorm();
  j.coef = theta.tail(q);
  return j;
}

VectorXd determined_part(const BlockFactors& F, const FoldFit& full, const MatrixXd& E,
                         const VectorXd& c, std::size_t& absorbed) {
  absorbed = 0;
  const Index q = E.cols();
  if (q == 0) return c;
  // E⊥ᵀE⊥ = Σ_b (E_b − Q_b G_b)ᵀ(E_b − Q_b G_b) + Gᵀ(I − UM UMᵀ)G, G the stacked Q_bᵀE_b of
  // the full fit's blocks: the part outside each block's span, then outside A's within them.
  const Projection pr = project_exact(F, E, VectorXd::Zero(E.rows()));
  MatrixXd perp = MatrixXd::Zero(q, q), EtE = MatrixXd::Zero(q, q);
  Index rows = 0;
  for (std::size_t b : full.blocks) rows += pr.G[b].rows();
  MatrixXd G(rows, q);
  Index at = 0;
  for (std::size_t b : full.blocks) {
    perp += pr.Perp[b];
    EtE += pr.EtE[b][0];
    G.middleRows(at, pr.G[b].rows()) = pr.G[b];
    at += pr.G[b].rows();
  }
  const MatrixXd UG = full.UM.transpose() * G;
  perp += G.transpose() * G - UG.transpose() * UG;
  // z = L c with EᵀE = LᵀL (L = D^½ Vᵀ from EᵀE = V D Vᵀ); B = L⁻ᵀ E⊥ᵀE⊥ L⁻¹.
  const Eigen::SelfAdjointEigenSolver<MatrixXd> ee(EtE);
  const VectorXd d = ee.eigenvalues();
  if (!(d.minCoeff() > 1e-12 * d.maxCoeff())) return c;  // dependent terms: leave c alone
  const MatrixXd L = d.cwiseSqrt().asDiagonal() * ee.eigenvectors().transpose();
  const MatrixXd Linv = ee.eigenvectors() * d.cwiseSqrt().cwiseInverse().asDiagonal();
  const Eigen::SelfAdjointEigenSolver<MatrixXd> bb(MatrixXd(Linv.transpose() * perp * Linv));
  const MatrixXd W = bb.eigenvectors();
  VectorXd z = W.transpose() * (L * c);
  // The nearly absorbed part is left out only when it is absurd: more than kAbsurd times the
  // determined part (RMS over the observations, |z|). A smaller one is the minimum-norm value the
  // rank cut gives an exactly absorbed term (a missing roll's constant shared with the other
  // errors' constants), and the shape is reported whole.
  double under = 0, det = 0;
  for (Index j = 0; j < q; ++j)
    (bb.eigenvalues()[j] < kDeterminedFraction * kDeterminedFraction ? under : det) += z[j] * z[j];
  if (!(under > kAbsurd * kAbsurd * det)) return c;
  for (Index j = 0; j < q; ++j)
    if (bb.eigenvalues()[j] < kDeterminedFraction * kDeterminedFraction) z[j] = 0, ++absorbed;
  return Linv * (W * z);
}

std::size_t joint_rank(const BlockFactors& F, const MatrixXd& E) {
  MatrixXd N;
  VectorXd z;
  joint_system(F, nullptr, E, N, z);
  return EquilibratedSvd(N, kRankTolerance, /*full_v=*/false).rank();
}

}  // namespace weilgen::gap_detail
