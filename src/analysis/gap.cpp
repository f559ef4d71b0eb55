#include "weilgen/analysis/gap.hpp"

#include <algorithm>
#include <boost/math/distributions/fisher_f.hpp>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <set>
#include <stdexcept>

#include "weilgen/analysis/ballbar_model.hpp"
#include "weilgen/analysis/gap_effects.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/uq/lsq.hpp"

namespace weilgen {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using Index = Eigen::Index;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Upper tail of F(d1, d2); 1 for degenerate inputs.
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

}  // namespace

// ---- Data ------------------------------------------------------------------------------------

namespace {

// A ballbar trace's dr observations: poses on the circle, the ball-to-ball unit vectors.
PointData ballbar_points(const MeasurementTable& t, const Description& desc,
                         const BallbarFlags& flags, const std::vector<double>& parameters,
                         std::optional<BallbarCircle>& circle) {
  const BallbarMachine machine = ballbar_machine(desc, parameters);
  circle = parse_ballbar_circle(t, machine, flags);
  if (!t.has("angle_deg"))
    throw InputError(SourceLoc{t.file, t.header_line, 0},
                     "a ballbar trace needs an 'angle_deg' column beside 'dr_um' (columns: " +
                         join(t.columns) + ")");
  const std::vector<double>& angle = t.column("angle_deg");
  const std::vector<double>& dr = t.column("dr_um");
  PointData p;
  p.file = t.file;
  p.poses.assign(t.rows(), {});
  std::vector<double> angles;  // of the measured rows, for one call to ballbar_directions
  for (std::size_t r = 0; r < t.rows(); ++r) {
    if (!std::isfinite(dr[r])) continue;
    if (!std::isfinite(angle[r]))
      throw InputError(SourceLoc{t.file, t.lines[r], 0},
                       "column 'angle_deg' is empty but dr_um is measured");
    p.poses[r] = ballbar_pose(machine, *circle, angle[r]);
    PointObservation ob;
    ob.row = r;
    ob.line = t.lines[r];
    ob.output = kRadialOutput;
    ob.value = dr[r];
    p.observations.push_back(ob);
    angles.push_back(angle[r]);
  }
  if (p.observations.empty())
    throw InputError(SourceLoc{t.file, 0, 0}, "no observations (no row has a measured dr_um)");
  const std::vector<std::array<double, 3>> u = ballbar_directions(machine, *circle, angles);
  for (std::size_t i = 0; i < u.size(); ++i) p.observations[i].radial = u[i];
  p.count[kRadialOutput] = p.observations.size();
  return p;
}

}  // namespace

GapData gap_data(const MeasurementTable& table, const Description& desc,
                 const std::map<std::string, double>& fixed, const BallbarFlags& ballbar,
                 const std::vector<double>& parameters) {
  MeasurementTable t = table;
  GapData g;
  const bool trace = t.has("dr_um");
  for (int b : desc.axes()) {
    const std::string& c = desc.bodies[static_cast<std::size_t>(b)].joint.coordinate;
    g.axes.push_back(c);
    if (trace || t.has(c)) continue;
    const auto it = fixed.find(c);
    if (it == fixed.end())
      throw InputError(SourceLoc{t.file, t.header_line, 0},
                       "missing column '" + c + "' (give the coordinate of a pose the data do " +
                           "not vary with --at " + c + "=VALUE; columns: " + join(t.columns) + ")");
    t.values[c] = std::vector<double>(t.rows(), it->second);
    t.columns.push_back(c);
    ColumnInfo info;
    info.name = c;
    info.role = ColumnRole::Coordinate;
    info.unit = desc.bodies[static_cast<std::size_t>(b)].joint.unit;
    t.info.push_back(info);
    g.fixed_axes.push_back(c);
  }
  g.points = trace ? ballbar_points(t, desc, ballbar, parameters, g.circle) : point_data(t, desc);
  const std::size_t rows = t.rows();
  g.time_s = t.has("t_s") ? t.column("t_s") : std::vector<double>(rows, kNaN);
  g.cycle = t.has("cycle") ? t.column("cycle") : std::vector<double>(rows, kNaN);
  // Observed rows only decide what varies.
  std::vector<bool> observed(rows, false);
  for (const PointObservation& o : g.points.observations) observed[o.row] = true;
  auto check_varies = [&](const std::string& name, const std::vector<double>& v, const char* unit) {
    double lo = INFINITY, hi = -INFINITY;
    for (std::size_t r = 0; r < rows; ++r) {
      if (!observed[r]) continue;
      if (!std::isfinite(v[r]))
        throw InputError(SourceLoc{t.file, t.lines[r], 0},
                         "column '" + name +
                             "' is empty or not a number where a deviation is "
                             "measured (the diagnosis needs it in every row)");
      lo = std::min(lo, v[r]), hi = std::max(hi, v[r]);
    }
    if (!(hi > lo))
      throw InputError(SourceLoc{t.file, t.header_line, 0},
                       "column '" + name + "' is constant (" + format_short(lo) + " " + unit +
                           "): it cannot explain anything; drop the column");
  };
  for (const std::string& c : t.columns_with(ColumnRole::Temperature)) {
    check_varies(c, t.column(c), "degC");
    g.temperature[c] = t.column(c);
  }
  for (const std::string& c : t.columns_with(ColumnRole::Covariate)) {
    check_varies(c, t.column(c), t.info_of(c).unit.c_str());
    g.covariate[c] = t.column(c);
  }
  if (t.has("t_s")) check_varies("t_s", g.time_s, "s");
  // Directions: dir_<axis>, or `dir` for the axis that varies most.
  if (trace) {
    check_varies("angle_deg", t.column("angle_deg"), "deg");
    g.covariate["angle_deg"] = t.column("angle_deg");
  }
  for (const std::string& c : t.columns_with(ColumnRole::Direction)) {
    std::string axis = t.info_of(c).axis;
    if (axis.empty() && trace) {  // a trace's `dir` is its feed (ccw +1, cw -1)
      check_varies("dir", t.column(c), "");
      g.covariate["feed"] = t.column(c);
      continue;
    }
    if (axis.empty()) {
      std::size_t best = 0;
      for (const std::string& a : g.axes) {
        const std::size_t n = t.has(a) ? distinct(t.column(a)) : 0;
        if (n > best) best = n, axis = a;
      }
    }
    if (!axis.empty()) g.dir[axis] = t.column(c);
  }
  if (g.points.observations.size() < 10)
    throw InputError(SourceLoc{t.file, 0, 0}, "only " +
                                                  std::to_string(g.points.observations.size()) +
                                                  " observations: the diagnosis needs at least 10");
  return g;
}

