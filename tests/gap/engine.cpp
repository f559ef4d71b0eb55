// The gap diagnosis' linear engine (src/analysis/gap/engine.cpp) against direct dense
// least squares, and the diagnosis' independence of the thread count.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "src/analysis/gap/internal.hpp"
#include "test_support.hpp"
#include "weilgen/uq/lsq.hpp"

using namespace weilgen;
using namespace weilgen::gap_detail;

namespace {

// A design like a machine model's: columns of very different scales (µm against m), two
// columns that are the same combination (rank deficient), a column of zeros.
MatrixXd design(std::size_t n, std::uint32_t seed) {
  std::mt19937 g(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  MatrixXd A(static_cast<Index>(n), 9);
  for (Index i = 0; i < A.rows(); ++i) {
    const double x = u(g), y = u(g), z = u(g);
    A.row(i) << 1, x, y, z * 1e3, x * y, x * x * 1e-3, 0, x + y, z * z;
  }
  return A;
}

VectorXd values(const MatrixXd& A, std::uint32_t seed) {
  std::mt19937 g(seed);
  std::normal_distribution<double> nd(0, 1);
  VectorXd theta(A.cols()), e(A.rows());
  for (Index k = 0; k < theta.size(); ++k) theta[k] = nd(g);
  for (Index i = 0; i < e.size(); ++i) e[i] = 0.5 * nd(g);
  VectorXd y = A * theta + e;
  for (Index i = 0; i < y.size(); ++i) y[i] += 3 * std::sin(7 * A(i, 1));  // unmodelled
  return y;
}

// Three folds of interleaved rows (as cycles are), so blocks are cut from scattered rows.
std::vector<Split> three_folds(std::size_t n) {
  std::vector<Split> s(3);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t f = 0; f < 3; ++f) ((i / 7) % 3 == f ? s[f].test : s[f].train).push_back(i);
  return s;
}

double rel(const VectorXd& a, const VectorXd& b) {
  return (a - b).norm() / std::max(1e-300, std::max(a.norm(), b.norm()));
}

// The largest |c(k, l) − S_kl| over all pairs, by c(k, l) and by the prepared columns.
std::pair<double, double> worst_entries(const HeldoutCovariance& cov, const MatrixXd& S) {
  double worst = 0, worst_column = 0;
  for (std::size_t l = 0; l < static_cast<std::size_t>(S.cols()); ++l) {
    const HeldoutCovariance::Column c = cov.column(l);
    for (std::size_t k = 0; k < static_cast<std::size_t>(S.rows()); ++k) {
      const double want = S(static_cast<Index>(k), static_cast<Index>(l));
      worst = std::max(worst, std::abs(cov(k, l) - want));
      worst_column = std::max(worst_column, std::abs(cov(k, c) - want));
    }
  }
  return {worst, worst_column};
}

}  // namespace

TEST_CASE("gap engine: a split's fit from block factors is the SVD fit of its training rows") {
  // 9000 observations: folds of 3000, cut into blocks of at most 4096 rows only for all data.
  const std::size_t n = 9000;
  const MatrixXd A = design(n, 3);
  const VectorXd y = values(A, 4);
  GapData d;
  DesignLeastSquares e(d, A, y, 2);
  e.splits = three_folds(n);
  e.fit_folds();
  CHECK(e.factors->rows.size() == 3);
  for (std::size_t f = 0; f < 3; ++f) {
    const Split& s = e.splits[f];
    const MatrixXd Atr = rows_of(A, s.train), Ate = rows_of(A, s.test);
    const EquilibratedSvd svd(Atr, 1e-9, false);
    const FoldFit& ff = e.folds[f];
    CHECK(ff.rank == svd.rank());
    CHECK(ff.rank == 7);  // 9 columns: a zero column and a repeated combination
    const VectorXd theta = svd.solve(rows_of(y, s.train));
    CHECK(rel(ff.theta, theta) < 1e-9);
    CHECK(ff.theta[6] == 0.0);  // the zero column's coefficient is exactly 0
    CHECK(rel(ff.res_test, rows_of(y, s.test) - Ate * theta) < 1e-9);
    const MatrixXd VS = svd.pinv_right();
    CHECK(rel(ff.lev_test, (Ate * VS).rowwise().squaredNorm()) < 1e-9);
  }
  // All data: blocks of at most 4096 rows; leverage of every row.
  const FoldFit all = fit_all_rows(A, y, all_rows(n), 2);
  const EquilibratedSvd svd(A, 1e-9, false);
  CHECK(rel(all.theta, svd.solve(y)) < 1e-9);
  const MatrixXd U = svd.U().leftCols(static_cast<Index>(svd.rank()));
  CHECK(rel(all.lev_train, U.rowwise().squaredNorm()) < 1e-9);
  CHECK(all.lev_train.sum() == doctest::Approx(7.0).epsilon(1e-9));
}

