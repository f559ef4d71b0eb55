#include "weilgen/measure/pdge_fit.hpp"

#include <algorithm>
#include <boost/math/tools/minima.hpp>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>

#include "weilgen/base/constants.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/uq/dense.hpp"

namespace weilgen {
namespace {

using Rows = std::vector<std::size_t>;

Rows all_rows(std::size_t n) {
  Rows r(n);
  for (std::size_t i = 0; i < n; ++i) r[i] = i;
  return r;
}

std::size_t distinct_in(const std::vector<double>& x, const Rows& rows) {
  std::vector<double> v;
  v.reserve(rows.size());
  for (std::size_t i : rows) v.push_back(x[i]);
  return distinct_count(v);
}

// The least-squares solution on `rows`; error non-empty when the data cannot support the basis.
struct Solved {
  std::string error;
  Eigen::VectorXd coef;
  std::size_t rank = 0;
  double condition = NAN;
  std::vector<double> unscaled_var;  // diag (XᵀX)⁻¹ in coefficient order (when asked)
};

Solved solve_rows(const Basis& basis, const std::vector<double>& x, const std::vector<double>& y,
                  const Rows& rows, double tolerance, bool with_variance) {
  Solved s;
  const std::size_t p = basis.size(), n = rows.size();
  const std::size_t distinct = distinct_in(x, rows);
  if (distinct < p) {
    const int max_order = max_order_for_points(basis.kind, distinct);
    s.error = basis.name() + " has " + std::to_string(p) + " coefficient" + (p == 1 ? "" : "s") +
              " but the data has " + std::to_string(distinct) + " distinct position" +
              (distinct == 1 ? "" : "s") + ": the data cannot support this order" +
              (max_order >= 0 ? " (use order <= " + std::to_string(max_order) + ")" : "");
    return s;
  }
  Eigen::MatrixXd X(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(p));
  Eigen::VectorXd Y(static_cast<Eigen::Index>(n));
  std::vector<double> t(p);
  for (std::size_t i = 0; i < n; ++i) {
    basis.evaluate(x[rows[i]], t.data());
    for (std::size_t k = 0; k < p; ++k)
      X(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k)) = t[k];
    Y(static_cast<Eigen::Index>(i)) = y[rows[i]];
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(X.rows(), X.cols());
  qr.setThreshold(tolerance);
  qr.compute(X);
  s.rank = static_cast<std::size_t>(qr.rank());
  const auto pi = static_cast<Eigen::Index>(p);
  const Eigen::MatrixXd R = qr.matrixR().topLeftCorner(pi, pi).triangularView<Eigen::Upper>();
  s.condition = std::abs(R(0, 0)) / std::abs(R(pi - 1, pi - 1));
  if (s.rank < p) {
    s.error = basis.name() + " has " + std::to_string(p) +
              " coefficients but its design matrix has numerical rank " + std::to_string(s.rank) +
              " (relative tolerance " + format_short(tolerance, 3) +
              "): the data cannot support this order" +
              (basis.kind == BasisKind::Fourier ? " (positions too few or aliased at period " +
                                                      format_short(basis.period(), 6) + " mm)"
                                                : "");
    return s;
  }
  s.coef = qr.solve(Y);
  if (with_variance) {
    const Eigen::MatrixXd Rinv =
        R.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(pi, pi));
    s.unscaled_var.assign(p, NAN);
    const auto& perm = qr.colsPermutation().indices();
    for (Eigen::Index j = 0; j < pi; ++j)
      s.unscaled_var[static_cast<std::size_t>(perm(j))] = Rinv.row(j).squaredNorm();
  }
  return s;
}

// A basis for a training subset (fixed, or with its period searched on the subset).
using BasisFor = std::function<Basis(const std::vector<double>& x, const std::vector<double>& y)>;

// Cross-validation; error set (and NaN score) when some training fold cannot support the basis.
CvScore cross_validate(const std::vector<double>& x, const std::vector<double>& y,
                       const std::vector<int>& folds, const BasisFor& basis_for, double tolerance,
                       std::string& error) {
  CvScore score;
  const int K = folds.empty() ? 0 : *std::max_element(folds.begin(), folds.end()) + 1;
  double total = 0;
  std::size_t total_n = 0;
  for (int k = 0; k < K; ++k) {
    std::vector<double> xt, yt;
    Rows test;
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (folds[i] == k) {
        test.push_back(i);
      } else {
        xt.push_back(x[i]);
        yt.push_back(y[i]);
      }
    }
    if (test.empty()) continue;
    Basis basis;
    try {
      basis = basis_for(xt, yt);
    } catch (const std::invalid_argument& e) {
      error = "fold " + std::to_string(k + 1) + ": " + e.what();
      return CvScore{};
    }
    const Solved s = solve_rows(basis, xt, yt, all_rows(xt.size()), tolerance, false);
    if (!s.error.empty()) {
      error = "fold " + std::to_string(k + 1) + " (trained without " + std::to_string(test.size()) +
              " rows): " + s.error;
      return CvScore{};
    }
    double fold_sum = 0;
    for (std::size_t i : test) {
      const double r = y[i] - basis.value(s.coef.data(), x[i]);
      fold_sum += r * r;
    }
    total += fold_sum;
    total_n += test.size();
    score.fold_mse.push_back(fold_sum / static_cast<double>(test.size()));
  }
  const double Kd = static_cast<double>(score.fold_mse.size());
  if (Kd < 2) {
    error = "fewer than two non-empty folds";
    return CvScore{};
  }
  score.mse = total / static_cast<double>(total_n);
  score.rmse = std::sqrt(score.mse);
  double mean = 0, var = 0;
  for (double m : score.fold_mse) mean += m / Kd;
  for (double m : score.fold_mse) var += (m - mean) * (m - mean) / (Kd - 1);
  score.mse_se = std::sqrt(var / Kd);
  return score;
}

}  // namespace

