// The planner's model, frame and exact evaluation (plan_internal.hpp, docs/planning.md "How").
#include <algorithm>
#include <cmath>
#include <limits>

#include "plan_internal.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/base/memory.hpp"

namespace weilgen::plan_detail {

std::uint64_t mix(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

double noise_of(const PlanInput& in, std::size_t setup, int kind) {
  const KindNoise& own = in.candidates.setups[setup].noise;
  const double v = own[static_cast<std::size_t>(kind)];
  return v > 0 ? v : in.noise[static_cast<std::size_t>(kind)];
}

std::vector<MatrixXd> PlanModel::blocks(const std::vector<PlanUnit>& units, bool grow) {
  std::vector<std::size_t> unit_of;
  const PointData data = plan_observations(*in_.model, in_.candidates, units, in_.angles, &unit_of);
  const MatrixXd full = design_matrix(*in_.model, *in_.param, data);
  const auto m = static_cast<Eigen::Index>(data.observations.size());
  const auto nf = static_cast<Eigen::Index>(cols_.size());
  // Which references are shared, and their columns.
  std::vector<std::vector<std::size_t>> local(units.size());  // references within one unit
  std::vector<std::pair<std::size_t, std::size_t>> shared;    // (reference, first column)
  for (std::size_t r = 0; r < data.references.size(); ++r) {
    const ObservationReference& ref = data.references[r];
    if (ref.observations.empty()) continue;
    const std::size_t u0 = unit_of[ref.observations.front()];
    bool one = true;
    for (std::size_t i : ref.observations) one = one && unit_of[i] == u0;
    if (one) {
      local[u0].push_back(r);
      continue;
    }
    auto it = nuisance_.find(ref.what);
    if (it == nuisance_.end()) {
      if (!grow) continue;  // a reference the candidates do not have: no column for it
      it = nuisance_.emplace(ref.what, nuisance_count_).first;
      nuisance_count_ += ref.basis.size();
    }
    shared.emplace_back(r, it->second);
  }
  const Eigen::Index width = nf + static_cast<Eigen::Index>(nuisance_count_);
  MatrixXd X = MatrixXd::Zero(m, width);
  std::vector<double> weight(static_cast<std::size_t>(m));
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto& ob = data.observations[static_cast<std::size_t>(i)];
    weight[static_cast<std::size_t>(i)] =
        1 / noise_of(in_, units[unit_of[static_cast<std::size_t>(i)]].setup, ob.output);
    for (Eigen::Index q = 0; q < nf; ++q)
      X(i, q) = full(i, static_cast<Eigen::Index>(cols_[static_cast<std::size_t>(q)])) *
                weight[static_cast<std::size_t>(i)];
  }
  for (const auto& [r, first] : shared) {
    const ObservationReference& ref = data.references[r];
    for (std::size_t f = 0; f < ref.basis.size(); ++f)
      for (std::size_t t = 0; t < ref.observations.size(); ++t)
        X(static_cast<Eigen::Index>(ref.observations[t]),
          nf + static_cast<Eigen::Index>(first + f)) =
            ref.basis[f][t] * weight[ref.observations[t]];
  }
  // Rows of each unit, its own references projected out.
  std::vector<std::vector<Eigen::Index>> rows(units.size());
  for (Eigen::Index i = 0; i < m; ++i) rows[unit_of[static_cast<std::size_t>(i)]].push_back(i);
  std::vector<MatrixXd> out(units.size());
  for (std::size_t u = 0; u < units.size(); ++u) {
    MatrixXd B(static_cast<Eigen::Index>(rows[u].size()), width);
    for (std::size_t t = 0; t < rows[u].size(); ++t)
      B.row(static_cast<Eigen::Index>(t)) = X.row(rows[u][t]);
    if (!local[u].empty()) {
      PointData one;  // the unit's references re-indexed to its rows
      for (std::size_t r : local[u]) {
        ObservationReference ref = data.references[r];
        for (std::size_t& i : ref.observations)
          i = static_cast<std::size_t>(
              std::find(rows[u].begin(), rows[u].end(), static_cast<Eigen::Index>(i)) -
              rows[u].begin());
        one.references.push_back(std::move(ref));
      }
      remove_references(one, B);
      // Compressed to its information (Bᵀ B = Vᵀ S² V): the rows S Vᵀ, as many as its rank.
      // Jacobi, not Eigen 3.4.0's BDCSVD: it reads out of bounds on rank-deficient input
      // (uq/lsq.cpp), and a unit or a set of candidates often does not see every combination.
      if (B.rows() > B.cols()) {
        const Eigen::JacobiSVD<MatrixXd> svd(B, Eigen::ComputeThinV);
        const VectorXd& sv = svd.singularValues();
        Eigen::Index k = 0;
        while (k < sv.size() && sv[k] > 1e-15 * sv[0]) ++k;
        B = sv.head(k).asDiagonal() * svd.matrixV().leftCols(k).transpose();
      }
    }
    out[u] = std::move(B);
  }
  return out;
}

Frame make_frame(const std::vector<MatrixXd>& blocks, double rank_tol, Eigen::Index max_rank) {
  Frame f;
  Eigen::Index rows = 0;
  const Eigen::Index width = blocks.front().cols();
  for (const MatrixXd& b : blocks) rows += b.rows();
  check_memory(static_cast<double>(rows) * static_cast<double>(width) * 8 * 3,
               "plan: the candidates' design matrix",
               "use fewer candidates (--candidates AXIS=start:stop:count, --angles)");
  MatrixXd X(rows, width);
  Eigen::Index at = 0;
  for (const MatrixXd& b : blocks) {
    X.middleRows(at, b.rows()) = b;
    at += b.rows();
  }
  f.scale = X.colwise().norm().transpose() / std::sqrt(static_cast<double>(blocks.size()));
  const double big = f.scale.maxCoeff();
  for (Eigen::Index p = 0; p < width; ++p)
    if (!(f.scale[p] > 1e-10 * big)) f.scale[p] = 1;  // a column no candidate sees
  X = X * f.scale.cwiseInverse().asDiagonal();
  const Eigen::JacobiSVD<MatrixXd> svd(X, Eigen::ComputeThinV);
  const VectorXd& s = svd.singularValues();
  Eigen::Index r = 0;
  while (r < s.size() && r < max_rank && s[r] > rank_tol * s[0]) ++r;
  f.Q = svd.matrixV().leftCols(r);
  f.Z.reserve(blocks.size());
  for (const MatrixXd& b : blocks) f.Z.push_back(b * f.scale.cwiseInverse().asDiagonal() * f.Q);
  return f;
}

// dx, dy, dz observations (values 0) at each pose.
PointData volumetric_rows(std::vector<std::vector<double>> poses) {
  PointData g;
  g.file = "volumetric";
  g.poses = std::move(poses);
  for (std::size_t r = 0; r < g.poses.size(); ++r)
    for (int o = 0; o < 3; ++o) {
      PointObservation ob;
      ob.row = r;
      ob.output = o;
      g.observations.push_back(ob);
    }
  return g;
}

// The volumetric prediction rows: dx, dy, dz at a 5-level grid over every axis's travel.
PointData prediction_grid(const Description& d) {
  std::vector<std::vector<double>> levels;
  for (std::size_t a = 0; a < d.axes().size(); ++a) {
    const Joint& j = d.axis_joint(a);
    std::vector<double> v;
    for (int i = 0; i < 5; ++i)
      v.push_back(j.max > j.min ? j.min + (j.max - j.min) * i / 4.0 : 0.0);
    levels.push_back(v);
  }
  std::vector<std::vector<double>> poses;
  std::vector<std::size_t> digit(levels.size(), 0);
  for (bool more = true; more;) {
    std::vector<double> pose;
    for (std::size_t a = 0; a < levels.size(); ++a) pose.push_back(levels[a][digit[a]]);
    poses.push_back(pose);
    more = false;
    for (std::size_t a = levels.size(); a-- > 0;) {
      if (++digit[a] < levels[a].size()) {
        more = true;
        break;
      }
      digit[a] = 0;
    }
  }
  return volumetric_rows(std::move(poses));
}

// The figures of a layout as identify will estimate from it.
LayoutFigures evaluate(Context& cx, const std::string& name, const std::vector<PlanUnit>& units,
                       const std::vector<MatrixXd>* frame_blocks, EquilibratedSvd* keep_svd,
                       MatrixXd* cov_out, bool in_frame) {
  LayoutFigures f;
  f.name = name;
  f.layout = units;
  std::vector<std::size_t> unit_of;
  const PointData data =
      plan_observations(*cx.in.model, cx.in.candidates, units, cx.in.angles, &unit_of);
  const MatrixXd full = design_matrix(*cx.in.model, *cx.in.param, data);
  const auto m = static_cast<Eigen::Index>(data.observations.size());
  const auto nf = static_cast<Eigen::Index>(cx.cols.size());
  MatrixXd A(m, nf);
  for (Eigen::Index q = 0; q < nf; ++q)
    A.col(q) = full.col(static_cast<Eigen::Index>(cx.cols[static_cast<std::size_t>(q)]));
  remove_references(data, A);
  const EquilibratedSvd svd(A, cx.o.rank_tolerance, true);
  f.observations = static_cast<std::size_t>(m);
  f.rank = svd.rank();
  f.condition = f.rank ? svd.sigma()[0] / svd.sigma()[static_cast<Eigen::Index>(f.rank - 1)] : kNaN;
  // Cov θ̂ = A⁺ Σ A⁺ᵀ: the equilibrated minimum-norm estimator with each observation's noise.
  const MatrixXd B =
      svd.pinv_right() * svd.U().leftCols(static_cast<Eigen::Index>(f.rank)).transpose();
  VectorXd sd(m);
  for (Eigen::Index i = 0; i < m; ++i)
    sd[i] = noise_of(cx.in, units[unit_of[static_cast<std::size_t>(i)]].setup,
                     data.observations[static_cast<std::size_t>(i)].output);
  const MatrixXd C = B * sd.asDiagonal();
  const MatrixXd cov = C * C.transpose();
  f.prediction_sd_um = std::sqrt(std::max(0.0, (cov * cx.Wg).trace()));
  f.parameter_sd.assign(cx.in.param->size(), kNaN);
  for (Eigen::Index q = 0; q < nf; ++q) {
    double null_weight = 0;
    for (Eigen::Index i = static_cast<Eigen::Index>(f.rank); i < nf; ++i)
      null_weight += svd.V()(q, i) * svd.V()(q, i);
    if (null_weight < 1e-12)
      f.parameter_sd[cx.cols[static_cast<std::size_t>(q)]] = std::sqrt(std::max(0.0, cov(q, q)));
  }
  if (keep_svd) *keep_svd = svd;
  if (cov_out) *cov_out = cov;
  if (!in_frame) return f;
  // In the frame: the information of the layout's units.
  std::vector<MatrixXd> own;
  if (!frame_blocks) {
    for (const MatrixXd& b : cx.model.blocks(units, false)) own.push_back(cx.frame.to_frame(b));
    frame_blocks = &own;
  }
  const Eigen::Index r = cx.frame.Q.cols();
  MatrixXd M = MatrixXd::Zero(r, r);
  for (const MatrixXd& z : *frame_blocks) M.noalias() += z.transpose() * z;
  f.log_det = design_criterion(M, DesignCriterion::D, cx.frame.W);
  f.criterion = design_criterion(M, cx.o.criterion, cx.frame.W);
  const Eigen::SelfAdjointEigenSolver<MatrixXd> es(M, Eigen::EigenvaluesOnly);
  VectorXd sv(r);
  for (Eigen::Index i = 0; i < r; ++i)
    sv[i] = std::sqrt(std::max(0.0, es.eigenvalues()[r - 1 - i]));
  f.observability = observability_indices(sv, f.observations);
  return f;
}

std::vector<MatrixXd> frame_blocks_of(const Context& cx, const std::vector<std::size_t>& idx) {
  std::vector<MatrixXd> z;
  for (std::size_t j : idx) z.push_back(cx.frame.Z[j]);
  return z;
}

std::vector<PlanUnit> units_of(const PlanCandidates& c, const std::vector<std::size_t>& idx) {
  std::vector<PlanUnit> u;
  for (std::size_t j : idx) u.push_back(c.units[j]);
  return u;
}

LayoutFigures evaluate_candidates(Context& cx, const std::string& name,
                                  const std::vector<std::size_t>& idx) {
  const std::vector<MatrixXd> z = frame_blocks_of(cx, idx);
  LayoutFigures f = evaluate(cx, name, units_of(cx.in.candidates, idx), &z);
  f.units = idx;
  return f;
}

// Greedy rank building in the frame: units in turn, each adding the most new directions, until
// the frame's rank. Returns how many units it took.
std::size_t greedy_rank_units(const Frame& f, const std::vector<std::size_t>& forced) {
  const Eigen::Index r = f.Q.cols();
  MatrixXd basis(r, 0);
  auto add = [&](const MatrixXd& z) {
    MatrixXd p = z.transpose();  // r × k
    if (basis.cols()) p -= basis * (basis.transpose() * p);
    const Eigen::JacobiSVD<MatrixXd> s(p, Eigen::ComputeThinU);
    Eigen::Index k = 0;
    while (k < s.singularValues().size() && s.singularValues()[k] > 1e-8 * std::max(1.0, z.norm()))
      ++k;
    if (k == 0) return;
    MatrixXd nb(r, basis.cols() + k);
    nb << basis, s.matrixU().leftCols(k);
    basis = nb;
  };
  std::size_t n = 0;
  for (std::size_t j : forced) add(f.Z[j]), ++n;
  std::vector<char> used(f.Z.size(), 0);
  for (std::size_t j : forced) used[j] = 1;
  while (basis.cols() < r) {
    std::size_t best = f.Z.size();
    double best_new = 0;
    for (std::size_t j = 0; j < f.Z.size(); ++j) {
      if (used[j]) continue;
      MatrixXd p = f.Z[j].transpose();
      if (basis.cols()) p -= basis * (basis.transpose() * p);
      const double gain = p.squaredNorm() / std::max(1e-300, f.Z[j].squaredNorm());
      if (gain > best_new + 1e-12) best_new = gain, best = j;
    }
    if (best == f.Z.size() || best_new < 1e-12) break;
    used[best] = 1;
    add(f.Z[best]);
    ++n;
  }
  return n;
}

}  // namespace weilgen::plan_detail