TEST_CASE("gap engine: extra columns fitted by projection are the joint fit [A E]") {
  const std::size_t n = 3000;
  const MatrixXd A = design(n, 5);
  const VectorXd y = values(A, 6);
  GapData d;
  DesignLeastSquares e(d, A, y, 1);
  e.splits = three_folds(n);
  e.fit_folds();
  std::mt19937 g(7);
  std::normal_distribution<double> nd(0, 1);
  // Group 0: two columns well outside the span. Group 1: one column 1e-5 outside it (the exact
  // projection's case). Group 2: one column inside the span to 1e-11 (not usable). Group 3: a
  // column inside the span and one outside (the first is dropped, the second fitted).
  MatrixXd E(static_cast<Index>(n), 6);
  for (Index i = 0; i < E.rows(); ++i) {
    E(i, 0) = std::sin(7 * A(i, 1));
    E(i, 1) = std::cos(3 * A(i, 2)) * A(i, 1);
    const double noise = nd(g);
    E(i, 2) = A(i, 1) + 2 * A(i, 2) + 1e-5 * noise;
    E(i, 3) = A(i, 4) - A(i, 0) + 1e-11 * noise;
    E(i, 4) = A(i, 2);
    E(i, 5) = std::sin(7 * A(i, 1)) + 0.1 * noise;
  }
  const Projection pr = project(
      *e.factors, {E.leftCols(2), E.middleCols(2, 1), E.middleCols(3, 1), E.middleCols(4, 2)}, y);
  for (std::size_t f = 0; f < 3; ++f) {
    const Split& s = e.splits[f];
    const FoldFit& ff = e.folds[f];
    const MatrixXd Atr = rows_of(A, s.train), Ate = rows_of(A, s.test);
    auto joint = [&](Index j0, Index q, VectorXd& coef, double& sse, VectorXd& after) {
      MatrixXd AE(Atr.rows(), Atr.cols() + q);
      AE << Atr, rows_of(E, s.train).middleCols(j0, q);
      const EquilibratedSvd svd(AE, 1e-12, false);
      const VectorXd t = svd.solve(rows_of(y, s.train));
      coef = t.tail(q);
      sse = (rows_of(y, s.train) - AE * t).squaredNorm();
      MatrixXd AEte(Ate.rows(), Ate.cols() + q);
      AEte << Ate, rows_of(E, s.test).middleCols(j0, q);
      after = rows_of(y, s.test) - AEte * t;
    };
    VectorXd coef, after;
    double sse = 0;
    Projection exact;
    // Group 0.
    ExtraFit x = fit_extra(ff, pr, 0);
    REQUIRE(x.usable);
    CHECK_FALSE(x.ill_conditioned);
    joint(0, 2, coef, sse, after);
    CHECK(rel(x.coef, coef) < 1e-8);
    CHECK(x.train_sse == doctest::Approx(sse).epsilon(1e-10));
    CHECK(rel(heldout_after(ff, s, A, E.middleCols(0, 2), x), after) < 1e-8);
    // Group 1: read from the sums it is ill-conditioned; the exact projection fits it.
    x = fit_extra(ff, pr, 1);
    REQUIRE(x.usable);
    CHECK(x.ill_conditioned);
    x = fit_extra(ff, pr, 1, *e.factors, E.middleCols(2, 1), y, exact);
    CHECK_FALSE(x.ill_conditioned);
    joint(2, 1, coef, sse, after);
    CHECK(rel(x.coef, coef) < 1e-7);
    CHECK(x.train_sse == doctest::Approx(sse).epsilon(1e-10));
    CHECK(rel(heldout_after(ff, s, A, E.middleCols(2, 1), x), after) < 1e-7);
    // Group 2: inside the span.
    CHECK_FALSE(fit_extra(ff, pr, 2).usable);
    // Group 3: the first column dropped (coefficient 0), the second fitted alone.
    x = fit_extra(ff, pr, 3);
    REQUIRE(x.usable);
    CHECK(x.coef[0] == 0.0);
    joint(5, 1, coef, sse, after);
    CHECK(x.coef[1] == doctest::Approx(coef[0]).epsilon(1e-8));
    CHECK(x.train_sse == doctest::Approx(sse).epsilon(1e-10));
  }
  // The joint fit on all data: rank, SSE and coefficients as the SVD of [A E].
  MatrixXd AE(A.rows(), A.cols() + 2);
  AE << A, E.leftCols(2);
  const EquilibratedSvd svd(AE, 1e-9, false);
  const VectorXd t = svd.solve(y);
  const JointFit j = joint_fit(*e.factors, A, y, E.leftCols(2));
  CHECK(j.rank == svd.rank());
  CHECK(j.rank == e.full_rank + 2);
  CHECK(j.sse == doctest::Approx((y - AE * t).squaredNorm()).epsilon(1e-10));
  CHECK(rel(j.coef, t.tail(2)) < 1e-9);
  CHECK(joint_rank(*e.factors, E.middleCols(3, 1)) == e.full_rank);
  CHECK(joint_rank(*e.factors, E.middleCols(2, 1)) == e.full_rank + 1);
}

