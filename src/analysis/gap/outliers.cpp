// Gross readings (docs/gap.md, "Outliers"): a reading whose studentised residual (of a fit on
// all data: the baseline, or the baseline and the accepted effects) lies beyond max(6, z_n)
// robust standard deviations of its output's residuals (z_n: the two-sided normal quantile
// that n readings exceed by chance with probability 1 %) and of its 20 nearest neighbours'
// in the pose space, and whose nearest neighbours do not share it: neither those in the pose
// space nor, when the data have a time, those nearest in time. A smooth effect moves its
// neighbours too (a bump or a reversal its pose neighbours, a drift its time neighbours: the
// same pose an hour later is not its neighbour), so it is not taken for an outlier; a spike is.
#include <algorithm>
#include <cmath>
#include <numeric>

#include "internal.hpp"
#include "weilgen/uq/distribution.hpp"

namespace weilgen::gap_detail {

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  double m = *mid;
  if (v.size() % 2 == 0) m = (m + *std::max_element(v.begin(), mid)) / 2;
  return m;
}

// The wider neighbourhood in the pose space whose spread a gross reading must exceed too.
constexpr std::size_t kLocal = 20;

}  // namespace

std::vector<GapOutlier> find_outliers(const GapData& d, const VectorXd& res, const VectorXd& lev) {
  const auto& obs = d.points.observations;
  std::vector<GapOutlier> out;
  // Studentised: a residual's variance is σ²(1 − h), so r/√(1 − h) has the same spread at every
  // leverage (the deleted r/(1 − h) would spread wider at the design's edge); a spike of size δ
  // reads δ√(1 − h) in it, δ in the deleted residual, which is reported.
  VectorXd r = res, deleted = res;
  for (Index i = 0; i < r.size(); ++i) {
    const double keep = std::max(1e-6, 1 - lev[i]);
    r[i] /= std::sqrt(keep);
    deleted[i] /= keep;
  }
  // Scale of each coordinate over the data, so that neighbours weigh axes alike.
  const std::size_t na = d.axes.size();
  std::vector<double> lo(na, INFINITY), hi(na, -INFINITY);
  for (const auto& p : d.points.poses)
    for (std::size_t a = 0; a < na && a < p.size(); ++a)
      if (std::isfinite(p[a])) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  for (int o = 0; o < static_cast<int>(kObservationKinds); ++o) {
    std::vector<std::size_t> mine;
    for (std::size_t i = 0; i < obs.size(); ++i)
      if (obs[i].output == o && std::isfinite(r[static_cast<Index>(i)])) mine.push_back(i);
    if (mine.size() < 10) continue;
    std::vector<double> v;
    for (std::size_t i : mine) v.push_back(r[static_cast<Index>(i)]);
    const double centre = median(v);
    for (double& x : v) x = std::abs(x - centre);
    const double sigma = 1.4826 * median(v);
    if (!(sigma > 0)) continue;
    const double n = static_cast<double>(mine.size());
    const double z = std::max(6.0, -normal_quantile(0.005 / n));  // P(Z > z) = 0.005 / n
    // Structure when neighbours share a good part of the deviation (a bump or a step moves them
    // by a similar amount); a spike's neighbours are at most pulled a little by the fit.
    auto shared = [&](const std::vector<std::size_t>& nb, double dev) {
      std::vector<double> around;
      for (std::size_t j : nb)
        around.push_back(std::abs(r[static_cast<Index>(j)] - centre) / sigma);
      return !around.empty() && median(around) > std::max(3.0, 0.3 * dev);
    };
    // The same output's readings in time order (rows without a time left out).
    std::vector<std::size_t> by_time;
    for (std::size_t i : mine)
      if (std::isfinite(d.time_s[obs[i].row])) by_time.push_back(i);
    std::stable_sort(by_time.begin(), by_time.end(), [&](std::size_t a, std::size_t b) {
      return d.time_s[obs[a].row] < d.time_s[obs[b].row];
    });
    std::vector<std::size_t> time_rank(obs.size(), SIZE_MAX);
    for (std::size_t k = 0; k < by_time.size(); ++k) time_rank[by_time[k]] = k;
    for (std::size_t i : mine) {
      const double dev = std::abs(r[static_cast<Index>(i)] - centre) / sigma;
      if (dev <= z) continue;
      // Its nearest neighbours (same output, other rows): a shared deviation is structure.
      const auto& pi = d.points.poses[obs[i].row];
      std::vector<std::pair<double, std::size_t>> near;
      for (std::size_t j : mine) {
        if (obs[j].row == obs[i].row) continue;
        const auto& pj = d.points.poses[obs[j].row];
        double dist = 0;
        for (std::size_t a = 0; a < na; ++a)
          if (hi[a] > lo[a]) dist += std::pow((pi[a] - pj[a]) / (hi[a] - lo[a]), 2);
        near.push_back({dist, j});
      }
      const std::size_t wide = std::min<std::size_t>(kLocal, near.size());
      std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(wide), near.end());
      // Against the spread of its wider neighbourhood too: noise that grows across the
      // workspace (a tracker's range) puts honest readings of the far poses beyond the global
      // scale, not beyond their neighbours'.
      std::vector<double> local;
      for (std::size_t m = 0; m < wide; ++m) local.push_back(r[static_cast<Index>(near[m].second)]);
      const double local_centre = median(local);
      for (double& x : local) x = std::abs(x - local_centre);
      const double local_sigma = 1.4826 * median(local);
      if (wide >= kLocal / 2 &&
          std::abs(r[static_cast<Index>(i)] - local_centre) <= z * std::max(sigma, local_sigma))
        continue;
      const std::size_t k = std::min<std::size_t>(4, near.size());
      std::vector<std::size_t> pose_nb;
      for (std::size_t m = 0; m < k; ++m) pose_nb.push_back(near[m].second);
      if (shared(pose_nb, dev)) continue;
      // Its neighbours in time: two before and two after.
      if (time_rank[i] != SIZE_MAX) {
        std::vector<std::size_t> time_nb;
        const std::size_t t = time_rank[i];
        for (std::size_t m = t >= 2 ? t - 2 : 0; m <= t + 2 && m < by_time.size(); ++m)
          if (m != t && obs[by_time[m]].row != obs[i].row) time_nb.push_back(by_time[m]);
        if (shared(time_nb, dev)) continue;
      }
      GapOutlier g;
      g.observation = i;
      g.line = obs[i].line;
      g.output = observation_name(static_cast<std::size_t>(o));
      g.value_um = obs[i].value;
      g.residual_um = deleted[static_cast<Index>(i)];
      g.sigmas = dev;
      out.push_back(g);
    }
  }
  std::sort(out.begin(), out.end(),
            [](const GapOutlier& a, const GapOutlier& b) { return a.observation < b.observation; });
  return out;
}