// ---- Held-out schemes ----------------------------------------------------------------------

std::string HoldoutScheme::str() const {
  switch (kind) {
    case Kind::Cycle:
      return "cycle:" + std::to_string(folds);
    case Kind::Time:
      return "time:" + std::to_string(folds);
    case Kind::Space:
      return "space:" + axis + ":" + std::to_string(folds);
    case Kind::Forward:
      return "forward:" + format_short(fraction);
  }
  return "";
}

std::optional<HoldoutScheme> parse_holdout(const std::string& text) {
  const std::vector<std::string> parts = [&] {
    std::vector<std::string> v;
    std::size_t s = 0;
    for (std::size_t i = 0; i <= text.size(); ++i)
      if (i == text.size() || text[i] == ':') v.push_back(text.substr(s, i - s)), s = i + 1;
    return v;
  }();
  const std::string what = "--holdout \"" + text + "\"";
  auto whole = [&](const std::string& s) {
    char* end = nullptr;
    const long k = std::strtol(s.c_str(), &end, 10);
    if (s.empty() || *end || k < 2 || k > 100)
      throw std::invalid_argument(what + ": the number of folds must be a whole number 2..100");
    return static_cast<int>(k);
  };
  HoldoutScheme h;
  const std::string& k = parts[0];
  if (k == "auto" && parts.size() == 1) return std::nullopt;
  if (k == "cycle" || k == "time") {
    h.kind = k == "cycle" ? HoldoutScheme::Kind::Cycle : HoldoutScheme::Kind::Time;
    if (parts.size() > 2) throw std::invalid_argument(what + ": expected " + k + "[:FOLDS]");
    if (parts.size() == 2) h.folds = whole(parts[1]);
    return h;
  }
  if (k == "space") {
    h.kind = HoldoutScheme::Kind::Space;
    if (parts.size() > 3) throw std::invalid_argument(what + ": expected space[:AXIS][:FOLDS]");
    for (std::size_t i = 1; i < parts.size(); ++i) {
      if (!parts[i].empty() && std::isdigit(static_cast<unsigned char>(parts[i][0])))
        h.folds = whole(parts[i]);
      else
        h.axis = parts[i];
    }
    return h;
  }
  if (k == "forward") {
    h.kind = HoldoutScheme::Kind::Forward;
    if (parts.size() > 2) throw std::invalid_argument(what + ": expected forward[:FRACTION]");
    if (parts.size() == 2) {
      char* end = nullptr;
      h.fraction = std::strtod(parts[1].c_str(), &end);
      if (parts[1].empty() || *end || !(h.fraction > 0.1 && h.fraction < 0.95))
        throw std::invalid_argument(what + ": the training fraction must be in (0.1, 0.95)");
    }
    return h;
  }
  throw std::invalid_argument(what + ": unknown scheme '" + k +
                              "' (expected cycle[:K], time[:K], space[:AXIS][:K], "
                              "forward[:FRACTION] or auto)");
}

HoldoutScheme default_holdout(const GapData& d) {
  HoldoutScheme h;
  if (distinct(d.cycle) >= 3) {
    h.kind = HoldoutScheme::Kind::Cycle;
  } else if (distinct(d.time_s) >= 10) {
    h.kind = HoldoutScheme::Kind::Time;
  } else {
    h.kind = HoldoutScheme::Kind::Space;
  }
  return h;
}

std::vector<Split> make_splits(const GapData& d, const HoldoutScheme& s, std::size_t min_train) {
  const auto& obs = d.points.observations;
  const std::size_t m = obs.size();
  std::vector<int> fold(m, -1);
  int k = s.folds;
  const std::string file = d.points.file;
  auto fail = [&](const std::string& msg) {
    throw InputError(SourceLoc{file, 0, 0}, "--holdout " + s.str() + ": " + msg);
  };
  if (s.kind == HoldoutScheme::Kind::Cycle) {
    std::vector<double> ids;
    for (const auto& o : obs) {
      if (!std::isfinite(d.cycle[o.row])) fail("needs a cycle column with a value in every row");
      ids.push_back(d.cycle[o.row]);
    }
    std::vector<double> u = ids;
    std::sort(u.begin(), u.end());
    u.erase(std::unique(u.begin(), u.end()), u.end());
    if (u.size() < 2) fail("needs at least 2 cycles (has " + std::to_string(u.size()) + ")");
    k = std::min<int>(k, static_cast<int>(u.size()));
    for (std::size_t i = 0; i < m; ++i)
      fold[i] = static_cast<int>(std::lower_bound(u.begin(), u.end(), ids[i]) - u.begin()) % k;
  } else if (s.kind == HoldoutScheme::Kind::Time || s.kind == HoldoutScheme::Kind::Forward) {
    std::vector<std::size_t> order(m);
    std::iota(order.begin(), order.end(), 0);
    for (const auto& o : obs)
      if (!std::isfinite(d.time_s[o.row])) fail("needs a t_s column with a value in every row");
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return d.time_s[obs[a].row] < d.time_s[obs[b].row];
    });
    if (s.kind == HoldoutScheme::Kind::Forward) {
      k = 1;
      const auto cut = static_cast<std::size_t>(s.fraction * static_cast<double>(m));
      for (std::size_t i = 0; i < m; ++i) fold[order[i]] = i < cut ? -1 : 0;
    } else {
      for (std::size_t i = 0; i < m; ++i)
        fold[order[i]] = static_cast<int>(i * static_cast<std::size_t>(k) / m);
    }
  } else {
    std::string axis = s.axis;
    std::size_t a = 0, best = 0;
    for (std::size_t i = 0; i < d.axes.size(); ++i) {
      std::vector<double> v;
      for (const auto& p : d.points.poses)
        if (!p.empty()) v.push_back(p[i]);
      const std::size_t n = distinct(v);
      if (axis.empty() ? n > best : d.axes[i] == axis) a = i, best = n;
    }
    if (!axis.empty() && d.axes[a] != axis)
      fail("'" + axis + "' is not a coordinate (" + join(d.axes) + ")");
    std::vector<double> u;
    for (const auto& o : obs) u.push_back(d.points.poses[o.row][a]);
    std::vector<double> levels = u;
    std::sort(levels.begin(), levels.end());
    levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
    if (levels.size() < 2) fail("the data do not vary along " + d.axes[a]);
    k = std::min<int>(k, static_cast<int>(levels.size()));
    for (std::size_t i = 0; i < m; ++i) {
      const auto l = static_cast<std::size_t>(std::lower_bound(levels.begin(), levels.end(), u[i]) -
                                              levels.begin());
      fold[i] = static_cast<int>(l * static_cast<std::size_t>(k) / levels.size());
    }
  }
  std::vector<Split> splits(static_cast<std::size_t>(k));
  for (std::size_t i = 0; i < m; ++i)
    for (int f = 0; f < k; ++f) (fold[i] == f ? splits[f].test : splits[f].train).push_back(i);
  for (std::size_t f = 0; f < splits.size(); ++f) {
    if (splits[f].test.size() < 3)
      fail("held-out part " + std::to_string(f + 1) + " has " +
           std::to_string(splits[f].test.size()) + " observations (at least 3)");
    if (splits[f].train.size() < min_train)
      fail("too few observations: a training part has " + std::to_string(splits[f].train.size()) +
           ", the model needs at least " + std::to_string(min_train));
  }
  return splits;
}