TEST_CASE("gap: the diagnosis is the same for any number of threads (JSON byte-identical)") {
  // A grid revisited in 3 cycles with a bump along Y in dz and a reversal of X in dx: many
  // candidates, refinement and two greedy steps.
  const std::filesystem::path dir = test::fresh_dir("gap_threads");
  std::mt19937_64 g(11);
  std::normal_distribution<double> nd(0, 0.5);
  std::ostringstream s;
  s << "X,Y,Z,t_s,dir_X,cycle,T_spindle,dx_um,dy_um,dz_um\n";
  double t = 0;
  for (int cy = 1; cy <= 3; ++cy)
    for (double Z : {-250.0, -150.0, -50.0})
      for (int iy = 0; iy < 8; ++iy)
        for (int k = 0; k < 12; ++k) {
          const bool up = k < 6;
          const double X = 100.0 * (up ? k : 11 - k), Y = -400 + 50.0 * iy;
          const double bump = 3 * std::exp(-0.5 * std::pow((Y + 180) / 40, 2));
          s << X << "," << Y << "," << Z << "," << t << "," << (up ? 1 : -1) << "," << cy << ","
            << 22 + 2 * (1 - std::exp(-t / 3600)) << "," << (up ? 1.5 : -1.5) + nd(g) << ","
            << nd(g) << "," << bump + nd(g) << "\n";
          t += 30;
        }
  const std::string data = (dir / "d.csv").string();
  std::ofstream(data) << s.str();
  std::vector<std::string> docs;
  for (int threads : {1, 2, 3}) {
    const std::string json = (dir / ("t" + std::to_string(threads) + ".json")).string();
    const test::Run r = test::run(test::cli("gap vmc_3axis -q --data " + data + " --threads " +
                                            std::to_string(threads) + " --json " + json));
    REQUIRE_MESSAGE(r.status == 0, r.out);
    std::ifstream in(json);
    docs.push_back(std::string(std::istreambuf_iterator<char>(in), {}));
  }
  // Both effects named: the reversal first, then the bump's shape.
  CHECK(
      docs[0].find("\"effect\": \"reversal\",\n    \"explanation\": [\n      \"reversal\",\n      "
                   "\"pdge_shape\"") != std::string::npos);
  CHECK(docs[0] == docs[1]);
  CHECK(docs[0] == docs[2]);
}

TEST_CASE("gap engine: the held-out residuals' covariance is M Mᵀ, M from each fold's fit") {
  // r = M e under the null hypothesis: row k of M is e_kᵀ − a_kᵀ A_f⁺ S_f for k held out by
  // split f (S_f selects its training rows). Build M from dense fits of the training rows and
  // compare every entry, the prepared columns and the centred differences' variances.
  const std::size_t n = 60;
  const MatrixXd A = design(n, 11);
  const VectorXd y = values(A, 12);
  GapData d;
  DesignLeastSquares e(d, A, y, 1);
  e.splits = three_folds(n);
  e.fit_folds();
  MatrixXd M = MatrixXd::Zero(static_cast<Index>(n), static_cast<Index>(n));
  for (const Split& s : e.splits) {
    const EquilibratedSvd svd(rows_of(A, s.train), 1e-9, false);
    MatrixXd P(A.cols(), static_cast<Index>(s.train.size()));  // θ = P y_train
    for (Index j = 0; j < P.cols(); ++j)
      P.col(j) = svd.solve(VectorXd::Unit(static_cast<Index>(s.train.size()), j));
    for (std::size_t k : s.test) {
      const VectorXd w = P.transpose() * A.row(static_cast<Index>(k)).transpose();
      M(static_cast<Index>(k), static_cast<Index>(k)) = 1;
      for (std::size_t j = 0; j < s.train.size(); ++j)
        M(static_cast<Index>(k), static_cast<Index>(s.train[j])) -= w[static_cast<Index>(j)];
    }
  }
  const MatrixXd S = M * M.transpose();
  const HeldoutCovariance cov(e);
  const auto [worst, worst_column] = worst_entries(cov, S);
  CHECK(worst < 1e-9 * S.cwiseAbs().maxCoeff());
  CHECK(worst_column < 1e-9 * S.cwiseAbs().maxCoeff());
  // Leverage on the diagonal: c(k, k) = 1 + h_k, h_k well above 0 for a 60-row design.
  CHECK(S.diagonal().maxCoeff() > 1.2);
  // Centred successive differences of a sequence crossing the folds.
  std::vector<std::size_t> seq;
  for (std::size_t i = 0; i < n; i += 2) seq.push_back(i);
  const std::vector<double> v = cov.difference_variances(seq);
  REQUIRE(v.size() == seq.size() - 1);
  const std::size_t k = v.size();
  for (std::size_t i = 0; i < k; ++i) {
    VectorXd c = VectorXd::Zero(static_cast<Index>(n));
    c[static_cast<Index>(seq[i + 1])] += 1, c[static_cast<Index>(seq[i])] -= 1;
    c[static_cast<Index>(seq.back())] -= 1.0 / static_cast<double>(k);
    c[static_cast<Index>(seq.front())] += 1.0 / static_cast<double>(k);
    CHECK(v[i] == doctest::Approx(c.dot(S * c)).epsilon(1e-9));
  }
}

