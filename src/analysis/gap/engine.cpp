#include <algorithm>
#include <boost/math/distributions/fisher_f.hpp>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <set>
#include <stdexcept>

#include "internal.hpp"
#include "weilgen/uq/lsq.hpp"

namespace weilgen::gap_detail {

double f_sf(double f, double d1, double d2) {
  if (!(f > 0) || !(d1 > 0) || !(d2 > 0) || !std::isfinite(f)) return f > 0 ? 0.0 : 1.0;
  return boost::math::cdf(boost::math::complement(boost::math::fisher_f(d1, d2), f));
}

std::size_t distinct(const std::vector<double>& v) {
  std::set<double> s;
  for (double x : v)
    if (std::isfinite(x)) s.insert(x);
  return s.size();
}

FoldFit fit_fold(const MatrixXd& A, const VectorXd& y, const Split& s) {
  FoldFit f;
  const MatrixXd Atr = rows_of(A, s.train), Ate = rows_of(A, s.test);
  const VectorXd ytr = rows_of(y, s.train), yte = rows_of(y, s.test);
  const EquilibratedSvd svd(Atr, 1e-9, /*full_v=*/false);
  f.rank = svd.rank();
  f.U = svd.U().leftCols(static_cast<Index>(f.rank));
  f.VS = svd.pinv_right();
  f.theta = svd.solve(ytr);
  f.res_train = ytr - Atr * f.theta;
  f.res_test = yte - Ate * f.theta;
  // h_i = a_iᵀ (AᵀA)⁺ a_i = |S⁻¹ Vᵀ (a_i / scale)|² = |VSᵀ a_i|².
  f.W = Ate * f.VS;
  f.lev_test = f.W.rowwise().squaredNorm();
  return f;
}

}  // namespace weilgen::gap_detail
