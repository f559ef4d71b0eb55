// The thermal-drift elimination of Stejskal et al. 2017 (eqs. (4)-(10)): adjacent-position
// differences, the deviation chart rebuilt from a reference position and cycle, the anomaly test
// on the differences' spreads, and the drift per cycle. docs/iso230-2.md, "Drift elimination".
#include <algorithm>
#include <iterator>
#include <stdexcept>
#include <tuple>

#include "weilgen/base/constants.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/measure/iso230_2.hpp"
#include "weilgen/uq/test_statistics.hpp"

namespace weilgen {

namespace {

// Within-group least-squares slope of y against u (one intercept per group) and its standard
// error. groups[g] = {(u, y)...}.
std::pair<double, double> within_slope(
    const std::vector<std::vector<std::pair<double, double>>>& g) {
  double suy = 0, suu = 0;
  std::size_t n = 0, groups = 0;
  std::vector<std::pair<double, double>> centre;
  for (const auto& grp : g) {
    double mu = 0, my = 0;
    for (const auto& [u, y] : grp) mu += u, my += y;
    mu /= static_cast<double>(grp.size());
    my /= static_cast<double>(grp.size());
    centre.emplace_back(mu, my);
    for (const auto& [u, y] : grp) suy += (u - mu) * (y - my), suu += (u - mu) * (u - mu);
    n += grp.size();
    ++groups;
  }
  if (!(suu > 0)) return {kNaN, kNaN};
  const double slope = suy / suu;
  double rss = 0;
  for (std::size_t k = 0; k < g.size(); ++k)
    for (const auto& [u, y] : g[k]) {
      const double r = y - centre[k].second - slope * (u - centre[k].first);
      rss += r * r;
    }
  const double dof = static_cast<double>(n) - static_cast<double>(groups) - 1;
  return {slope, dof > 0 ? std::sqrt(rss / dof / suu) : kNaN};
}

// The reference target (the one nearest --reference-position, else the first) and cycle
// (--reference-cycle, else the lowest cycle id measured in both directions) into `res`; returns
// the reference cycle's column in each direction.
std::array<std::size_t, 2> drift_reference(const IsoRuns& R, const DriftOptions& options,
                                           DriftResult& res) {
  const std::size_t m = R.targets();
  if (options.reference_position_mm) {
    const double p = *options.reference_position_mm;
    std::size_t best = 0;
    for (std::size_t i = 1; i < m; ++i)
      if (std::abs(R.positions_mm[i] - p) < std::abs(R.positions_mm[best] - p)) best = i;
    if (!(std::abs(R.positions_mm[best] - p) <= options.tolerance_mm)) {
      std::string list;
      for (double v : R.positions_mm) list += (list.empty() ? "" : ", ") + format_number(v);
      throw std::invalid_argument("--reference-position " + format_number(p) +
                                  ": not a target (targets: " + list + " mm)");
    }
    res.reference_target = best;
  }
  if (options.reference_cycle) {
    res.reference_cycle = *options.reference_cycle;
  } else {  // the lowest cycle id measured in both directions
    std::vector<long> common;
    std::set_intersection(R.cycles[kUp].begin(), R.cycles[kUp].end(), R.cycles[kDown].begin(),
                          R.cycles[kDown].end(), std::back_inserter(common));
    if (common.empty())
      throw InputError(SourceLoc{R.file, 0, 0},
                       "the two directions share no cycle id: the drift elimination needs a "
                       "reference cycle measured in both directions");
    res.reference_cycle = common.front();
  }
  std::array<std::size_t, 2> j0{};
  for (int d = 0; d < 2; ++d) {
    const auto& c = R.cycles[d];
    const auto it = std::find(c.begin(), c.end(), res.reference_cycle);
    if (it == c.end())
      throw std::invalid_argument("--reference-cycle " + std::to_string(res.reference_cycle) +
                                  ": not a cycle of direction " + (d == kUp ? "+1" : "-1") +
                                  " (cycles " + std::to_string(c.front()) + " to " +
                                  std::to_string(c.back()) + ")");
    j0[d] = static_cast<std::size_t>(it - c.begin());
  }

  return j0;
}

// Adjacent-position differences per direction and each difference's F statistic against the
// pooled spread of the other differences of the same parity (they share no target with it).
void adjacent_differences(const IsoRuns& R, DriftResult& res) {
  const std::size_t m = R.targets();
  for (int d = 0; d < 2; ++d) {
    const std::size_t n = R.cycles[d].size();
    AdjacentDifferences& D = res.differences[d];
    D = {};
    for (std::size_t k = 1; k < m; ++k) {
      std::vector<double> diff(n);
      for (std::size_t j = 0; j < n; ++j) diff[j] = R.x[d][k][j] - R.x[d][k - 1][j];
      D.mean.push_back(sample_mean(diff));
      D.s.push_back(sample_sd(diff));
      D.sem.push_back(D.s.back() / std::sqrt(static_cast<double>(n)));
    }
    const double nu1 = static_cast<double>(n - 1);
    for (std::size_t k = 0; k + 1 < m; ++k) {
      double pooled = 0;
      int p = 0;
      for (std::size_t l = k % 2; l + 1 < m; l += 2)
        if (l != k) pooled += D.s[l] * D.s[l], ++p;
      D.pool.push_back(p);
      if (p == 0) {
        D.F.push_back(kNaN);
        D.p_value.push_back(kNaN);
        continue;
      }
      pooled /= p;
      const double num = D.s[k] * D.s[k];
      double F = kNaN, pv = 1.0;
      if (pooled > 0) {
        F = num / pooled;
        pv = fisher_f_sf(F, nu1, nu1 * p);
      } else if (num > 0) {
        F = INFINITY;
        pv = 0.0;
      }
      D.F.push_back(F);
      D.p_value.push_back(pv);
      ++res.tests;
    }
  }
}

// Flags (Bonferroni over every test of both directions) and their attribution to targets.
void flag_anomalies(std::size_t m, double alpha, DriftResult& res) {
  const double threshold = res.tests > 0 ? alpha / static_cast<double>(res.tests) : 0;
  for (int d = 0; d < 2; ++d) {
    AdjacentDifferences& D = res.differences[d];
    const int dir = d == kUp ? +1 : -1;
    for (std::size_t k = 0; k + 1 < m; ++k) {
      const bool flag = std::isfinite(D.p_value[k]) && D.p_value[k] < threshold;
      D.flagged.push_back(flag);
      if (flag) res.anomalous_differences.push_back({dir, k, k + 1, D.s[k], D.F[k], D.p_value[k]});
    }
    // Difference k joins targets k and k+1 (0-based, k = 0..m-2). Target i is anomalous when
    // both differences that involve it are flagged; an end target when its only difference is
    // flagged and the next one is not.
    auto flagged = [&](long k) {
      return k >= 0 && k + 1 < static_cast<long>(m) && D.flagged[static_cast<std::size_t>(k)];
    };
    for (std::size_t i = 0; i < m; ++i) {
      const long left = static_cast<long>(i) - 1, right = static_cast<long>(i);
      bool anomalous;
      if (i == 0)
        anomalous = flagged(0) && !flagged(1);
      else if (i + 1 == m)
        anomalous = flagged(left) && !flagged(left - 1);
      else
        anomalous = flagged(left) && flagged(right);
      if (anomalous) res.anomalous_positions.push_back({dir, i});
    }
  }
}

// The rebuilt chart: the reference cycle's value at the reference target, accumulated with the
// mean adjacent differences outward; s* of the difference linking each target toward the
// reference, divided by sqrt(2) (Stejskal et al. 2017, eq. (9)). Returns s* per direction.
std::array<std::vector<double>, 2> rebuild_chart(const IsoRuns& R,
                                                 const std::array<std::size_t, 2>& j0,
                                                 DriftResult& res) {
  const std::size_t m = R.targets(), r = res.reference_target;
  std::array<std::vector<double>, 2> s_star;
  for (int d = 0; d < 2; ++d) {
    const std::size_t n = R.cycles[d].size();
    const AdjacentDifferences& D = res.differences[d];
    DriftChart& C = res.chart[d];
    C = {};
    C.value.assign(m, 0);
    C.s_diff.assign(m, 0);
    C.value[r] = R.x[d][r][j0[d]];
    for (std::size_t i = r + 1; i < m; ++i) C.value[i] = C.value[i - 1] + D.mean[i - 1];
    for (std::size_t i = r; i-- > 0;) C.value[i] = C.value[i + 1] - D.mean[i];
    for (std::size_t i = 0; i < m; ++i) {
      std::size_t k;  // difference between targets k and k+1
      if (i > r)
        k = i - 1;
      else if (i < r)
        k = i;
      else
        k = i + 1 < m ? i : i - 1;
      C.s_diff[i] = D.s[k];
      C.s.push_back(D.s[k] / std::sqrt(2.0));
    }
    C.shifted.assign(m, std::vector<double>(n));
    for (std::size_t i = 0; i < m; ++i)
      for (std::size_t j = 0; j < n; ++j)
        C.shifted[i][j] = R.x[d][i][j] - R.x[d][r][j] + R.x[d][r][j0[d]];
    s_star[d] = C.s;
  }
  return s_star;
}

// s ratio: pooled s of the differences over the pooled classical s.
void spread_ratio(const IsoRuns& R, DriftResult& res) {
  const std::size_t m = R.targets();
  for (int d = 0; d < 2; ++d) {
    double sd2 = 0, sx2 = 0;
    for (double s : res.differences[d].s) sd2 += s * s;
    for (std::size_t i = 0; i < m; ++i) {
      const double s = sample_sd(R.x[d][i]);
      sx2 += s * s;
    }
    res.s_ratio[d] =
        std::sqrt(sd2 / static_cast<double>(m - 1)) / std::sqrt(sx2 / static_cast<double>(m));
  }
}

// Drift per cycle: each cycle's mean offset from the reference cycle, and the drift rate per
// cycle (and per hour when the readings are timed) as a within-target slope.
void drift_per_cycle(const IsoRuns& R, const std::array<std::size_t, 2>& j0, DriftPerCycle& P) {
  const std::size_t m = R.targets();
  for (int d = 0; d < 2; ++d)
    P.cycles.insert(P.cycles.end(), R.cycles[d].begin(), R.cycles[d].end());
  std::sort(P.cycles.begin(), P.cycles.end());
  P.cycles.erase(std::unique(P.cycles.begin(), P.cycles.end()), P.cycles.end());
  const std::size_t nc = P.cycles.size();
  std::array<std::vector<double>*, 2> off = {&P.offset_up, &P.offset_down};
  for (int d = 0; d < 2; ++d) {
    const std::size_t n = R.cycles[d].size();
    std::vector<double> raw(n, 0);
    for (std::size_t i = 0; i < m; ++i) {
      const double mean = sample_mean(R.x[d][i]);
      for (std::size_t j = 0; j < n; ++j) raw[j] += (R.x[d][i][j] - mean) / static_cast<double>(m);
    }
    off[d]->assign(nc, kNaN);
    for (std::size_t j = 0; j < n; ++j) {
      const std::size_t c = static_cast<std::size_t>(
          std::lower_bound(P.cycles.begin(), P.cycles.end(), R.cycles[d][j]) - P.cycles.begin());
      (*off[d])[c] = raw[j] - raw[j0[d]];
    }
  }
  for (std::size_t c = 0; c < nc; ++c) {
    const double u = P.offset_up[c], w = P.offset_down[c];
    P.offset.push_back(std::isnan(u) ? w : std::isnan(w) ? u : (u + w) / 2);
  }
  std::vector<std::vector<std::pair<double, double>>> by_cycle, by_time;
  for (int d = 0; d < 2; ++d)
    for (std::size_t i = 0; i < m; ++i) {
      by_cycle.emplace_back();
      by_time.emplace_back();
      for (std::size_t j = 0; j < R.cycles[d].size(); ++j) {
        by_cycle.back().emplace_back(static_cast<double>(R.cycles[d][j]), R.x[d][i][j]);
        by_time.back().emplace_back(R.t[d][i][j] / 3600.0, R.x[d][i][j]);
      }
    }
  std::tie(P.rate_per_cycle, P.rate_per_cycle_se) = within_slope(by_cycle);
  if (R.has_time) {
    std::tie(P.rate_per_h, P.rate_per_h_se) = within_slope(by_time);
    double t0 = INFINITY;
    for (int d = 0; d < 2; ++d)
      for (const auto& row : R.t[d])
        for (double t : row) t0 = std::min(t0, t);
    std::vector<double> sum(nc, 0), cnt(nc, 0);
    for (int d = 0; d < 2; ++d)
      for (std::size_t j = 0; j < R.cycles[d].size(); ++j) {
        const std::size_t c = static_cast<std::size_t>(
            std::lower_bound(P.cycles.begin(), P.cycles.end(), R.cycles[d][j]) - P.cycles.begin());
        for (std::size_t i = 0; i < m; ++i) sum[c] += R.t[d][i][j] - t0, cnt[c] += 1;
      }
    for (std::size_t c = 0; c < nc; ++c) P.time_h.push_back(sum[c] / cnt[c] / 3600.0);
  }
}

}  // namespace

void DriftOptions::validate() const {
  if (!(alpha > 0 && alpha < 1))
    throw std::invalid_argument("drift elimination: alpha must be in (0, 1)");
  if (!(coverage > 0))
    throw std::invalid_argument("drift elimination: the coverage factor must be > 0");
  if (!(tolerance_mm > 0))
    throw std::invalid_argument("drift elimination: tolerance_mm must be > 0");
}

DriftElimination::DriftElimination(DriftOptions options) : options_(std::move(options)) {
  options_.validate();
}

DriftResult DriftElimination::run(const IsoRuns& R) const {
  const std::size_t m = R.targets();
  if (m < 2)
    throw InputError(SourceLoc{R.file, 0, 0},
                     "the drift elimination needs at least 2 targets (adjacent differences)");
  DriftResult res;
  res.alpha = options_.alpha;
  const std::array<std::size_t, 2> j0 = drift_reference(R, options_, res);
  adjacent_differences(R, res);
  flag_anomalies(m, options_.alpha, res);
  const std::array<std::vector<double>, 2> s_star = rebuild_chart(R, j0, res);
  res.figures = iso_figures(res.chart[kUp].value, res.chart[kDown].value, s_star[kUp],
                            s_star[kDown], options_.coverage, options_.coverage);
  if (options_.student) {
    const double ku = student_coverage_factor(R.cycles[kUp].size() - 1, options_.coverage);
    const double kd = student_coverage_factor(R.cycles[kDown].size() - 1, options_.coverage);
    res.student = iso_figures(res.chart[kUp].value, res.chart[kDown].value, s_star[kUp],
                              s_star[kDown], ku, kd);
  }

  spread_ratio(R, res);
  drift_per_cycle(R, j0, res.per_cycle);
  return res;
}

}  // namespace weilgen
