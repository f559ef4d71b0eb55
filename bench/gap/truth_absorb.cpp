// What the model machine can absorb of a signal (bench/gap/README.md, "SNR"): its
// first-order regressors, their column space, and the part of a signal outside it.
#include <algorithm>
#include <cmath>
#include <set>

#include "truth.hpp"

namespace weilgen::gapbench {

// ---------------------------------------------------------------------------------------------
// What the model can absorb: the first-order model of the model machine (its Jacobian at zero
// error, from the exact chain) with every PIGE a constant and every PDGE a Legendre series of
// degree fit_degree on its axis' travel. Any identification of that model fits at least as well
// on the training data, so only the residual of an effect on these regressors can show in
// held-out data.

namespace {
struct RegressorLayout {
  std::vector<int> error;  // model error of each column
  std::vector<int> term;   // basis term of each column
};
}  // namespace

void Synthesiser::build_regressors() {
  const std::size_t nm = model_desc_.errors.size();
  const std::vector<int> model_axes = model_desc_.axes();
  std::vector<int> axis_of(nm, -1);  // index into axes_ of a PDGE's axis
  for (std::size_t i = 0; i < nm; ++i) {
    const ErrorDef& e = model_desc_.errors[i];
    if (e.dependence != Dependence::PDGE) continue;
    for (std::size_t k = 0; k < model_axes.size(); ++k) {
      const Joint& j = model_desc_.bodies[static_cast<std::size_t>(model_axes[k])].joint;
      if (model_axes[k] == e.body && j.max > j.min) {
        for (std::size_t a = 0; a < axes_.size(); ++a)
          if (axes_[a].name == j.coordinate) axis_of[i] = static_cast<int>(a);
      }
    }
  }
  // Model Jacobian per pose by central differences of the exact chain. With h = 1e-4 (mm, rad)
  // truncation (h^2/6 relative) and round-off (eps * 1000 mm / h) both stay near 1e-9, far
  // below the rank threshold below: exactly dependent columns (E_XY[1] and E_XX[1] both move dx)
  // must stay dependent, or their round-off would "absorb" signal with huge coefficients.
  std::vector<Eigen::MatrixXd> jac(poses_.size());
  for (std::size_t p = 0; p < poses_.size(); ++p) {
    // The model's axes are the truth's (same bodies); map by coordinate name to be safe.
    std::vector<double> ax(model_axes.size());
    for (std::size_t k = 0; k < model_axes.size(); ++k) {
      const std::string& name =
          model_desc_.bodies[static_cast<std::size_t>(model_axes[k])].joint.coordinate;
      for (std::size_t a = 0; a < axes_.size(); ++a)
        if (axes_[a].name == name) ax[k] = poses_[p][a];
    }
    jac[p] = position_jacobian(*model_chain_, ax, nm, 1e-4);
  }
  RegressorLayout lay;
  for (std::size_t i = 0; i < nm; ++i) {
    // A rotary axis' PDGE in Fourier (rotary_harmonics), others Legendre of fit_degree.
    const int harmonics = axis_of[i] >= 0 && !axes_[static_cast<std::size_t>(axis_of[i])].linear
                              ? spec_.rotary_harmonics
                              : 0;
    const int terms = axis_of[i] < 0 ? 1 : harmonics > 0 ? 2 * harmonics + 1 : spec_.fit_degree + 1;
    for (int k = 0; k < terms; ++k) {
      lay.error.push_back(static_cast<int>(i));
      lay.term.push_back(k);
    }
  }
  const Eigen::Index n = static_cast<Eigen::Index>(obs_row_.size());
  Eigen::MatrixXd A(n, static_cast<Eigen::Index>(lay.error.size()));
  const std::vector<double> zero(model_desc_.errors.size(), 0.0);
  double phi[16];
  for (Eigen::Index o = 0; o < n; ++o) {
    const Row& row = rows_[static_cast<std::size_t>(obs_row_[static_cast<std::size_t>(o)])];
    const int dim = column_dim_[static_cast<std::size_t>(obs_col_[static_cast<std::size_t>(o)])];
    const Eigen::MatrixXd& J = jac[static_cast<std::size_t>(row.pose)];
    Eigen::RowVectorXd g;
    if (dim >= 0) {
      g = J.row(dim);
    } else {
      // dr sees the deviation along the nominal ball-to-ball direction.
      const Eigen::Vector3d u =
          (tool_point(*model_chain_, row.axes, zero) - centre_point_).normalized();
      g = u.transpose() * J;
    }
    int last_error = -1;
    for (std::size_t c = 0; c < lay.error.size(); ++c) {
      const int i = lay.error[c];
      if (i != last_error && axis_of[static_cast<std::size_t>(i)] >= 0) {
        const auto ai = static_cast<std::size_t>(axis_of[static_cast<std::size_t>(i)]);
        const AxisInfo& a = axes_[ai];
        pdge_basis(a.linear ? 0 : spec_.rotary_harmonics, spec_.fit_degree, row.axes[ai], a.min,
                   a.max, phi);
      }
      last_error = i;
      const double basis = axis_of[static_cast<std::size_t>(i)] >= 0 ? phi[lay.term[c]] : 1.0;
      A(o, static_cast<Eigen::Index>(c)) = g[i] * basis;
    }
  }
  // Drop columns the layout does not see (e.g. E_AZ at tool_length 0) and normalise the rest.
  double biggest = 0;
  for (Eigen::Index c = 0; c < A.cols(); ++c) biggest = std::max(biggest, A.col(c).norm());
  std::vector<Eigen::Index> keep;
  for (Eigen::Index c = 0; c < A.cols(); ++c)
    if (A.col(c).norm() > 1e-7 * biggest) keep.push_back(c);
  regressors_.resize(n, static_cast<Eigen::Index>(keep.size()));
  regressor_error_.clear();
  for (std::size_t c = 0; c < keep.size(); ++c) {
    regressors_.col(static_cast<Eigen::Index>(c)) = A.col(keep[c]) / A.col(keep[c]).norm();
    regressor_error_.push_back(lay.error[static_cast<std::size_t>(keep[c])]);
  }
  span_ = Span(regressors_);
}

// An orthonormal basis of the regressors' column space: the left singular vectors whose singular
// values exceed 1e-7 of the largest. Those are either O(1) or round-off (identification
// condition numbers are ~40), so any cut between 1e-12 and 1e-3 gives the same space;
// `smallest_kept` and `largest_dropped` record the gap.
Synthesiser::Span::Span(const Eigen::MatrixXd& A) {
  // Jacobi, not Eigen 3.4.0's BDCSVD (out-of-bounds read on rank-deficient input: src/uq/lsq.cpp).
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU);
  const Eigen::VectorXd& sv = svd.singularValues();
  Eigen::Index k = 0;
  while (k < sv.size() && sv[k] > 1e-7 * sv[0]) ++k;
  basis = svd.matrixU().leftCols(k);
  smallest_kept = k > 0 ? sv[k - 1] / sv[0] : 0.0;
  largest_dropped = k < sv.size() ? sv[k] / sv[0] : 0.0;
}