// ---- The linear engine ---------------------------------------------------------------------

namespace {

// The training fit of one split: A_tr = U S Vᵀ (equilibrated, rank r), the pseudo-inverse as
// VS·Uᵀ, residuals and test leverages.
struct FoldFit {
  MatrixXd U, VS, W;  // W = A_test · VS
  VectorXd theta, res_train, res_test, lev_test;
  std::size_t rank = 0;
};

MatrixXd rows_of(const MatrixXd& M, const std::vector<std::size_t>& idx) {
  MatrixXd R(static_cast<Index>(idx.size()), M.cols());
  for (std::size_t i = 0; i < idx.size(); ++i)
    R.row(static_cast<Index>(i)) = M.row(static_cast<Index>(idx[i]));
  return R;
}
VectorXd rows_of(const VectorXd& v, const std::vector<std::size_t>& idx) {
  VectorXd R(static_cast<Index>(idx.size()));
  for (std::size_t i = 0; i < idx.size(); ++i)
    R[static_cast<Index>(i)] = v[static_cast<Index>(idx[i])];
  return R;
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

// The split that trains on every observation (and holds none out).
Split all_rows(std::size_t n) {
  Split s;
  s.train.resize(n);
  std::iota(s.train.begin(), s.train.end(), 0);
  return s;
}

struct Engine {
  const GapData& data;
  MatrixXd A;  // baseline (plus accepted effects)
  VectorXd y;
  std::vector<Split> splits;
  std::vector<FoldFit> folds;
  double full_sse = 0;
  std::size_t full_rank = 0;
  FoldFit full;  // the fit on all data

  // The fit on all data (its rank sizes the splits; its SSE is the F tests' reference).
  void fit_full() {
    full = fit_fold(A, y, all_rows(static_cast<std::size_t>(y.size())));
    full_sse = full.res_train.squaredNorm();
    full_rank = full.rank;
  }
  void fit_folds() {
    folds.clear();
    for (const Split& s : splits) folds.push_back(fit_fold(A, y, s));
  }
  void refit() {
    fit_full();
    fit_folds();
  }
  // Held-out residual and leverage per observation.
  void heldout(VectorXd& r, VectorXd& h) const {
    r = VectorXd::Constant(y.size(), kNaN);
    h = VectorXd::Zero(y.size());
    for (std::size_t f = 0; f < splits.size(); ++f)
      for (std::size_t i = 0; i < splits[f].test.size(); ++i) {
        r[static_cast<Index>(splits[f].test[i])] = folds[f].res_test[static_cast<Index>(i)];
        h[static_cast<Index>(splits[f].test[i])] = folds[f].lev_test[static_cast<Index>(i)];
      }
  }
};

// Baseline θ of a split in the parameterisation's full size (effects may append columns).
std::vector<double> split_theta(const VectorXd& theta, std::size_t np) {
  return std::vector<double>(theta.data(), theta.data() + static_cast<Index>(np));
}

struct Gap {
  double ss = 0, expected = 0;  // Σ r², Σ σ²(1 + h)
  std::size_t n = 0;
};

// Excess RMS over the floor and the F-test p-value of a set of held-out residuals.
void gap_stats(const Gap& g, double dof, double& excess, double& p) {
  excess = g.n ? std::sqrt(std::max(0.0, (g.ss - g.expected) / static_cast<double>(g.n))) : 0;
  p = g.n ? f_sf((g.ss / g.expected), static_cast<double>(g.n), dof) : 1;
}

}  // namespace

// ---- Noise floor ---------------------------------------------------------------------------

namespace {

// Robust pooled scale of successive differences: each sequence of 3 or more has its mean
// difference removed (a linear drift along it does not count), then
// σ = 1.4826 · median|d − median d| / √2 over all differences, so that a step or a few drift
// jumps between repeats do not inflate the floor as they would a mean square. Degrees of
// freedom: the MAD's efficiency (0.37) times the MSSD's (2/3) times the number of differences.
void mssd(const std::vector<std::vector<double>>& sequences, double& sigma2, double& dof,
          std::size_t& differences) {
  std::vector<double> all;
  for (const auto& s : sequences) {
    if (s.size() < 2) continue;
    std::vector<double> d;
    for (std::size_t i = 1; i < s.size(); ++i) d.push_back(s[i] - s[i - 1]);
    const std::size_t k = d.size();
    if (k < 2) {
      all.push_back(d[0]);
      continue;
    }
    const double mean = std::accumulate(d.begin(), d.end(), 0.0) / static_cast<double>(k);
    // Var(d_i − d̄) = 2σ²(1 + 1/k² − [i is the first or last]/k) for white noise: rescale to 2σ².
    const double kk = static_cast<double>(k);
    for (std::size_t i = 0; i < k; ++i) {
      const double end = (i == 0 || i + 1 == k) ? 1.0 / kk : 0.0;
      all.push_back((d[i] - mean) / std::sqrt(1 + 1 / (kk * kk) - end));
    }
  }
  differences = all.size();
  if (all.size() < 3) {
    sigma2 = kNaN;
    dof = 0;
    return;
  }
  auto median = [](std::vector<double> v) {
    const auto mid = v.begin() + static_cast<long>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
  };
  const double m = median(all);
  for (double& x : all) x = std::abs(x - m);
  const double sigma = 1.4826 * median(all) / std::sqrt(2.0);
  sigma2 = sigma * sigma;
  dof = 0.37 * (2.0 / 3.0) * static_cast<double>(differences);
}

NoiseFloor noise_floor(const GapData& d, const VectorXd& heldout) {
  const auto& obs = d.points.observations;
  NoiseFloor nf;
  auto time_of = [&](std::size_t i) {
    const double t = d.time_s[obs[i].row];
    return std::isfinite(t) ? t : static_cast<double>(obs[i].row);
  };
  // Repeats: the same pose, directions and output.
  std::map<std::vector<double>, std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    std::vector<double> key = d.points.poses[obs[i].row];
    for (const auto& [a, v] : d.dir) key.push_back(v[obs[i].row]);
    key.push_back(obs[i].output);
    groups[key].push_back(i);
  }
  std::size_t repeated = 0;
  std::array<std::vector<std::vector<double>>, kObservationKinds> seq;
  for (auto& [key, idx] : groups) {
    if (idx.size() < 2) continue;
    repeated += idx.size();
    std::stable_sort(idx.begin(), idx.end(),
                     [&](std::size_t a, std::size_t b) { return time_of(a) < time_of(b); });
    std::vector<double> s;
    for (std::size_t i : idx) s.push_back(obs[i].value);
    seq[static_cast<std::size_t>(obs[idx[0]].output)].push_back(s);
  }
  const bool repeats = repeated * 10 >= obs.size() * 3;  // >= 30 % of observations repeated
  // Small-scale sequences: the held-out residual in time (or row) order, per output.
  std::array<std::vector<std::vector<double>>, kObservationKinds> small;
  {
    std::vector<std::size_t> order(obs.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return time_of(a) < time_of(b); });
    std::array<std::vector<double>, kObservationKinds> s;
    for (std::size_t i : order)
      if (std::isfinite(heldout[static_cast<Index>(i)]))
        s[static_cast<std::size_t>(obs[i].output)].push_back(heldout[static_cast<Index>(i)]);
    for (std::size_t o = 0; o < kObservationKinds; ++o) small[o].push_back(s[o]);
  }
  struct Estimate {
    std::array<double, kObservationKinds> per_output{};
    double sigma = kNaN, dof = 0;
    std::size_t n = 0;
  };
  auto estimate = [](const std::array<std::vector<std::vector<double>>, kObservationKinds>& sq) {
    Estimate e;
    std::vector<std::vector<double>> all;
    e.per_output.fill(kNaN);
    for (std::size_t o = 0; o < kObservationKinds; ++o) {
      double s2 = 0, dof = 0;
      std::size_t n = 0;
      mssd(sq[o], s2, dof, n);
      if (n) e.per_output[o] = std::sqrt(s2);
      for (const auto& x : sq[o]) all.push_back(x);
    }
    double s2 = 0;
    mssd(all, s2, e.dof, e.n);
    e.sigma = std::sqrt(s2);
    return e;
  };
  const Estimate from_small = estimate(small);
  // Repeats are the floor unless a drift or step between them (every repeat straddles it)
  // makes them read higher than the residual's small-scale structure: then the smaller one.
  Estimate chosen = from_small;
  bool use_repeats = false;
  std::string other;
  if (repeats) {
    const Estimate from_repeats = estimate(seq);
    use_repeats = !(from_small.sigma < from_repeats.sigma);
    if (use_repeats) chosen = from_repeats;
    other = use_repeats ? "; the small-scale estimate is " + format_short(from_small.sigma)
                        : "; repeats read " + format_short(from_repeats.sigma) +
                              " (a drift or step between them)";
  }
  nf.per_output = chosen.per_output;
  nf.sigma_um = chosen.sigma;
  nf.dof = chosen.dof;
  nf.source = use_repeats ? "repeats" : "small-scale";
  nf.detail = std::to_string(chosen.n) +
              (use_repeats ? " successive differences of repeated observations (same pose, "
                             "direction and output, in time order)"
                           : " successive differences of the held-out residual in time (or row) "
                             "order") +
              other;
  if (!(nf.sigma_um > 0))
    throw InputError(SourceLoc{d.points.file, 0, 0},
                     "cannot estimate the noise floor (no repeated observations and too few "
                     "held-out residuals)");
  return nf;
}

}  // namespace

