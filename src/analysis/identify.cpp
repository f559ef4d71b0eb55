#include "weilgen/analysis/identify.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>

#include "weilgen/analysis/per_output_rms.hpp"
#include "weilgen/analysis/study_spec.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/machine/derived.hpp"
#include "weilgen/uq/dense.hpp"
#include "weilgen/uq/lsq.hpp"

namespace weilgen {

const char* observation_name(std::size_t output) {
  static const char* const line[] = {"dr", "lin", "str", "ang"};
  return output >= 6 ? line[output - 6] : output_name(output);
}

const char* observation_unit(std::size_t output) {
  if (output >= 6) return output == static_cast<std::size_t>(kLineAngular) ? "µrad" : "µm";
  return measured_unit(output);
}

std::string NullCombination::str(const std::vector<IdentParameter>& params) const {
  std::string s;
  for (const auto& [p, c] : terms) {
    const double a = std::abs(c);
    s += s.empty() ? (c < 0 ? "-" : "") : (c < 0 ? " - " : " + ");
    if (std::abs(a - 1) > 1e-9) s += format_short(a) + "·";
    s += params[p].label;
  }
  return s;
}

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// The equilibrated SVD (lsq.hpp) with its minimum-norm solution.
struct SvdSolve {
  EquilibratedSvd svd;
  VectorXd x;
  SvdSolve(const MatrixXd& A, const VectorXd& y, double tol)
      : svd(A, tol, /*full_v=*/true), x(svd.solve(y)) {}
};

}  // namespace

// Readable null-space basis: reduced row echelon form of Nᵀ (each combination has a leading
// parameter the others do not contain), in θ units, leading coefficient 1.
std::vector<NullCombination> null_combinations(const EquilibratedSvd& s,
                                               const std::vector<std::size_t>& cols) {
  const Eigen::Index n = s.V().rows(), k = n - static_cast<Eigen::Index>(s.rank());
  std::vector<NullCombination> out;
  if (k <= 0) return out;
  // Rows: null vectors in θ units (z / scale).
  MatrixXd N = s.V().rightCols(k).transpose();
  for (Eigen::Index p = 0; p < n; ++p) N.col(p) /= s.scale()[p];
  Eigen::Index row = 0;
  for (Eigen::Index c = 0; c < n && row < k; ++c) {
    Eigen::Index piv = row;
    N.col(c).segment(row, k - row).cwiseAbs().maxCoeff(&piv);
    piv += row;
    if (std::abs(N(piv, c)) < 1e-9 * N.cwiseAbs().maxCoeff()) continue;
    N.row(row).swap(N.row(piv));
    N.row(row) /= N(row, c);
    for (Eigen::Index r = 0; r < k; ++r)
      if (r != row) N.row(r) -= N(r, c) * N.row(row);
    ++row;
  }
  for (Eigen::Index r = 0; r < k; ++r) {
    NullCombination nc;
    const double big = N.row(r).cwiseAbs().maxCoeff();
    for (Eigen::Index p = 0; p < n; ++p)
      if (std::abs(N(r, p)) > 1e-9 * big)
        nc.terms.emplace_back(cols[static_cast<std::size_t>(p)], N(r, p));
    if (!nc.terms.empty()) out.push_back(std::move(nc));
  }
  return out;
}

MatrixXd design_matrix(const Model& model, const ErrorParameterisation& param,
                       const PointData& data) {
  const std::size_t m = data.observations.size(), np = param.size(), ne = model.num_errors();
  ModelData md(model);
  std::vector<double> jac(np);
  MatrixXd A(static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(np));
  std::size_t last_row = SIZE_MAX;
  for (std::size_t i = 0; i < m; ++i) {
    const PointObservation& ob = data.observations[i];
    const double* pose = data.poses[ob.row].data();
    if (ob.row != last_row) {
      model.coefficients(md, pose, md.coeff.data());
      param.derivatives(pose, jac.data());
      last_row = ob.row;
    }
    if (ob.error >= 0) {
      // An error observed directly (a 6D line): µm per mm or µrad per rad of that error.
      const double scale = error_measured_scale(model.description().errors[ob.error]);
      for (std::size_t p = 0; p < np; ++p)
        A(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(p)) =
            param.parameters()[p].error == ob.error ? scale * jac[p] : 0.0;
      continue;
    }
    for (std::size_t p = 0; p < np; ++p) {
      const auto err = static_cast<std::size_t>(param.parameters()[p].error);
      double v = 0;
      for (int o = 0; o < 6; ++o) {
        const double w = observation_weight(ob, o);
        if (w != 0)
          v += w * kMeasuredScale[static_cast<std::size_t>(o)] *
               md.coeff[static_cast<std::size_t>(o) * ne + err];
      }
      A(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(p)) = v * jac[p];
    }
  }
  return A;
}