const char* cv_scheme_name(CvScheme s) { return s == CvScheme::Blocks ? "blocks" : "cycles"; }
const char* order_rule_name(OrderRule r) {
  return r == OrderRule::OneStandardError ? "1se" : "min";
}

std::size_t distinct_count(const std::vector<double>& x) {
  std::vector<double> v(x);
  std::sort(v.begin(), v.end());
  return static_cast<std::size_t>(std::unique(v.begin(), v.end()) - v.begin());
}

double median_spacing(const std::vector<double>& x) {
  std::vector<double> v(x);
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  if (v.size() < 2) return NAN;
  std::vector<double> d(v.size() - 1);
  for (std::size_t i = 0; i + 1 < v.size(); ++i) d[i] = v[i + 1] - v[i];
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
  return d[d.size() / 2];
}

FitMetrics fit_metrics(const std::vector<double>& y, const std::vector<double>& fitted) {
  if (y.size() != fitted.size() || y.empty()) {
    throw std::invalid_argument("fit metrics: " + std::to_string(y.size()) + " values and " +
                                std::to_string(fitted.size()) + " fitted values");
  }
  FitMetrics m;
  m.n = y.size();
  const double n = static_cast<double>(m.n);
  double mean = 0;
  for (double v : y) mean += v / n;
  double sse = 0, sst = 0, emax = 0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double r = y[i] - fitted[i];
    sse += r * r;
    sst += (y[i] - mean) * (y[i] - mean);
    emax = std::max(emax, std::abs(r));
  }
  m.e_max = emax;
  m.sse = sse;
  m.rmse = std::sqrt(sse / n);
  m.r2 = sst > 0 ? 1 - sse / sst : NAN;
  return m;
}

FitResult LeastSquaresFit::run(const std::vector<double>& x, const std::vector<double>& y,
                               const Basis& basis) const {
  basis.validate();
  if (x.size() != y.size()) {
    throw std::invalid_argument("fit: " + std::to_string(x.size()) + " positions but " +
                                std::to_string(y.size()) + " values");
  }
  if (x.empty()) throw std::invalid_argument("fit " + basis.name() + ": no data");
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) {
      throw std::invalid_argument("fit: row " + std::to_string(i + 1) +
                                  " is not finite (drop missing values before fitting)");
    }
  }
  const Solved s = solve_rows(basis, x, y, all_rows(x.size()), options_.rank_tolerance, true);
  if (!s.error.empty()) throw std::invalid_argument(s.error);
  FitResult r;
  r.basis = basis;
  r.coefficients.assign(s.coef.data(), s.coef.data() + s.coef.size());
  r.rank = s.rank;
  r.condition = s.condition;
  r.fitted.resize(x.size());
  r.residuals.resize(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    r.fitted[i] = basis.value(r.coefficients.data(), x[i]);
    r.residuals[i] = y[i] - r.fitted[i];
  }
  r.metrics = fit_metrics(y, r.fitted);
  const std::size_t p = basis.size();
  r.std_errors.assign(p, NAN);
  if (x.size() > p) {
    r.sigma = std::sqrt(r.metrics.sse / static_cast<double>(x.size() - p));
    for (std::size_t k = 0; k < p; ++k) r.std_errors[k] = r.sigma * std::sqrt(s.unscaled_var[k]);
  }
  return r;
}