// ---- Localisation --------------------------------------------------------------------------

namespace {

std::vector<GapRegion> localise(const GapData& d, const VectorXd& r, const VectorXd& h,
                                const NoiseFloor& nf, double alpha) {
  const auto& obs = d.points.observations;
  const double s2 = nf.sigma_um * nf.sigma_um;
  struct Dim {
    std::string by;
    std::vector<double> value;  // per observation
    bool ordered = true;
  };
  std::vector<Dim> dims;
  for (std::size_t a = 0; a < d.axes.size(); ++a) {
    Dim dm{d.axes[a], {}, true};
    for (const auto& o : obs) dm.value.push_back(d.points.poses[o.row][a]);
    if (distinct(dm.value) >= 2) dims.push_back(dm);
  }
  auto add = [&](const std::string& name, const std::vector<double>& per_row, bool ordered) {
    Dim dm{name, {}, ordered};
    for (const auto& o : obs) dm.value.push_back(per_row[o.row]);
    if (distinct(dm.value) >= 2) dims.push_back(dm);
  };
  add("t_s", d.time_s, true);
  for (const auto& [a, v] : d.dir) add("dir_" + a, v, false);
  add("cycle", d.cycle, false);
  for (const auto& [n, v] : d.temperature) add(n, v, true);
  for (const auto& [n, v] : d.covariate) add(n, v, true);

  std::vector<GapRegion> bins;
  auto stats = [&](GapRegion& g, const std::vector<std::size_t>& idx) {
    Gap gp;
    double ss = 0;
    for (std::size_t i : idx) {
      const double ri = r[static_cast<Index>(i)];
      if (!std::isfinite(ri)) continue;
      gp.ss += ri * ri;
      gp.expected += s2 * (1 + h[static_cast<Index>(i)]);
      ss += ri * ri;
      ++gp.n;
    }
    g.n = gp.n;
    g.rms_um = gp.n ? std::sqrt(ss / static_cast<double>(gp.n)) : 0;
    gap_stats(gp, nf.dof, g.excess_um, g.p_value);
  };
  for (int o = 0; o < static_cast<int>(kObservationKinds); ++o) {
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < obs.size(); ++i)
      if (obs[i].output == o) idx.push_back(i);
    if (idx.empty()) continue;
    GapRegion g;
    g.by = "output";
    g.output = observation_name(static_cast<std::size_t>(o));
    stats(g, idx);
    bins.push_back(g);
    for (const Dim& dm : dims) {
      // Up to 8 bins of (nearly) equal count over the sorted distinct values.
      std::vector<double> vals;
      for (std::size_t i : idx) vals.push_back(dm.value[i]);
      std::vector<double> u = vals;
      std::sort(u.begin(), u.end());
      u.erase(std::unique(u.begin(), u.end()), u.end());
      const std::size_t nb = std::min<std::size_t>(8, u.size());
      std::vector<std::vector<std::size_t>> members(nb);
      std::vector<std::pair<double, double>> range(nb, {INFINITY, -INFINITY});
      for (std::size_t k = 0; k < idx.size(); ++k) {
        const auto l =
            static_cast<std::size_t>(std::lower_bound(u.begin(), u.end(), vals[k]) - u.begin());
        const std::size_t b = l * nb / u.size();
        members[b].push_back(idx[k]);
        range[b].first = std::min(range[b].first, vals[k]);
        range[b].second = std::max(range[b].second, vals[k]);
      }
      for (std::size_t b = 0; b < nb; ++b) {
        GapRegion reg;
        reg.by = dm.by;
        reg.output = observation_name(static_cast<std::size_t>(o));
        reg.from = range[b].first;
        reg.to = range[b].second;
        stats(reg, members[b]);
        bins.push_back(reg);
      }
    }
  }
  const double tests = static_cast<double>(bins.size());
  for (GapRegion& g : bins) {
    g.p_value = std::min(1.0, g.p_value * tests);  // Bonferroni over every bin tested
    g.significant = g.p_value < alpha;
  }
  // Merge runs of adjacent significant bins of one ordered dimension and output into regions.
  std::map<std::string, std::size_t> first_of, end_of;
  for (std::size_t i = 0; i < bins.size(); ++i) {
    const std::string key = bins[i].by + "/" + bins[i].output;
    if (!first_of.count(key)) first_of[key] = i;
    end_of[key] = i + 1;
  }
  std::vector<GapRegion> out;
  for (std::size_t i = 0; i < bins.size();) {
    GapRegion g = bins[i];
    std::size_t j = i + 1;
    const bool ordered =
        g.by != "output" && std::any_of(dims.begin(), dims.end(),
                                        [&](const Dim& dm) { return dm.by == g.by && dm.ordered; });
    while (ordered && g.significant && j < bins.size() && bins[j].significant &&
           bins[j].by == g.by && bins[j].output == g.output) {
      const double w1 = static_cast<double>(g.n), w2 = static_cast<double>(bins[j].n);
      g.rms_um =
          std::sqrt((g.rms_um * g.rms_um * w1 + bins[j].rms_um * bins[j].rms_um * w2) / (w1 + w2));
      g.excess_um =
          std::sqrt((g.excess_um * g.excess_um * w1 + bins[j].excess_um * bins[j].excess_um * w2) /
                    (w1 + w2));
      g.p_value = std::min(g.p_value, bins[j].p_value);
      g.to = bins[j].to;
      g.n += bins[j].n;
      ++j;
    }
    // A region spanning its whole dimension says no more than the output's own entry.
    const bool whole = g.by != "output" && i == first_of[g.by + "/" + g.output] &&
                       j == end_of[g.by + "/" + g.output] && j - i > 1;
    if (!whole) out.push_back(g);
    i = j;
  }
  // A region holding every held-out residual of its output repeats the output's entry.
  std::map<std::string, std::size_t> per_output_n;
  for (const GapRegion& g : out)
    if (g.by == "output") per_output_n[g.output] = g.n;
  out.erase(std::remove_if(out.begin(), out.end(),
                           [&](const GapRegion& g) {
                             return g.by != "output" && g.n == per_output_n[g.output];
                           }),
            out.end());
  std::stable_sort(out.begin(), out.end(), [](const GapRegion& a, const GapRegion& b) {
    if (a.significant != b.significant) return a.significant;
    return a.excess_um > b.excess_um;
  });
  return out;
}

}  // namespace