std::size_t remove_references(const PointData& data, MatrixXd& A, VectorXd* y) {
  std::size_t removed = 0;
  for (const ObservationReference& ref : data.references) {
    const auto n = static_cast<Eigen::Index>(ref.observations.size());
    const auto k = static_cast<Eigen::Index>(ref.basis.size());
    if (n == 0 || k == 0) continue;
    MatrixXd N(n, k);
    for (Eigen::Index j = 0; j < k; ++j)
      for (Eigen::Index i = 0; i < n; ++i)
        N(i, j) = ref.basis[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)];
    // An orthonormal basis of the functions' span at these observations (rank-revealing: a
    // function the observations cannot tell from the others takes no degree of freedom).
    const Eigen::ColPivHouseholderQR<MatrixXd> qr(N);
    const auto rank = qr.rank();
    if (rank == 0) continue;
    const MatrixXd Q = MatrixXd(qr.householderQ()).leftCols(rank);
    MatrixXd block(n, A.cols());
    for (Eigen::Index i = 0; i < n; ++i)
      block.row(i) =
          A.row(static_cast<Eigen::Index>(ref.observations[static_cast<std::size_t>(i)]));
    block -= Q * (Q.transpose() * block);
    for (Eigen::Index i = 0; i < n; ++i)
      A.row(static_cast<Eigen::Index>(ref.observations[static_cast<std::size_t>(i)])) =
          block.row(i);
    if (y) {
      VectorXd v(n);
      for (Eigen::Index i = 0; i < n; ++i)
        v[i] = (*y)[static_cast<Eigen::Index>(ref.observations[static_cast<std::size_t>(i)])];
      v -= Q * (Q.transpose() * v);
      for (Eigen::Index i = 0; i < n; ++i)
        (*y)[static_cast<Eigen::Index>(ref.observations[static_cast<std::size_t>(i)])] = v[i];
    }
    removed += static_cast<std::size_t>(rank);
  }
  return removed;
}

void IdentifyOptions::validate() const {
  if (!(rank_tolerance > 0 && rank_tolerance < 1))
    throw std::invalid_argument("--rank-tol must be in (0, 1)");
  if (max_gauss_newton < 0) throw std::invalid_argument("identify: max_gauss_newton must be >= 0");
}

Identification::Identification(IdentifyOptions options) : options_(std::move(options)) {
  options_.validate();
}