Eigen::VectorXd Synthesiser::Span::residual(const Eigen::VectorXd& s) const {
  return s - basis * (basis.transpose() * s);
}

std::vector<double> Synthesiser::unabsorbed_rms(const std::vector<double>& signal_um) const {
  const Eigen::Map<const Eigen::VectorXd> s(signal_um.data(),
                                            static_cast<Eigen::Index>(signal_um.size()));
  const Eigen::VectorXd r = span_.residual(s);
  std::vector<double> sum(columns_.size(), 0.0), count(columns_.size(), 0.0);
  for (std::size_t o = 0; o < signal_um.size(); ++o) {
    sum[static_cast<std::size_t>(obs_col_[o])] +=
        r[static_cast<Eigen::Index>(o)] * r[static_cast<Eigen::Index>(o)];
    count[static_cast<std::size_t>(obs_col_[o])] += 1;
  }
  for (std::size_t c = 0; c < sum.size(); ++c) sum[c] = std::sqrt(sum[c] / count[c]);
  return sum;
}

std::vector<double> Synthesiser::raw_rms(const std::vector<double>& signal_um) const {
  std::vector<double> sum(columns_.size(), 0.0), count(columns_.size(), 0.0);
  for (std::size_t o = 0; o < signal_um.size(); ++o) {
    sum[static_cast<std::size_t>(obs_col_[o])] += signal_um[o] * signal_um[o];
    count[static_cast<std::size_t>(obs_col_[o])] += 1;
  }
  for (std::size_t c = 0; c < sum.size(); ++c) sum[c] = std::sqrt(sum[c] / count[c]);
  return sum;
}

std::vector<std::pair<std::string, double>> Synthesiser::missing_error_visibility() const {
  // First-order signal of each error alone (its drawn shape), projected on the regressors of
  // every other error: what a model without that error could not absorb.
  std::vector<std::pair<std::string, double>> out;
  const std::size_t n = truth_desc_.errors.size();
  const std::vector<double> amps(effects_.size(), 1.0);
  const std::vector<bool> off(effects_.size(), false);
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<double> sig(obs_row_.size());
    for (std::size_t o = 0; o < sig.size(); ++o) {
      const Row& row = rows_[static_cast<std::size_t>(obs_row_[o])];
      std::vector<double> e = errors_at(row, amps, off);
      for (std::size_t k = 0; k < n; ++k)
        if (k != i) e[k] = 0;
      const Eigen::Vector3d d = linear_deviation(row, e);
      double v[1];
      measure_row(static_cast<std::size_t>(obs_row_[o]), d, v);
      const int dim = column_dim_[static_cast<std::size_t>(obs_col_[o])];
      sig[o] = dim >= 0 ? 1000 * d[dim] : v[0];
    }
    std::vector<Eigen::Index> keep;
    for (std::size_t c = 0; c < regressor_error_.size(); ++c)
      if (regressor_error_[c] != static_cast<int>(i)) keep.push_back(static_cast<Eigen::Index>(c));
    Eigen::MatrixXd A(regressors_.rows(), static_cast<Eigen::Index>(keep.size()));
    for (std::size_t c = 0; c < keep.size(); ++c)
      A.col(static_cast<Eigen::Index>(c)) = regressors_.col(keep[c]);
    const Eigen::Map<const Eigen::VectorXd> s(sig.data(), static_cast<Eigen::Index>(sig.size()));
    const Eigen::VectorXd r = Span(A).residual(s);
    std::vector<double> res(r.data(), r.data() + r.size());
    // Below 1e-9 um the error does not reach the measured values at all (E_AZ at tool length 0).
    const double raw = max_of(raw_rms(sig));
    out.emplace_back(truth_desc_.errors[i].name, raw > 1e-9 ? max_of(raw_rms(res)) / raw : 0.0);
  }
  return out;
}

}  // namespace weilgen::gapbench
