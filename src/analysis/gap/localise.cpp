// Where the held-out residual concentrates (docs/gap.md, "Where"). Every dimension of every
// output gets a one-way analysis of variance over up to 8 bins of equal count: the F test of the
// between-bin against the within-bin variation says whether the dimension structures the
// residual at all, and the between-bin share how much of it. Ranking by that share (not by the
// size of the worst bin) puts the cause first: a bump along Y is "Y", not "the largest bin of
// dir_Y"; a drift spread over all data is "t_s", not whichever cycle is largest.
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "internal.hpp"

namespace weilgen::gap_detail {

namespace {

struct Dim {
  std::string by, unit;
  std::vector<double> value;  // per observation
  bool ordered = true;
  std::vector<std::string> same_as;
};

// The coordinates the residual is binned along, per observation: the axes, time, each
// direction, the cycle, the temperatures and covariates; one with fewer than two values is left
// out, one equal to an earlier one is named beside it.
std::vector<Dim> localisation_dims(const GapData& d) {
  const auto& obs = d.points.observations;
  std::vector<Dim> dims;
  auto add = [&](const std::string& name, const std::string& unit, std::vector<double> value,
                 bool ordered) {
    if (distinct(value) < 2) return;
    // The very same values as a dimension already taken (dir_X = dir_Y in a diagonal run):
    // reported once.
    for (Dim& other : dims)
      if (other.value == value) {
        other.same_as.push_back(name);
        return;
      }
    dims.push_back({name, unit, std::move(value), ordered, {}});
  };
  for (std::size_t a = 0; a < d.axes.size(); ++a) {
    std::vector<double> v;
    for (const auto& o : obs) v.push_back(d.points.poses[o.row][a]);
    add(d.axes[a], a < d.axis_units.size() ? d.axis_units[a] : "", std::move(v), true);
  }
  auto per_obs = [&](const std::vector<double>& per_row) {
    std::vector<double> v;
    for (const auto& o : obs) v.push_back(per_row[o.row]);
    return v;
  };
  add("t_s", "s", per_obs(d.time_s), true);
  for (const auto& [a, v] : d.dir) add("dir_" + a, "", per_obs(v), false);
  add("cycle", "", per_obs(d.cycle), false);
  for (const auto& [n, v] : d.temperature) add(n, "°C", per_obs(v), true);
  for (const auto& [n, v] : d.covariate) {
    const auto u = d.covariate_unit.find(n);
    add(n, u == d.covariate_unit.end() ? "" : u->second, per_obs(v), true);
  }
  return dims;
}

}  // namespace

std::vector<GapRegion> localise(const GapData& d, const VectorXd& r, const VectorXd& h,
                                const NoiseFloor& nf, double alpha) {
  const auto& obs = d.points.observations;
  const double s2 = nf.sigma_um * nf.sigma_um;
  const std::vector<Dim> dims = localisation_dims(d);

  auto bin_stats = [&](GapRegion& g, const std::vector<std::size_t>& idx) {
    Gap gp;
    for (std::size_t i : idx) {
      const double ri = r[static_cast<Index>(i)];
      if (!std::isfinite(ri)) continue;
      gp.ss += ri * ri;
      gp.expected += s2 * (1 + h[static_cast<Index>(i)]);
      ++gp.n;
    }
    g.n = gp.n;
    g.rms_um = gp.n ? std::sqrt(gp.ss / static_cast<double>(gp.n)) : 0;
    double p = 1;
    gap_stats(gp, nf.dof, g.excess_um, p);
    return p;
  };
  std::vector<GapRegion> outputs, regions;
  for (int o = 0; o < static_cast<int>(kObservationKinds); ++o) {
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < obs.size(); ++i)
      if (obs[i].output == o && std::isfinite(r[static_cast<Index>(i)])) idx.push_back(i);
    if (idx.empty()) continue;
    GapRegion whole;
    whole.by = "output";
    whole.output = observation_name(static_cast<std::size_t>(o));
    whole.p_value = bin_stats(whole, idx);
    outputs.push_back(whole);
    for (const Dim& dm : dims) {
      std::vector<double> u;
      for (std::size_t i : idx) u.push_back(dm.value[i]);
      std::sort(u.begin(), u.end());
      u.erase(std::unique(u.begin(), u.end()), u.end());
      if (u.size() < 2) continue;
      const std::size_t nb = std::min<std::size_t>(8, u.size());
      std::vector<std::vector<std::size_t>> members(nb);
      std::vector<std::pair<double, double>> range(nb, {INFINITY, -INFINITY});
      for (std::size_t i : idx) {
        const auto l =
            static_cast<std::size_t>(std::lower_bound(u.begin(), u.end(), dm.value[i]) - u.begin());
        const std::size_t b = l * nb / u.size();
        members[b].push_back(i);
        range[b].first = std::min(range[b].first, dm.value[i]);
        range[b].second = std::max(range[b].second, dm.value[i]);
      }
      // One-way analysis of variance of the residual over the bins.
      double mean = 0;
      for (std::size_t i : idx) mean += r[static_cast<Index>(i)];
      mean /= static_cast<double>(idx.size());
      double ssb = 0, ssw = 0;
      std::size_t k = 0;
      std::vector<double> rms(nb, 0.0);
      for (std::size_t b = 0; b < nb; ++b) {
        if (members[b].empty()) continue;
        ++k;
        double m = 0, ss = 0;
        for (std::size_t i : members[b]) m += r[static_cast<Index>(i)];
        m /= static_cast<double>(members[b].size());
        for (std::size_t i : members[b]) {
          const double ri = r[static_cast<Index>(i)];
          ssw += (ri - m) * (ri - m);
          ss += ri * ri;
        }
        ssb += static_cast<double>(members[b].size()) * (m - mean) * (m - mean);
        rms[b] = std::sqrt(ss / static_cast<double>(members[b].size()));
      }
      const double n = static_cast<double>(idx.size());
      if (k < 2 || n <= static_cast<double>(k)) continue;
      const double f = ssw > 0 ? (ssb / static_cast<double>(k - 1)) / (ssw / (n - double(k)))
                               : (ssb > 0 ? INFINITY : 0);
      // The worst bin, widened over ordered neighbours nearly as bad.
      std::size_t worst = 0;
      for (std::size_t b = 1; b < nb; ++b)
        if (rms[b] > rms[worst]) worst = b;
      std::size_t lo = worst, hi = worst;
      while (dm.ordered && lo > 0 && rms[lo - 1] >= 0.7 * rms[worst]) --lo;
      while (dm.ordered && hi + 1 < nb && rms[hi + 1] >= 0.7 * rms[worst]) ++hi;
      std::vector<std::size_t> in;
      for (std::size_t b = lo; b <= hi; ++b)
        in.insert(in.end(), members[b].begin(), members[b].end());
      GapRegion g;
      g.by = dm.by;
      g.unit = dm.unit;
      g.same_as = dm.same_as;
      g.output = observation_name(static_cast<std::size_t>(o));
      g.from = range[lo].first;
      g.to = range[hi].second;
      bin_stats(g, in);
      g.p_value = f_sf(f, static_cast<double>(k - 1), n - static_cast<double>(k));
      // omega^2: the between-bin share less what k bins would explain by chance, so a
      // dimension of 8 bins does not outrank a direction (2 bins) by its bin count alone.
      const double msw = ssw / (n - static_cast<double>(k));
      g.explained =
          (ssb + ssw) > 0
              ? std::max(0.0, (ssb - static_cast<double>(k - 1) * msw) / (ssb + ssw + msw))
              : 0;
      regions.push_back(g);
    }
  }
  // Bonferroni over every test: the outputs' gap tests and every dimension's F test.
  const double tests = static_cast<double>(outputs.size() + regions.size());
  for (auto* list : {&outputs, &regions})
    for (GapRegion& g : *list) {
      g.p_value = std::min(1.0, g.p_value * tests);
      g.significant = g.p_value < alpha;
    }
  // Dimensions that structure the residual first, by how much of it they explain; then the
  // outputs' own entries; then the rest.
  std::stable_sort(regions.begin(), regions.end(), [](const GapRegion& a, const GapRegion& b) {
    if (a.significant != b.significant) return a.significant;
    return a.explained > b.explained;
  });
  std::stable_sort(outputs.begin(), outputs.end(), [](const GapRegion& a, const GapRegion& b) {
    if (a.significant != b.significant) return a.significant;
    return a.excess_um > b.excess_um;
  });
  std::vector<GapRegion> out;
  for (const GapRegion& g : regions)
    if (g.significant) out.push_back(g);
  out.insert(out.end(), outputs.begin(), outputs.end());
  for (const GapRegion& g : regions)
    if (!g.significant) out.push_back(g);
  return out;
}

}  // namespace weilgen::gap_detail