std::vector<int> cv_folds(const std::vector<double>& x, const std::vector<int>& cycles,
                          const CvOptions& options) {
  std::vector<int> folds(x.size(), 0);
  if (options.scheme == CvScheme::Cycles) {
    if (cycles.size() != x.size()) {
      throw std::invalid_argument(
          "leave-one-cycle-out cross-validation needs a cycle id per row (a `cycle` column)");
    }
    std::map<int, int> ids;
    for (int c : cycles) ids.emplace(c, 0);
    if (ids.size() < 2) {
      throw std::invalid_argument(
          "leave-one-cycle-out cross-validation needs at least two "
          "cycles; the data has " +
          std::to_string(ids.size()));
    }
    int k = 0;
    for (auto& [id, fold] : ids) fold = k++;
    for (std::size_t i = 0; i < x.size(); ++i) folds[i] = ids[cycles[i]];
    return folds;
  }
  if (options.folds < 2)
    throw std::invalid_argument("cross-validation needs at least 2 folds, not " +
                                std::to_string(options.folds));
  std::vector<double> v(x);
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  const auto K = static_cast<std::size_t>(options.folds);
  // Position j of the m candidates goes to fold floor(j K / m): contiguous, sizes differ by at
  // most one. With keep_ends the candidates are the m = distinct - 2 interior positions.
  const std::size_t skip = options.keep_ends ? 1 : 0;
  const std::size_t m = v.size() - 2 * skip;
  if (m < K) {
    throw std::invalid_argument(std::to_string(K) + "-fold cross-validation needs at least " +
                                std::to_string(K + 2 * skip) + " distinct positions" +
                                (skip ? " (the two end positions are never held out)" : "") +
                                "; the data has " + std::to_string(v.size()));
  }
  for (std::size_t i = 0; i < x.size(); ++i) {
    const auto j = static_cast<std::size_t>(std::lower_bound(v.begin(), v.end(), x[i]) - v.begin());
    if (j < skip || j >= skip + m)
      folds[i] = -1;
    else
      folds[i] = static_cast<int>((j - skip) * K / m);
  }
  return folds;
}

PeriodSearchResult PeriodSearch::run(const std::vector<double>& x, const std::vector<double>& y,
                                     int order, double a, double b,
                                     const std::vector<int>& folds) const {
  if (order < 1)
    throw std::invalid_argument("period search: a Fourier order >= 1 is needed, not " +
                                std::to_string(order));
  Basis::make(BasisKind::Fourier, order, a, b).validate();
  if (x.size() != y.size() || x.empty())
    throw std::invalid_argument(
        "period search: positions and values differ in number or are empty");
  if (options_.objective == PeriodObjective::Cv && folds.size() != x.size())
    throw std::invalid_argument("period search: the CV objective needs a fold per row");
  if (options_.oversampling < 1)
    throw std::invalid_argument("period search: oversampling must be >= 1");
  const double T = b - a;
  const double dx = median_spacing(x);
  const double lmin = std::isnan(options_.min_mm) ? 2 * order * dx : options_.min_mm;
  const double lmax = std::isnan(options_.max_mm) ? 2 * T : options_.max_mm;
  if (!(lmin > 0) || !(lmin < lmax)) {
    throw std::invalid_argument("period search: fourier:" + std::to_string(order) +
                                " needs a period range min < max, got [" + format_short(lmin, 6) +
                                ", " + format_short(lmax, 6) + "] mm" +
                                (std::isnan(options_.min_mm)
                                     ? " (min = 2 * order * spacing " + format_short(dx, 6) + " mm)"
                                     : ""));
  }
  const double flo = 1 / lmax, fhi = 1 / lmin;
  const double df = 1 / (options_.oversampling * order * T);
  const auto count =
      static_cast<std::size_t>(std::clamp(std::ceil((fhi - flo) / df) + 1, 16.0, 20000.0));

  PeriodSearchResult out;
  const Rows rows = all_rows(x.size());
  const double tol = least_squares_.rank_tolerance;
  auto objective = [&](double f) -> double {
    ++out.evaluations;
    const Basis basis = Basis::make(BasisKind::Fourier, order, a, b, 1 / f);
    if (options_.objective == PeriodObjective::Sse) {
      const Solved s = solve_rows(basis, x, y, rows, tol, false);
      if (!s.error.empty()) return kInf;
      double sse = 0;
      for (std::size_t i = 0; i < x.size(); ++i) {
        const double r = y[i] - basis.value(s.coef.data(), x[i]);
        sse += r * r;
      }
      return sse;
    }
    std::string error;
    const CvScore cv = cross_validate(
        x, y, folds, [&](const std::vector<double>&, const std::vector<double>&) { return basis; },
        tol, error);
    return error.empty() ? cv.mse : kInf;
  };

  std::vector<double> fgrid(count);
  std::size_t best = count;
  double best_value = kInf;
  for (std::size_t i = 0; i < count; ++i) {
    fgrid[i] = flo + (fhi - flo) * static_cast<double>(i) / static_cast<double>(count - 1);
    const double v = objective(fgrid[i]);
    out.grid_period_mm.push_back(1 / fgrid[i]);
    out.grid_objective.push_back(std::isfinite(v) ? v : NAN);
    if (v < best_value) best_value = v, best = i;
  }
  if (best == count) {
    throw std::invalid_argument(
        "period search: no period in [" + format_short(lmin, 6) + ", " + format_short(lmax, 6) +
        "] mm gives a full-rank fourier:" + std::to_string(order) + " fit of these positions");
  }
  const double lo = fgrid[best == 0 ? 0 : best - 1];
  const double hi = fgrid[std::min(best + 1, count - 1)];
  std::uintmax_t iterations = 100;
  const auto refined = boost::math::tools::brent_find_minima(
      objective, lo, hi, std::numeric_limits<double>::digits / 2, iterations);
  double f = fgrid[best];
  out.objective = best_value;
  if (refined.second < best_value) f = refined.first, out.objective = refined.second;
  out.period_mm = 1 / f;
  out.min_mm = lmin;
  out.max_mm = lmax;
  out.at_bound = std::abs(out.period_mm - lmin) <= 1e-6 * lmin ||
                 std::abs(out.period_mm - lmax) <= 1e-6 * lmax;
  out.fit = LeastSquaresFit(least_squares_)
                .run(x, y, Basis::make(BasisKind::Fourier, order, a, b, out.period_mm));
  return out;
}

