#include "weilgen/uq/lsq.hpp"

namespace weilgen {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

EquilibratedSvd::EquilibratedSvd(const MatrixXd& A, double rank_tolerance, bool full_v) {
  const Index n = A.cols();
  scale_ = A.colwise().norm().transpose();
  // A column that is rounding noise (a basis function that vanishes at every sample, such as
  // sin(2π·2x/L) on samples L/4 apart) would be scaled up to unit norm and fitted as if the data
  // excited it: it counts as zero, like an exactly zero column.
  const double largest = n ? scale_.maxCoeff() : 0;
  zero_column_.resize(static_cast<std::size_t>(n));
  for (Index p = 0; p < n; ++p) {
    zero_column_[static_cast<std::size_t>(p)] = !(scale_[p] > kNegligibleColumn * largest);
    if (zero_column_[static_cast<std::size_t>(p)]) scale_[p] = 1;
  }
  MatrixXd As = A * scale_.cwiseInverse().asDiagonal();
  for (Index p = 0; p < n; ++p)
    if (zero_column_[static_cast<std::size_t>(p)]) As.col(p).setZero();
  const unsigned options =
      Eigen::ComputeThinU | (full_v ? Eigen::ComputeFullV : Eigen::ComputeThinV);
  // One-sided Jacobi (after a QR), not Eigen 3.4.0's divide-and-conquer BDCSVD: its
  // perturbCol0 reads perm(-1) when the first undeflated index lies below a deflated one, which
  // happens on rank-deficient designs (fixed upstream after 3.4.0; Debian 12 ships 3.4.0). In a
  // normal build that read returned garbage, seen as NaN singular vectors (a 1010 x 75 design of
  // rank 4: tests/test_lsq.cpp); under AddressSanitizer it crashed the gap diagnosis. Jacobi is
  // 1.2-2x slower on the small triangles the callers pass (gap, identify) and always exact to
  // rounding.
  Eigen::JacobiSVD<MatrixXd> svd(As, options);
  sigma_ = VectorXd::Zero(n);
  sigma_.head(svd.singularValues().size()) = svd.singularValues();
  U_ = svd.matrixU();
  V_ = svd.matrixV();
  const double smax = sigma_.size() ? sigma_[0] : 0;
  while (rank_ < static_cast<std::size_t>(std::min(n, U_.cols())) &&
         sigma_[static_cast<Index>(rank_)] > rank_tolerance * smax && smax > 0)
    ++rank_;
}

VectorXd EquilibratedSvd::solve(const VectorXd& y) const {
  VectorXd z = VectorXd::Zero(V_.rows());
  for (std::size_t i = 0; i < rank_; ++i) {
    const auto c = static_cast<Index>(i);
    z += V_.col(c) * (U_.col(c).dot(y) / sigma_[c]);
  }
  VectorXd x = z.cwiseQuotient(scale_);
  for (std::size_t p = 0; p < zero_column_.size(); ++p)
    if (zero_column_[p]) x[static_cast<Index>(p)] = 0;  // not rounding noise
  return x;
}

MatrixXd EquilibratedSvd::pinv_right() const {
  const auto r = static_cast<Index>(rank_);
  return scale_.cwiseInverse().asDiagonal() * V_.leftCols(r) *
         sigma_.head(r).cwiseInverse().asDiagonal();
}

}  // namespace weilgen
