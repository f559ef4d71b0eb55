#include "weilgen/analysis/identify.hpp"

#include <Eigen/Dense>
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

namespace {

int error_of_name(const Description& d, const std::string& name, const std::string& what) {
  const int k = d.error_index(name);
  if (k < 0)
    throw std::invalid_argument(what + ": unknown error '" + name + "' (machine " + d.name +
                                " has " + join(error_names(d)) + ")");
  return k;
}

// The joint with the range its link takes over the corners of the independent axes' travel
// (exact for a link linear in each axis, as Y23.2 = -Y23.1 or A12 = A04).
Joint linked_range(const Description& d, const Joint& j, const std::vector<double>& params) {
  Joint out = j;
  const std::vector<int> axes = d.axes();
  double lo = INFINITY, hi = -INFINITY;
  const std::size_t n = axes.size();
  for (std::size_t corner = 0; corner < (std::size_t{1} << std::min<std::size_t>(n, 16));
       ++corner) {
    std::map<std::string, double> values;
    for (std::size_t p = 0; p < d.parameters.size(); ++p)
      values[d.parameters[p].name] = p < params.size() ? params[p] : d.parameters[p].value;
    for (std::size_t a = 0; a < n; ++a) {
      const Joint& ja = d.bodies[static_cast<std::size_t>(axes[a])].joint;
      values[ja.coordinate] = (corner >> a) & 1 ? ja.max : ja.min;
    }
    resolve_links(d, values);
    lo = std::min(lo, values.at(j.coordinate));
    hi = std::max(hi, values.at(j.coordinate));
  }
  out.min = lo;
  out.max = hi;
  return out;
}

}  // namespace

PdgeBasisChoice parse_pdge_flags(const Description& desc, const std::vector<std::string>& flags,
                                 PdgeBasisChoice base) {
  for (const std::string& flag : flags) {
    const auto eq = flag.find('=');
    const std::string what = "--pdge \"" + flag + "\"";
    try {
      if (eq == std::string::npos) {
        parse_basis(trim(flag));
        base.all = trim(flag);
      } else {
        const std::string name = trim(flag.substr(0, eq)), spec = trim(flag.substr(eq + 1));
        const int k = error_of_name(desc, name, what);
        parse_basis(spec);
        base.per_error.emplace_back(desc.errors[static_cast<std::size_t>(k)].name, spec);
      }
    } catch (const std::invalid_argument& e) {
      const std::string m = e.what();
      throw std::invalid_argument(m.rfind("--pdge", 0) == 0 ? m : what + ": " + m);
    }
  }
  return base;
}

ErrorParameterisation::ErrorParameterisation(const Description& desc, const PdgeBasisChoice& choice,
                                             std::vector<double> parameters)
    : desc_(&desc), param_values_(std::move(parameters)) {
  if (param_values_.empty())
    for (const Parameter& p : desc.parameters) param_values_.push_back(p.value);
  const std::vector<int> axes = desc.axes();
  const std::size_t ne = desc.errors.size();
  bases_.resize(ne);
  first_.resize(ne);
  axis_index_.assign(ne, -1);
  coordinate_.resize(ne);
  to_base_.resize(ne);
  for (std::size_t k = 0; k < ne; ++k) {
    const ErrorDef& e = desc.errors[k];
    to_base_[k] = e.to_base;
    first_[k] = params_.size();
    const Joint& j = desc.bodies[static_cast<std::size_t>(e.body)].joint;
    if (e.dependence == Dependence::PIGE || j.type == JointType::Fixed) {
      params_.push_back({static_cast<int>(k), 0, e.name, e.unit});
      continue;
    }
    // Precedence: per-error flag, run-wide flag, the error's basis, the machine's, fallback.
    std::string spec = choice.fallback.empty() ? default_pdge_basis(j) : choice.fallback;
    SourceLoc where;
    const bool rotary = j.type == JointType::Revolute;
    const std::string& machine = rotary ? desc.pdge_basis_revolute : desc.pdge_basis;
    if (!machine.empty())
      spec = machine, where = rotary ? desc.pdge_basis_revolute_loc : desc.pdge_basis_loc;
    if (!e.basis.empty()) spec = e.basis, where = e.basis_loc;
    if (choice.all) spec = *choice.all, where = {};
    for (const auto& [name, s] : choice.per_error)
      if (name == e.name) spec = s, where = {};
    // A linked joint without a range of its own takes its link's range over the travel.
    Joint placed = j;
    if (!(j.max > j.min) && j.link) placed = linked_range(desc, j, param_values_);
    if (!(placed.max > placed.min)) {
      throw InputError(j.loc, "joint " + j.coordinate + ": " + e.name +
                                  " is position dependent but the joint has no travel range "
                                  "(range: [min, max]) to place its basis on");
    }
    try {
      bases_[k] = basis_on_joint(parse_basis(spec), placed);
    } catch (const std::invalid_argument& ex) {
      if (where.line > 0) throw InputError(where, ex.what());
      throw std::invalid_argument(e.name + ": " + ex.what());
    }
    coordinate_[k] = j.coordinate;
    for (std::size_t a = 0; a < axes.size(); ++a)
      if (axes[a] == e.body) axis_index_[k] = static_cast<int>(a);
    const std::vector<std::string> names = bases_[k]->term_names();
    for (std::size_t t = 0; t < names.size(); ++t)
      params_.push_back({static_cast<int>(k), t, e.name + "[" + names[t] + "]", e.unit});
  }
}

double ErrorParameterisation::position_of(std::size_t k, const double* axes) const {
  if (axis_index_[k] >= 0) return axes[axis_index_[k]];
  // A linked coordinate: evaluate the links from the independent axes and the parameters.
  std::map<std::string, double> values;
  for (std::size_t p = 0; p < desc_->parameters.size(); ++p)
    values[desc_->parameters[p].name] = param_values_[p];
  const std::vector<int> ax = desc_->axes();
  for (std::size_t a = 0; a < ax.size(); ++a)
    values[desc_->bodies[static_cast<std::size_t>(ax[a])].joint.coordinate] = axes[a];
  resolve_links(*desc_, values);
  return values.at(coordinate_[k]);
}

void ErrorParameterisation::derivatives(const double* axes, double* jac) const {
  for (std::size_t k = 0; k < bases_.size(); ++k) {
    double* out = jac + first_[k];
    if (!bases_[k]) {
      out[0] = to_base_[k];
      continue;
    }
    bases_[k]->evaluate(position_of(k, axes), out);
    for (std::size_t t = 0; t < bases_[k]->size(); ++t) out[t] *= to_base_[k];
  }
}

void ErrorParameterisation::errors_at(const double* axes, const double* theta,
                                      double* errors) const {
  std::vector<double> jac(params_.size());
  derivatives(axes, jac.data());
  std::fill(errors, errors + bases_.size(), 0.0);
  for (std::size_t p = 0; p < params_.size(); ++p) errors[params_[p].error] += jac[p] * theta[p];
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