// ---- Diagnosis -----------------------------------------------------------------------------

const std::vector<std::string>& gap_effect_names() {
  static const std::vector<std::string> names = {"thermal_drift", "reversal",     "periodic",
                                                 "pdge_shape",    "higher_order", "missing_error",
                                                 "tool_offset",   "setup"};
  return names;
}

GapDiagnosis::GapDiagnosis(std::shared_ptr<const Model> model, const ErrorParameterisation& param,
                           GapOptions options)
    : model_(std::move(model)), param_(param), options_(std::move(options)) {}

namespace {

// Evaluates one candidate (all variants; the variant chosen by training SSE over the splits)
// against the engine's current model.
struct Evaluated {
  EffectFit fit;
  gap_detail::Variant variant;  // the chosen (possibly refined) variant
  MatrixXd columns;             // full-data columns of the chosen variant (for acceptance)
  VectorXd heldout;             // held-out residual after
  VectorXd coef;                // full-data coefficients of the columns
  double heldout_sse = INFINITY;
};

// Least-squares coefficients of columns Eperp (already projected off the model's span) for the
// residual r; empty when the model spans them. The rank is decided on columns scaled by their
// norm before projection (`norm`): columns (nearly) inside the span would otherwise get huge
// coefficients from rounding.
std::optional<VectorXd> projected_fit(const MatrixXd& Eperp, VectorXd norm, const VectorXd& r) {
  for (Index k = 0; k < norm.size(); ++k)
    if (!(norm[k] > 0)) norm[k] = 1;
  const MatrixXd Es = Eperp * norm.cwiseInverse().asDiagonal();
  Eigen::ColPivHouseholderQR<MatrixXd> qr(Es);
  qr.setThreshold(1e-6);
  if (qr.rank() == 0) return std::nullopt;
  return VectorXd(norm.cwiseInverse().asDiagonal() * qr.solve(r));
}

// The columns of a θ-dependent variant for the fit `ff` on rows `train`: at the fit's θ, then
// (Variant::theta_iterations) at the θ of the joint fit [A E] with those columns.
MatrixXd theta_columns(const gap_detail::Candidate& c, const gap_detail::Variant& v,
                       const FoldFit& ff, const std::vector<std::size_t>& train, std::size_t np) {
  MatrixXd E = c.columns(v, split_theta(ff.theta, np));
  for (int it = 0; it < v.theta_iterations; ++it) {
    const MatrixXd Etr = rows_of(E, train);
    const MatrixXd P = ff.U.transpose() * Etr;
    const auto coef = projected_fit(Etr - ff.U * P, Etr.colwise().norm().transpose(), ff.res_train);
    if (!coef) break;
    E = c.columns(v, split_theta(VectorXd(ff.theta - ff.VS * (P * *coef)), np));
  }
  return E;
}

Evaluated evaluate(const gap_detail::Candidate& c, const Engine& e, std::size_t np,
                   const VectorXd& base_r, const VectorXd& base_h, double s2, double alpha,
                   double n_candidates) {
  Evaluated best;
  double best_train = INFINITY;
  // Training SSE over the splits and the held-out residual of one variant; false when the
  // model already spans its columns.
  auto score = [&](const gap_detail::Variant& v, double& train_sse, VectorXd& after,
                   MatrixXd& shared) {
    train_sse = 0;
    after = VectorXd::Constant(e.y.size(), kNaN);
    if (!v.needs_theta) shared = c.columns(v, {});
    for (std::size_t f = 0; f < e.splits.size(); ++f) {
      const Split& s = e.splits[f];
      const FoldFit& ff = e.folds[f];
      const MatrixXd E = v.needs_theta ? theta_columns(c, v, ff, s.train, np) : shared;
      const MatrixXd Etr = rows_of(E, s.train), Ete = rows_of(E, s.test);
      const MatrixXd P = ff.U.transpose() * Etr;
      const MatrixXd Eperp = Etr - ff.U * P;
      const auto fitted = projected_fit(Eperp, Etr.colwise().norm().transpose(), ff.res_train);
      if (!fitted) return false;  // the model already spans these columns
      const VectorXd& coef = *fitted;
      train_sse += (ff.res_train - Eperp * coef).squaredNorm();
      const VectorXd delta = (Ete - ff.W * P) * coef;
      for (std::size_t i = 0; i < s.test.size(); ++i)
        after[static_cast<Index>(s.test[i])] =
            ff.res_test[static_cast<Index>(i)] - delta[static_cast<Index>(i)];
    }
    return true;
  };
  MatrixXd best_shared;
  for (const gap_detail::Variant& v : c.variants) {
    double train_sse = 0;
    VectorXd after;
    MatrixXd shared;
    if (!score(v, train_sse, after, shared) || !(train_sse < best_train)) continue;
    best_train = train_sse;
    best.variant = v;
    best.heldout = after;
    best_shared = shared;
  }
  // Continuous hyper-parameters (a period, a lag, a bump's centre and width) are refined between
  // their grid neighbours by golden section on the training SSE, one after the other, twice; the
  // p-value keeps the grid's multiplicity.
  if (std::isfinite(best_train) && !best.variant.refine.empty()) {
    gap_detail::Variant v = best.variant;
    auto sse_at = [&](std::size_t k, double x) {
      gap_detail::Variant t = v;
      t.hyper[k] = x;
      double sse = INFINITY;
      VectorXd after;
      MatrixXd shared;
      if (!score(t, sse, after, shared)) return static_cast<double>(INFINITY);
      return sse;
    };
    const double g = (std::sqrt(5.0) - 1) / 2;
    for (int pass = 0; pass < 2; ++pass)
      for (const auto& r : v.refine) {
        double lo = r.lo, hi = r.hi;
        double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
        double f1 = sse_at(r.index, x1), f2 = sse_at(r.index, x2);
        for (int it = 0; it < 30 && hi - lo > 1e-6 * std::abs(hi); ++it) {
          if (f1 < f2) {
            hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = sse_at(r.index, x1);
          } else {
            lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = sse_at(r.index, x2);
          }
        }
        const double x = f1 < f2 ? x1 : x2;
        if (std::min(f1, f2) < sse_at(r.index, v.hyper[r.index])) v.hyper[r.index] = x;
      }
    double sse = INFINITY;
    VectorXd after;
    MatrixXd shared;
    if (score(v, sse, after, shared) && sse < best_train) {
      best_train = sse;
      best.variant = v;
      best.heldout = after;
      best_shared = shared;
    }
  }
  if (std::isfinite(best_train)) {
    best.fit.variant = best.variant.label;
    best.columns = best.variant.needs_theta
                       ? theta_columns(c, best.variant, e.full,
                                       all_rows(static_cast<std::size_t>(e.y.size())).train, np)
                       : best_shared;
    best.fit.tested_variants = static_cast<double>(c.variants.size());
  }
  best.fit.name = c.name;
  if (!std::isfinite(best_train)) return best;
  // Held-out before/after.
  Gap before, afterg;
  std::array<double, kObservationKinds> sb{}, sa{};
  std::array<std::size_t, kObservationKinds> n{};
  const auto& obs = e.data.points.observations;
  best.heldout_sse = 0;
  for (Index i = 0; i < e.y.size(); ++i) {
    if (!std::isfinite(best.heldout[i])) continue;
    const auto o = static_cast<std::size_t>(obs[static_cast<std::size_t>(i)].output);
    sb[o] += base_r[i] * base_r[i];
    sa[o] += best.heldout[i] * best.heldout[i];
    ++n[o];
    before.ss += base_r[i] * base_r[i];
    afterg.ss += best.heldout[i] * best.heldout[i];
    before.expected += s2 * (1 + base_h[i]);
    ++before.n;
  }
  best.heldout_sse = afterg.ss;
  for (std::size_t o = 0; o < kObservationKinds; ++o) {
    best.fit.rms_before[o] = n[o] ? std::sqrt(sb[o] / static_cast<double>(n[o])) : kNaN;
    best.fit.rms_after[o] = n[o] ? std::sqrt(sa[o] / static_cast<double>(n[o])) : kNaN;
  }
  const double nn = static_cast<double>(before.n);
  best.fit.heldout_rms_before_um = std::sqrt(before.ss / nn);
  best.fit.heldout_rms_after_um = std::sqrt(afterg.ss / nn);
  best.fit.shrink_pct = 100 * (1 - best.fit.heldout_rms_after_um / best.fit.heldout_rms_before_um);
  const double excess_before = std::max(0.0, before.ss - before.expected);
  // Of the excess over the floor; of the whole held-out SS when the floor already exceeds it.
  const double denominator = excess_before > 0 ? excess_before : before.ss;
  best.fit.explained_fraction =
      denominator > 0 ? std::clamp((before.ss - afterg.ss) / denominator, 0.0, 1.0) : 0;
  // Nested-model F test on all data, corrected for variants and candidates.
  const MatrixXd& E = best.columns;
  MatrixXd AE(e.A.rows(), e.A.cols() + E.cols());
  AE << e.A, E;
  const FoldFit f1 = fit_fold(AE, e.y, all_rows(static_cast<std::size_t>(e.y.size())));
  const double q = static_cast<double>(f1.rank) - static_cast<double>(e.full_rank);
  const double sse1 = f1.res_train.squaredNorm();
  const double d2 = static_cast<double>(e.y.size()) - static_cast<double>(f1.rank);
  best.fit.extra_parameters = static_cast<std::size_t>(std::max(0.0, q));
  if (q > 0 && d2 > 0) {
    best.fit.f_statistic = ((e.full_sse - sse1) / q) / (sse1 / d2);
    best.fit.p_value =
        std::min(1.0, f_sf(best.fit.f_statistic, q, d2) * best.fit.tested_variants * n_candidates);
  }
  // Held-out improvement must also beat chance: the drop in held-out SS against the floor.
  const double heldout_gain = (before.ss - afterg.ss) / s2;
  best.fit.significant = best.fit.p_value < alpha && heldout_gain > 0;
  best.coef = f1.theta.tail(E.cols());  // full-data coefficients, for the description
  return best;
}

// The shape degrees of freedom the data leave along coordinate `axis` in `output` beyond the
// baseline design A0 (rank rank0): the rank that one free value per distinct position adds.
std::size_t shape_dof_free(const MatrixXd& A0, std::size_t rank0, const GapData& d, int axis,
                           int output) {
  const auto& obs = d.points.observations;
  std::vector<double> levels;
  for (const auto& o : obs)
    if (observation_weight(o, output) != 0)
      levels.push_back(d.points.poses[o.row][static_cast<std::size_t>(axis)]);
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  MatrixXd AG = MatrixXd::Zero(A0.rows(), A0.cols() + static_cast<Index>(levels.size()));
  AG.leftCols(A0.cols()) = A0;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const double w = observation_weight(obs[i], output);
    if (w == 0) continue;
    const double q = d.points.poses[obs[i].row][static_cast<std::size_t>(axis)];
    const auto l = std::lower_bound(levels.begin(), levels.end(), q) - levels.begin();
    AG(static_cast<Index>(i), A0.cols() + l) = w;
  }
  const std::size_t r = EquilibratedSvd(AG, 1e-9, /*full_v=*/false).rank();
  return r > rank0 ? r - rank0 : 0;
}

