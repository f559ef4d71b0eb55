// Gross readings (docs/gap.md, "Outliers"): a reading whose baseline residual (deleted: divided
// by 1 − its leverage, so a reading at the edge of the design cannot hide) lies beyond
// max(6, z_n) robust standard deviations of its output's residuals (z_n: the two-sided normal
// quantile that n readings exceed by chance with probability 1 %), and whose nearest neighbours
// in the pose space do not share it. A smooth effect (a bump, a reversal, a drift) moves its
// neighbours too, so it is not taken for an outlier; a spike is.
#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <cmath>

#include "internal.hpp"

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

}  // namespace

std::vector<GapOutlier> find_outliers(const GapData& d, const VectorXd& r) {
  const auto& obs = d.points.observations;
  std::vector<GapOutlier> out;
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
    const boost::math::normal_distribution<double> normal;
    const double z =
        std::max(6.0, boost::math::quantile(boost::math::complement(normal, 0.005 / n)));
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
      const std::size_t k = std::min<std::size_t>(4, near.size());
      std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(k), near.end());
      std::vector<double> around;
      for (std::size_t m = 0; m < k; ++m)
        around.push_back(std::abs(r[static_cast<Index>(near[m].second)] - centre) / sigma);
      // Structure when the neighbours share a good part of it (a bump or a step moves them by a
      // similar amount); a spike's neighbours are at most pulled a little by the fit.
      if (k > 0 && median(around) > std::max(3.0, 0.3 * dev)) continue;
      GapOutlier g;
      g.observation = i;
      g.line = obs[i].line;
      g.output = observation_name(static_cast<std::size_t>(o));
      g.value_um = obs[i].value;
      g.residual_um = r[static_cast<Index>(i)];
      g.sigmas = dev;
      out.push_back(g);
    }
  }
  std::sort(out.begin(), out.end(),
            [](const GapOutlier& a, const GapOutlier& b) { return a.observation < b.observation; });
  return out;
}

}  // namespace weilgen::gap_detail