TEST_CASE(
    "gap engine: the estimable held-out residual is free of errors a fold cannot determine, and "
    "its covariance is M_f S M_fᵀ") {
  // Two columns non-zero only on split 0's held-out rows: its training rows determine neither,
  // so its held-out residual carries them whatever θ is. M_0 removes them (2 directions), and the
  // estimable covariance is the plain one seen through M = blockdiag(M_f).
  const std::size_t n = 60;
  MatrixXd A(static_cast<Index>(n), 11);
  A.leftCols(9) = design(n, 31);
  const std::vector<Split> splits = three_folds(n);
  A.rightCols(2).setZero();
  for (std::size_t k : splits[0].test) {
    const auto i = static_cast<Index>(k);
    A(i, 9) = 1 + 0.1 * A(i, 1), A(i, 10) = A(i, 2) * 1e2;
  }
  VectorXd y = values(A, 32);
  auto estimable = [&](const VectorXd& values, VectorXd& r, VectorXd& h, std::size_t& removed) {
    GapData d;
    DesignLeastSquares e(d, A, values, 1);
    e.splits = splits;
    e.fit_folds();
    VectorXd h0;
    e.heldout(r, h0);
    HeldoutCovariance(e, true).estimable(r, h, removed);
  };
  VectorXd r1, h1, r2, h2;
  std::size_t removed1 = 0, removed2 = 0;
  estimable(y, r1, h1, removed1);
  CHECK(removed1 == 2);
  // 50 and −30 more of the two undetermined errors: the estimable residual does not move.
  estimable(y + 50 * A.col(9) - 30 * A.col(10), r2, h2, removed2);
  CHECK(removed2 == 2);
  CHECK(rel(r1, r2) < 1e-9);
  CHECK(rel(h1, h2) < 1e-12);
  // Dense: S = M Mᵀ of the plain held-out residual, M_f = I − U Uᵀ with U the left singular
  // vectors of A_test (I − A_tr⁺A_tr).
  GapData d;
  DesignLeastSquares e(d, A, y, 1);
  e.splits = splits;
  e.fit_folds();
  const HeldoutCovariance plain(e), est(e, true);
  MatrixXd S(static_cast<Index>(n), static_cast<Index>(n)), Mb = MatrixXd::Zero(S.rows(), S.cols());
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t l = 0; l < n; ++l)
      S(static_cast<Index>(k), static_cast<Index>(l)) = plain(k, l);
  for (const Split& s : splits) {
    const MatrixXd Atr = rows_of(A, s.train), At = rows_of(A, s.test);
    const MatrixXd P = Atr.completeOrthogonalDecomposition().pseudoInverse() * Atr;
    const Eigen::JacobiSVD<MatrixXd> svd(At * (MatrixXd::Identity(A.cols(), A.cols()) - P),
                                         Eigen::ComputeThinU);
    Index k = 0;
    while (k < svd.singularValues().size() && svd.singularValues()[k] > 1e-8) ++k;
    const MatrixXd U = svd.matrixU().leftCols(k);
    const MatrixXd M = MatrixXd::Identity(At.rows(), At.rows()) - U * U.transpose();
    for (std::size_t i = 0; i < s.test.size(); ++i)
      for (std::size_t j = 0; j < s.test.size(); ++j)
        Mb(static_cast<Index>(s.test[i]), static_cast<Index>(s.test[j])) =
            M(static_cast<Index>(i), static_cast<Index>(j));
  }
  const MatrixXd want = Mb * S * Mb.transpose();
  const auto [worst, worst_column] = worst_entries(est, want);
  for (std::size_t l = 0; l < n; ++l)
    CHECK(1 + h1[static_cast<Index>(l)] ==
          doctest::Approx(want(static_cast<Index>(l), static_cast<Index>(l))).epsilon(1e-9));
  CHECK(worst < 1e-9 * want.cwiseAbs().maxCoeff());
  CHECK(worst_column < 1e-9 * want.cwiseAbs().maxCoeff());
}