std::string pct(double fraction) {
  char b[32];
  std::snprintf(b, sizeof b, "%.0f %%", 100 * fraction);
  return b;
}

// The verdict and its reason from the greedy explanation (docs/gap.md, "Verdict"). `shape` holds
// each accepted effect's (coordinate, output) when it is a shape along a coordinate.
void decide_verdict(GapResult& R, const GapOptions& opt, const std::vector<std::string>& axes,
                    bool gap_significant, double explained,
                    const std::vector<std::pair<int, int>>& shape) {
  auto unexplained = [&](std::string why) {
    R.verdict = "unexplained";
    R.verdict_reason = std::move(why);
  };
  if (R.explanation.empty()) {
    if (gap_significant)
      unexplained("a significant held-out gap that no candidate of the library removes");
    else
      R.verdict = "none", R.verdict_reason = "the held-out gap is at the noise floor";
    return;
  }
  const EffectFit& first = R.explanation.front();
  for (std::size_t k = 0; k < R.explanation.size(); ++k) {
    const EffectFit& f = R.explanation[k];
    if (f.distinguishable || (k > 0 && shape[k] != shape[0])) continue;
    const std::string along = axes[static_cast<std::size_t>(shape[k].first)];
    const std::string out = observation_name(static_cast<std::size_t>(shape[k].second));
    return unexplained(f.name + " along " + along + " in " + out + " fits, but " +
                       f.indistinct_reason);
  }
  if (shape[0].first >= 0 && first.explained_fraction < opt.explain_fraction)
    for (std::size_t k = 1; k < R.explanation.size(); ++k)
      if (shape[k] == shape[0])
        return unexplained(first.name + " removes " + pct(first.explained_fraction) +
                           " of the excess and needs " + R.explanation[k].name +
                           " along the same coordinate and output: a shape outside the library");
  if (first.explained_fraction < 0.5)
    return unexplained("the first effect, " + first.name + ", removes only " +
                       pct(first.explained_fraction) + " of the excess held-out sum of squares");
  if (R.final_p_value < opt.alpha) {
    if (explained < opt.explain_fraction)
      return unexplained("the accepted effects remove " + pct(explained) +
                         " of the excess and leave a significant gap");
    if (R.final_rms_um > 2 * R.noise.sigma_um)
      return unexplained(
          "the accepted effects leave a significant held-out RMS of more than twice the noise "
          "floor");
  }
  R.verdict = first.name;
  R.verdict_reason =
      first.name + " removes " + pct(first.explained_fraction) +
      " of the excess held-out sum of squares" +
      (R.explanation.size() > 1 ? ", the accepted effects " + pct(explained) : "") +
      (R.final_p_value >= opt.alpha ? "; the remaining gap is at the noise floor" : "");
}

}  // namespace