void PdgeFitOptions::validate() const {
  if (min_order < 0 || max_order < min_order)
    throw std::invalid_argument("fit: order range " + std::to_string(min_order) + ".." +
                                std::to_string(max_order) + " is empty");
  if (cv.folds < 2) throw std::invalid_argument("fit: the CV needs at least 2 folds");
}

PdgeFit::PdgeFit(PdgeFitOptions options) : options_(std::move(options)) { options_.validate(); }

PdgeFitResult PdgeFit::run(const std::vector<double>& x, const std::vector<double>& y,
                           const std::vector<int>& cycles, const BasisSpec& spec, double a,
                           double b) const {
  const PdgeFitOptions& o = options_;
  Basis::make(spec.kind, 0, a, b).validate();
  if (x.size() != y.size())
    throw std::invalid_argument("fit: " + std::to_string(x.size()) + " positions but " +
                                std::to_string(y.size()) + " values");
  if (x.empty()) throw std::invalid_argument("fit " + spec.str() + ": no data");
  if (!cycles.empty() && cycles.size() != x.size())
    throw std::invalid_argument("fit: cycles must be empty or one per row");
  if (spec.auto_order() && (o.min_order < 0 || o.max_order < o.min_order)) {
    throw std::invalid_argument("fit: order range " + std::to_string(o.min_order) + ".." +
                                std::to_string(o.max_order) + " is empty");
  }
  const bool fourier = spec.kind == BasisKind::Fourier;

  PdgeFitResult result;
  result.spec = spec;
  result.order_choice = spec.auto_order() ? order_rule_name(o.rule) : "fixed";
  if (fourier)
    result.period_choice = spec.period_search           ? "search"
                           : std::isnan(spec.period_mm) ? "travel"
                                                        : "given";

  std::vector<int> folds;
  std::string fold_error;
  CvOptions cvo = o.cv;
  try {
    if (cvo.scheme == CvScheme::Blocks && cvo.folds >= 2) {
      const long distinct = static_cast<long>(distinct_count(x));
      const long candidates = distinct - (cvo.keep_ends ? 2 : 0);
      if (candidates < 2) {
        throw std::invalid_argument(
            "block cross-validation needs at least " + std::to_string(cvo.keep_ends ? 4 : 2) +
            " distinct positions" +
            (cvo.keep_ends ? " (two interior ones to hold out; the ends always train)" : "") +
            "; the data has " + std::to_string(distinct));
      }
      if (candidates < cvo.folds) cvo.folds = static_cast<int>(candidates);
    }
    folds = cv_folds(x, cycles, cvo);
    result.folds = *std::max_element(folds.begin(), folds.end()) + 1;
  } catch (const std::invalid_argument& e) {
    if (spec.auto_order())
      throw std::invalid_argument(std::string("choosing the order of ") + spec.str() + ": " +
                                  e.what() + " (give a fixed order, or cross-validate by cycles)");
    fold_error = e.what();
  }

  const LeastSquaresFit lsq(o.least_squares);
  PeriodSearchOptions inner = o.period_search;  // inside CV: SSE on the training fold
  inner.objective = PeriodObjective::Sse;
  const PeriodSearch outer_search(o.period_search, o.least_squares);
  const PeriodSearch inner_search(inner, o.least_squares);

  // The full-data fit of one order (throws std::invalid_argument when unsupported).
  std::map<int, bool> at_bound;  // order -> the searched period is an end of its range
  auto full_fit = [&](int order) -> FitResult {
    if (fourier && spec.period_search && order >= 1) {
      PeriodSearchResult r = outer_search.run(x, y, order, a, b, folds);
      at_bound[order] = r.at_bound;
      return std::move(r.fit);
    }
    return lsq.run(x, y, Basis::make(spec.kind, order, a, b, fourier ? spec.period_mm : NAN));
  };
  auto basis_for = [&](int order) -> BasisFor {
    if (fourier && spec.period_search && order >= 1) {
      return [&, order](const std::vector<double>& xt, const std::vector<double>& yt) {
        return inner_search.run(xt, yt, order, a, b).fit.basis;
      };
    }
    const Basis fixed = Basis::make(spec.kind, order, a, b, fourier ? spec.period_mm : NAN);
    return [fixed](const std::vector<double>&, const std::vector<double>&) { return fixed; };
  };

  const int lo = spec.auto_order() ? o.min_order : spec.order;
  const int hi = spec.auto_order() ? o.max_order : spec.order;
  std::vector<FitResult> fits;
  for (int order = lo; order <= hi; ++order) {
    CvCurvePoint pt;
    pt.order = order;
    pt.params = basis_size(spec.kind, order);
    FitResult fit;
    try {
      fit = full_fit(order);
    } catch (const std::invalid_argument& e) {
      if (!spec.auto_order()) throw;
      pt.reason = e.what();
      result.curve.push_back(pt);
      fits.emplace_back();
      continue;
    }
    pt.train_rmse = fit.metrics.rmse;
    if (fourier) pt.period_mm = fit.basis.period();
    std::string error = fold_error;
    if (error.empty())
      pt.cv = cross_validate(x, y, folds, basis_for(order), o.least_squares.rank_tolerance, error);
    pt.feasible = error.empty();
    pt.reason = error;
    result.curve.push_back(pt);
    fits.push_back(std::move(fit));
  }

  if (!spec.auto_order()) {
    result.period_at_bound = at_bound[spec.order];
    result.fit = std::move(fits.front());
    result.cv = result.curve.front().cv;
    result.cv_note = result.curve.front().reason;
    return result;
  }
  std::size_t best = result.curve.size();
  for (std::size_t i = 0; i < result.curve.size(); ++i) {
    const auto& c = result.curve[i];
    if (c.feasible && (best == result.curve.size() || c.cv.mse < result.curve[best].cv.mse))
      best = i;
  }
  if (best == result.curve.size()) {
    std::string why = result.curve.empty() ? "" : result.curve.front().reason;
    throw std::invalid_argument("choosing the order of " + spec.str() + ": no order in " +
                                std::to_string(lo) + ".." + std::to_string(hi) +
                                " can be cross-validated on this data (order " +
                                std::to_string(lo) + ": " + why + ")");
  }
  result.min_cv_order = result.curve[best].order;
  std::size_t chosen = best;
  if (o.rule == OrderRule::OneStandardError) {
    const double threshold = result.curve[best].cv.mse + result.curve[best].cv.mse_se;
    for (std::size_t i = 0; i < best; ++i) {
      if (result.curve[i].feasible && result.curve[i].cv.mse <= threshold) {
        chosen = i;
        break;
      }
    }
  }
  result.period_at_bound = at_bound[result.curve[chosen].order];
  result.fit = std::move(fits[chosen]);
  result.cv = result.curve[chosen].cv;
  return result;
}

}  // namespace weilgen
