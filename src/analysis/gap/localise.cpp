#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <set>
#include <stdexcept>

#include "internal.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen::gap_detail {

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

}  // namespace weilgen::gap_detail