IdentifyResult Identification::run(const Model& model_, const ErrorParameterisation& param_,
                                   const PointData& data) const {
  const Description& desc = model_.description();
  const std::size_t np = param_.size(), m = data.observations.size();
  IdentifyResult R;
  R.theta.assign(np, 0.0);
  R.standard_error.assign(np, kNaN);
  R.identifiable.assign(np, false);
  R.fixed.assign(np, false);
  for (const std::string& f : options_.fixed)
    for (const ErrorTarget& t : select_errors(desc, f, "--fix " + quoted(f)))
      for (std::size_t p = 0; p < np; ++p)
        if (param_.parameters()[p].error == static_cast<int>(t.error)) R.fixed[p] = true;
  std::vector<std::size_t> cols;  // free parameters
  for (std::size_t p = 0; p < np; ++p)
    if (!R.fixed[p]) cols.push_back(p);
  R.free_parameters = cols.size();
  R.observations = m;
  R.count = data.count;
  const std::size_t na = desc.axes().size();
  R.span_min.assign(na, kInf);
  R.span_max.assign(na, -kInf);
  for (const PointObservation& ob : data.observations)
    for (std::size_t a = 0; a < na; ++a) {
      const double v = data.poses[ob.row][a] + 0.0;  // + 0.0: a measured -0 is the position 0
      R.span_min[a] = std::min(R.span_min[a], v);
      R.span_max[a] = std::max(R.span_max[a], v);
    }

  ModelData md(model_);
  VectorXd y(static_cast<Eigen::Index>(m));
  for (std::size_t i = 0; i < m; ++i) y[static_cast<Eigen::Index>(i)] = data.observations[i].value;

  // Linear model at zero error, without the fixed parameters; the set-up references removed
  // from the data and the model alike.
  MatrixXd full = design_matrix(model_, param_, data);
  R.references = remove_references(data, full, &y);
  MatrixXd A(static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(cols.size()));
  for (std::size_t q = 0; q < cols.size(); ++q)
    A.col(static_cast<Eigen::Index>(q)) = full.col(static_cast<Eigen::Index>(cols[q]));
  SvdSolve S(A, y, options_.rank_tolerance);
  for (std::size_t q = 0; q < cols.size(); ++q)
    R.theta[cols[q]] = S.x[static_cast<Eigen::Index>(q)];

  // Residuals of the full model (exact at order 1; the Gauss-Newton objective above).
  auto residual = [&](const std::vector<double>& theta) {
    VectorXd f = predict_observations(model_, md, param_, theta, data);
    MatrixXd none(static_cast<Eigen::Index>(m), 0);
    VectorXd r = y - f;
    remove_references(data, none, &r);
    return r;
  };
  VectorXd r = model_.order() > 1 ? residual(R.theta) : VectorXd(y - A * S.x);
  if (model_.order() > 1) {
    // Gauss-Newton; central differences are exact for the quadratic terms of an order-2 model.
    for (int it = 0; it < options_.max_gauss_newton; ++it) {
      MatrixXd J(static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(cols.size()));
      for (std::size_t q = 0; q < cols.size(); ++q) {
        std::vector<double> tp = R.theta, tm = R.theta;
        const double h = std::max(1.0, 1e-3 * std::abs(R.theta[cols[q]]));
        tp[cols[q]] += h;
        tm[cols[q]] -= h;
        J.col(static_cast<Eigen::Index>(q)) = (residual(tm) - residual(tp)) / (2 * h);
      }
      // Directions the first-order data cannot see become weakly visible through products of
      // errors; a looser rank cut keeps the step out of them, and halving keeps it descending.
      S = SvdSolve(J, r, std::max(options_.rank_tolerance, 1e-6));
      const double before = r.squaredNorm();
      std::vector<double> trial = R.theta;
      double step = 0, size = 0, t = 1;
      for (int halving = 0; halving < 20; ++halving, t /= 2) {
        trial = R.theta;
        for (std::size_t q = 0; q < cols.size(); ++q)
          trial[cols[q]] += t * S.x[static_cast<Eigen::Index>(q)];
        const VectorXd rt = residual(trial);
        if (rt.squaredNorm() <= before) {
          r = rt;
          break;
        }
      }
      for (std::size_t q = 0; q < cols.size(); ++q) {
        const double dq = trial[cols[q]] - R.theta[cols[q]];
        step += dq * dq;
        size += trial[cols[q]] * trial[cols[q]];
      }
      R.theta = trial;
      R.gauss_newton_iterations = it + 1;
      if (step <= 1e-20 * std::max(size, 1.0)) break;
    }
  }

  const EquilibratedSvd& sv = S.svd;
  R.rank = sv.rank();
  R.singular_values.assign(sv.sigma().data(), sv.sigma().data() + sv.sigma().size());
  R.condition =
      sv.rank() ? sv.sigma()[0] / sv.sigma()[static_cast<Eigen::Index>(sv.rank() - 1)] : kNaN;
  const double sse = r.squaredNorm();
  const double dof =
      static_cast<double>(m) - static_cast<double>(sv.rank()) - static_cast<double>(R.references);
  R.residual_sigma = dof > 0 ? std::sqrt(sse / dof) : kNaN;
  const Eigen::Index nf = static_cast<Eigen::Index>(cols.size());
  for (Eigen::Index q = 0; q < nf; ++q) {
    double null_weight = 0, var = 0;
    for (Eigen::Index i = static_cast<Eigen::Index>(sv.rank()); i < nf; ++i)
      null_weight += sv.V()(q, i) * sv.V()(q, i);
    for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(sv.rank()); ++i)
      var += sv.V()(q, i) * sv.V()(q, i) / (sv.sigma()[i] * sv.sigma()[i]);
    const std::size_t p = cols[static_cast<std::size_t>(q)];
    R.identifiable[p] = null_weight < 1e-12;
    if (R.identifiable[p]) R.standard_error[p] = R.residual_sigma * std::sqrt(var) / sv.scale()[q];
  }
  R.unidentifiable = null_combinations(sv, cols);

  // Before: the measured values with the set-up references removed, as the fit sees them.
  PerOutputRms<kObservationKinds> before, after;
  for (std::size_t i = 0; i < m; ++i) {
    const auto o = static_cast<std::size_t>(data.observations[i].output);
    before.add(o, y[static_cast<Eigen::Index>(i)]);
    after.add(o, r[static_cast<Eigen::Index>(i)]);
  }
  for (std::size_t o = 0; o < kObservationKinds; ++o) {
    R.rms_before[o] = before.rms(o);
    R.rms_after[o] = after.rms(o);
    R.max_after[o] = after.max_abs(o);
  }
  return R;
}

VectorXd predict_observations(const Model& model, ModelData& md, const ErrorParameterisation& param,
                              const std::vector<double>& theta, const PointData& data) {
  const Description& desc = model.description();
  VectorXd f(static_cast<Eigen::Index>(data.observations.size()));
  std::size_t row = SIZE_MAX;
  std::array<double, 6> dev{};
  std::vector<double> errors(desc.errors.size());
  for (std::size_t i = 0; i < data.observations.size(); ++i) {
    const PointObservation& ob = data.observations[i];
    const double* pose = data.poses[ob.row].data();
    if (ob.error >= 0) {
      param.errors_at(pose, theta.data(), errors.data());
      const auto k = static_cast<std::size_t>(ob.error);
      f[static_cast<Eigen::Index>(i)] = error_measured_scale(desc.errors[k]) * errors[k];
      continue;
    }
    if (ob.row != row) {
      dev = predict_deviation(model, md, param, theta, pose);
      row = ob.row;
    }
    f[static_cast<Eigen::Index>(i)] = observe(ob, dev);
  }
  return f;
}

std::array<double, 6> predict_deviation(const Model& model, ModelData& data,
                                        const ErrorParameterisation& param,
                                        const std::vector<double>& theta, const double* axes) {
  param.errors_at(axes, theta.data(), data.errors.data());
  std::array<double, 6> out{};
  model.deviation(data, axes, data.errors.data(), out.data());
  for (std::size_t o = 0; o < 6; ++o) out[o] *= kMeasuredScale[o];
  return out;
}

}  // namespace weilgen