// In rounds: the deleted residuals of the fit on the readings left, the readings find_outliers
// flags removed, refit, until a round flags none (at most 4 rounds: a spike pulls the fit
// towards itself and masks a smaller one beside it only until it is gone).
std::vector<GapOutlier> gross_readings(const MatrixXd& A, const GapData& d, unsigned threads) {
  std::vector<GapOutlier> all;
  std::vector<std::size_t> index(d.points.observations.size());  // into `d`
  std::iota(index.begin(), index.end(), 0);
  GapData cur = d;
  for (int round = 0; round < 4; ++round) {
    const auto& obs = cur.points.observations;
    VectorXd y(static_cast<Index>(obs.size()));
    for (std::size_t i = 0; i < obs.size(); ++i) y[static_cast<Index>(i)] = obs[i].value;
    const FoldFit f = fit_all_rows(rows_of(A, index), y, all_rows(obs.size()), threads);
    std::vector<GapOutlier> found = find_outliers(cur, f.res_train, f.lev_train);
    if (found.empty()) break;
    std::vector<std::size_t> kept;
    GapData next = without_readings(cur, found, kept);
    for (GapOutlier& g : found) g.observation = index[g.observation];
    all.insert(all.end(), found.begin(), found.end());
    for (std::size_t& k : kept) k = index[k];
    cur = std::move(next);
    index = std::move(kept);
  }
  std::sort(all.begin(), all.end(),
            [](const GapOutlier& a, const GapOutlier& b) { return a.observation < b.observation; });
  return all;
}

GapData without_readings(const GapData& d, const std::vector<GapOutlier>& gross,
                         std::vector<std::size_t>& kept) {
  const auto& obs = d.points.observations;
  GapData clean = d;
  clean.points.observations.clear();
  clean.points.count = {};
  kept.clear();
  std::size_t next = 0;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    if (next < gross.size() && gross[next].observation == i) {
      ++next;
      continue;
    }
    kept.push_back(i);
    clean.points.observations.push_back(obs[i]);
    ++clean.points.count[static_cast<std::size_t>(obs[i].output)];
  }
  return clean;
}

}  // namespace weilgen::gap_detail
