// Minimum-norm linear least squares by a column-equilibrated SVD, shared by the identification
// (identify.cpp) and the gap diagnosis (gap.cpp): every column is scaled to unit norm before the
// SVD, so the rank decision does not depend on units (µm against µrad, mm against m). A column
// of rounding noise is not scaled up: it counts as zero (kNegligibleColumn).
#pragma once

#include <cstddef>
#include <vector>

#include "weilgen/uq/dense.hpp"

namespace weilgen {

class EquilibratedSvd {
 public:
  // A column whose norm is at most this fraction of the largest column's is rounding noise, not
  // data: it is treated as zero (solution 0, outside the rank, in the null space). Rounding
  // leaves about 1e-16 of a column's scale; a column the data really excite is far above 1e-10.
  static constexpr double kNegligibleColumn = 1e-10;

  // Singular values at most `rank_tolerance` × the largest count as zero. `full_v` keeps all
  // right singular vectors (the null space), else the thin set.
  EquilibratedSvd(const Eigen::MatrixXd& A, double rank_tolerance, bool full_v);

  std::size_t rank() const { return rank_; }
  // Column norms (1 for zero and negligible columns).
  const Eigen::VectorXd& scale() const { return scale_; }
  const Eigen::VectorXd& sigma() const { return sigma_; }  // descending, zero-padded to cols
  const Eigen::MatrixXd& V() const { return V_; }          // equilibrated right vectors
  const Eigen::MatrixXd& U() const { return U_; }          // thin left vectors

  // The minimum-norm solution of A x ≈ y, in the original column scale; a column the data
  // never excite (zero or negligible norm) gets exactly 0.
  Eigen::VectorXd solve(const Eigen::VectorXd& y) const;
  // The pseudo-inverse's right factor: A⁺ = pinv_right() · U_rᵀ with U_r the first rank()
  // columns of U(); (cols × rank).
  Eigen::MatrixXd pinv_right() const;

 private:
  Eigen::VectorXd scale_, sigma_;
  Eigen::MatrixXd U_, V_;
  std::size_t rank_ = 0;
  std::vector<bool> zero_column_;
};

}  // namespace weilgen
