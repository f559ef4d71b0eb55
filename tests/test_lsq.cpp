// The column-equilibrated SVD (weilgen/uq/lsq.hpp) that identify and the gap folds share.
#include <doctest/doctest.h>

#include <cmath>

#include "test_support.hpp"
#include "weilgen/analysis/identify.hpp"
#include "weilgen/uq/lsq.hpp"

using namespace weilgen;

TEST_CASE("lsq: minimum-norm solution of a rank-deficient system with badly scaled columns") {
  // Columns 0 and 2 are equal up to a factor 1e6; column 1 is independent.
  Eigen::MatrixXd A(4, 3);
  A << 1, 0, 1e6, 1, 1, 1e6, 1, 2, 1e6, 1, 3, 1e6;
  const Eigen::VectorXd x0 = (Eigen::VectorXd(3) << 2, 0.5, 0).finished();
  const EquilibratedSvd svd(A, 1e-9, false);
  CHECK(svd.rank() == 2);
  const Eigen::VectorXd x = svd.solve(A * x0);
  CHECK((A * x - A * x0).norm() < 1e-9);
  // Minimum norm in the equilibrated columns: the equal columns share the weight equally.
  CHECK(x[0] == doctest::Approx(1.0));
  CHECK(x[2] == doctest::Approx(1e-6));
}

TEST_CASE("lsq: a line run's design matrix (rank 4 of 75) gets a finite SVD") {
  // vmc_3axis, dx measured along X only (101 targets, 5 cycles up and down) at Y = -180,
  // Z = -213 mm (the benchmark's line scenario s0254):
  // Eigen 3.4.0's BDCSVD reads out of bounds on this matrix (it returned NaN singular vectors,
  // and crashed under AddressSanitizer); the decomposition must be finite.
  const auto model = test::builtin_model("vmc_3axis");
  const ErrorParameterisation p(model->description(), parse_pdge_flags(model->description(), {}),
                                model->parameters());
  PointData d;
  for (int pass = 0; pass < 10; ++pass)
    for (int k = 0; k <= 100; ++k) {
      const int i = pass % 2 == 0 ? k : 100 - k;     // up, then down
      d.poses.push_back({-180.0, 5.0 * i, -213.0});  // Y, X, Z
      d.observations.push_back({d.poses.size() - 1, 0, 0, 0.0, {}});
    }
  const Eigen::MatrixXd A = design_matrix(*model, p, d);
  REQUIRE(A.rows() == 1010);
  const EquilibratedSvd svd(A, 1e-9, false);
  CHECK(svd.rank() == 4);  // E_XX: constant and cubic
  Eigen::VectorXd y(A.rows());
  for (Eigen::Index i = 0; i < y.size(); ++i) y[i] = std::sin(0.01 * static_cast<double>(i % 101));
  const Eigen::VectorXd x = svd.solve(y);
  CHECK(x.allFinite());
  // The residual is orthogonal to the columns (normal equations).
  CHECK((A.transpose() * (y - A * x)).norm() < 1e-8 * A.norm() * y.norm());
}

TEST_CASE("lsq: a column of rounding noise counts as zero, a small real column does not") {
  // Column 1 is sin(2π·2·y/L) at y = 0, L/4, ..., L, as double rounding leaves it (~1e-16):
  // scaled to unit norm it looked like data and was fitted with a coefficient of 1e16.
  Eigen::MatrixXd A(5, 3);
  const double pi = std::acos(-1.0);
  for (int k = 0; k < 5; ++k) {
    A(k, 0) = 1;
    A(k, 1) = std::sin(2 * pi * 2 * k / 4.0);
    A(k, 2) = 1e-6 * k;  // small, but the data excite it: kept (equilibration's purpose)
  }
  REQUIRE(A.col(1).norm() > 0);
  REQUIRE(A.col(1).norm() < 1e-14);
  const Eigen::VectorXd y = (Eigen::VectorXd(5) << 1, -2, 3, -4, 5).finished();
  const EquilibratedSvd svd(A, 1e-9, true);
  CHECK(svd.rank() == 2);
  const Eigen::VectorXd x = svd.solve(y);
  CHECK(x[1] == 0.0);
  CHECK(svd.scale()[1] == 1.0);
  // The other two columns get the least-squares fit of y on them alone.
  Eigen::MatrixXd B(5, 2);
  B << A.col(0), A.col(2);
  const Eigen::VectorXd xb = B.colPivHouseholderQr().solve(y);
  CHECK(x[0] == doctest::Approx(xb[0]));
  CHECK(x[2] == doctest::Approx(xb[1]));
  // The noise column is the null space: V's last column is e_1.
  CHECK(std::abs(svd.V()(1, 2)) == doctest::Approx(1.0));
  // The rule is relative to the largest column: alone, the same column is the data's scale.
  CHECK(EquilibratedSvd(A.col(1), 1e-9, true).rank() == 1);
}