void GapDiagnosis::run(const GapData& data, const HoldoutScheme& scheme,
                       const std::string& reason) {
  GapResult R;
  R.holdout = scheme.str();
  R.holdout_reason = reason;
  const auto& obs = data.points.observations;
  R.observations = obs.size();
  R.count = data.points.count;
  R.parameters = param_.size();

  Engine e{data, design_matrix(*model_, param_, data.points), {}, {}, {}, 0, 0, {}};
  e.y.resize(static_cast<Index>(obs.size()));
  for (std::size_t i = 0; i < obs.size(); ++i) e.y[static_cast<Index>(i)] = obs[i].value;
  e.fit_full();
  R.rank = e.full_rank;
  e.splits = make_splits(data, scheme, R.rank + 5);
  if (scheme.kind != HoldoutScheme::Kind::Forward) {  // the folds actually used (K <= groups)
    HoldoutScheme used = scheme;
    used.folds = static_cast<int>(e.splits.size());
    R.holdout = used.str();
  }
  e.fit_folds();
  VectorXd r, h;
  e.heldout(r, h);
  R.noise = noise_floor(data, r);
  const double s2 = R.noise.sigma_um * R.noise.sigma_um;

  auto summarise = [&](const VectorXd& res, std::array<double, kObservationKinds>& rms,
                       double& total, std::array<double, kObservationKinds>* mx) {
    std::array<double, kObservationKinds> ss{};
    std::array<std::size_t, kObservationKinds> n{};
    double all = 0;
    std::size_t na = 0;
    if (mx) mx->fill(0);
    for (std::size_t i = 0; i < obs.size(); ++i) {
      const double v = res[static_cast<Index>(i)];
      if (!std::isfinite(v)) continue;
      const auto o = static_cast<std::size_t>(obs[i].output);
      ss[o] += v * v, ++n[o], all += v * v, ++na;
      if (mx) (*mx)[o] = std::max((*mx)[o], std::abs(v));
    }
    for (std::size_t o = 0; o < kObservationKinds; ++o) {
      rms[o] = n[o] ? std::sqrt(ss[o] / static_cast<double>(n[o])) : kNaN;
      if (mx && !n[o]) (*mx)[o] = kNaN;
    }
    total = na ? std::sqrt(all / static_cast<double>(na)) : kNaN;
  };
  // Σ r² and its expectation σ²(1 + h) over the held-out residuals.
  auto held_gap = [&](const VectorXd& res, const VectorXd& lev) {
    Gap g;
    for (Index i = 0; i < res.size(); ++i)
      if (std::isfinite(res[i])) g.ss += res[i] * res[i], g.expected += s2 * (1 + lev[i]), ++g.n;
    return g;
  };
  summarise(r, R.baseline_rms, R.baseline_rms_um, &R.baseline_max);
  const Gap base = held_gap(r, h);
  gap_stats(base, R.noise.dof, R.baseline_excess_um, R.baseline_p_value);
  R.where = localise(data, r, h, R.noise, options_.alpha);
  R.residual_before.assign(r.data(), r.data() + r.size());

  gap_detail::EffectContext ctx;
  ctx.data = &data;
  ctx.model = model_.get();
  ctx.param = &param_;
  auto chain = std::make_shared<NumericChain>(model_->description());
  chain->set_parameters(model_->parameters());
  ctx.chain = chain;
  const std::vector<std::string>& names =
      options_.effects.empty() ? gap_effect_names() : options_.effects;
  std::vector<gap_detail::Candidate> candidates = gap_detail::effect_candidates(ctx, names);
  const double n_candidates = static_cast<double>(std::max<std::size_t>(1, candidates.size()));

  const bool gap_significant = R.baseline_p_value < options_.alpha;
  VectorXd cur_r = r, cur_h = h;
  std::vector<bool> used(candidates.size(), false);
  // Shape effects: free shape dof per (coordinate, output), and the dof the accepted ones use.
  const MatrixXd A0 = e.A;
  const std::size_t rank0 = e.full_rank;
  std::map<std::pair<int, int>, std::size_t> dof_free, dof_used;
  std::vector<std::pair<int, int>> accepted_shape;  // per accepted effect; (-1, -1) if none
  auto check_shape = [&](const gap_detail::Variant& v, EffectFit& fit) {
    if (v.shape_axis < 0) return;
    const std::pair<int, int> key{v.shape_axis, v.shape_output};
    if (!dof_free.count(key))
      dof_free[key] = shape_dof_free(A0, rank0, data, v.shape_axis, v.shape_output);
    fit.shape_dof_free = dof_free[key];
    fit.shape_dof_used = dof_used[key] + fit.extra_parameters + v.refine.size();
    if (fit.shape_dof_used >= fit.shape_dof_free) {
      const std::string along = data.axes[static_cast<std::size_t>(v.shape_axis)];
      fit.distinguishable = false;
      fit.indistinct_reason =
          "the data leave " + std::to_string(fit.shape_dof_free) +
          " shape degrees of freedom along " + along + " beyond the model and the fitted shape" +
          (dof_used[key] ? "s use " : " uses ") + std::to_string(fit.shape_dof_used) +
          ": any shape would fit as well (a step, a bump, a period); measure "
          "more positions along " +
          along;
    }
  };
  for (int step = 0; step < options_.max_effects; ++step) {
    std::vector<Evaluated> ev;
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      if (used[k]) continue;
      Evaluated x =
          evaluate(candidates[k], e, param_.size(), cur_r, cur_h, s2, options_.alpha, n_candidates);
      if (!std::isfinite(x.heldout_sse)) continue;
      candidates[k].describe(x.variant, x.coef, x.fit);
      check_shape(x.variant, x.fit);
      ev.push_back(std::move(x));
      ev.back().fit.name = candidates[k].name;
    }
    std::stable_sort(ev.begin(), ev.end(), [](const Evaluated& a, const Evaluated& b) {
      return a.heldout_sse < b.heldout_sse;
    });
    if (step == 0)
      for (const Evaluated& x : ev) R.effects.push_back(x.fit);
    const Evaluated* pick = nullptr;
    for (const Evaluated& x : ev)
      if (x.fit.significant) {
        pick = &x;
        break;
      }
    // A significant effect is evidence of a gap by itself: a floor from repeats that straddle a
    // drift can be inflated enough to hide the gap from the floor test.
    if (!pick) break;
    // Accept: its columns join the model.
    EffectFit fit = pick->fit;
    MatrixXd AE(e.A.rows(), e.A.cols() + pick->columns.cols());
    AE << e.A, pick->columns;
    e.A = AE;
    e.refit();
    e.heldout(cur_r, cur_h);
    R.explanation.push_back(fit);
    if (pick->variant.shape_axis >= 0) {
      accepted_shape.emplace_back(pick->variant.shape_axis, pick->variant.shape_output);
      dof_used[accepted_shape.back()] = fit.shape_dof_used;
    } else {
      accepted_shape.emplace_back(-1, -1);
    }
    // Thermal drift may need a second sensor or lag; other effects are taken once.
    for (std::size_t k = 0; k < candidates.size(); ++k)
      if (candidates[k].name == fit.name && fit.name != "thermal_drift") used[k] = true;
    double ex = 0, p = 1;
    gap_stats(held_gap(cur_r, cur_h), R.noise.dof, ex, p);
    if (p >= options_.alpha) break;
  }
  summarise(cur_r, R.final_rms, R.final_rms_um, nullptr);
  const Gap final_gap = held_gap(cur_r, cur_h);
  gap_stats(final_gap, R.noise.dof, R.final_excess_um, R.final_p_value);
  R.residual_after.assign(cur_r.data(), cur_r.data() + cur_r.size());
  // Of the excess over the floor (of the whole held-out SS when the floor exceeds it).
  const double explained_ss = base.ss - final_gap.ss;
  const double excess_ss = std::max(0.0, base.ss - base.expected);
  const double explained =
      excess_ss > 0 ? explained_ss / excess_ss : (base.ss > 0 ? explained_ss / base.ss : 0);
  decide_verdict(R, options_, data.axes, gap_significant, explained, accepted_shape);
  result_ = std::move(R);
}

}  // namespace weilgen
