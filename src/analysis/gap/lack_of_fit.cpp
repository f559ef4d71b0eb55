// The lack of fit of a model on all data (docs/gap.md, "Lack of fit").
#include <algorithm>
#include <cmath>
#include <optional>

#include "verdict.hpp"
#include "weilgen/base/parallel.hpp"

namespace weilgen::gap_detail {

namespace {

// Per observation, the value of every coordinate that varies in the data: time, then the axes.
std::vector<std::pair<std::string, std::vector<double>>> varying_coordinates(const GapData& d) {
  const auto& obs = d.points.observations;
  const std::size_t n = obs.size();
  std::vector<std::pair<std::string, std::vector<double>>> coords;
  auto add = [&](const std::string& name, auto&& value) {
    std::vector<double> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = value(obs[i].row);
    if (std::any_of(v.begin(), v.end(), [](double x) { return !std::isfinite(x); })) return;
    if (*std::max_element(v.begin(), v.end()) > *std::min_element(v.begin(), v.end()))
      coords.emplace_back(name, std::move(v));
  };
  add("time", [&](std::size_t row) { return row < d.time_s.size() ? d.time_s[row] : kNaN; });
  for (std::size_t a = 0; a < d.axes.size(); ++a)
    add(d.axes[a], [&](std::size_t row) { return d.points.poses[row][a]; });
  return coords;
}

// The bin edges of one coordinate's values: its distinct positions, or kBins bins of equal
// count when it has more (bin b holds the values below edges[b]).
std::vector<double> bin_edges(const std::vector<double>& v) {
  std::vector<double> levels = v;
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  std::vector<double> edges;
  if (levels.size() <= LackOfFit::kBins) {
    for (std::size_t l = 1; l < levels.size(); ++l) edges.push_back(levels[l]);
  } else {
    std::vector<double> sorted = v;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t b = 1; b < LackOfFit::kBins; ++b)
      edges.push_back(sorted[b * v.size() / LackOfFit::kBins]);
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  }
  return edges;
}

// A free offset per deviation output and bin, as each observation sees it: its own output, or
// for a ballbar's dr the offset's radial part (a step in y moves the circle's centre, which a
// free offset of dr per bin, averaging out over each circle, would not see). Only the outputs'
// bins that hold observations.
MatrixXd bin_offsets(const GapData& d, const std::vector<double>& v,
                     const std::vector<double>& edges) {
  const auto& obs = d.points.observations;
  constexpr int kOffsets = 6;  // dx dy dz da db dc
  const Index nb = static_cast<Index>(edges.size() + 1);
  MatrixXd G = MatrixXd::Zero(static_cast<Index>(obs.size()), nb * kOffsets);
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const auto b = std::upper_bound(edges.begin(), edges.end(), v[i]) - edges.begin();
    for (int o = 0; o < kOffsets; ++o)
      G(static_cast<Index>(i), o * nb + b) = observation_weight(obs[i], o);
  }
  std::vector<Index> seen;
  for (Index c = 0; c < G.cols(); ++c)
    if (G.col(c).any()) seen.push_back(c);
  return G(Eigen::all, seen);
}

}  // namespace

LackOfFit lack_of_fit(const DesignLeastSquares& e, const GapData& d, const MatrixXd* extra) {
  const std::size_t n = d.points.observations.size();
  const auto coords = varying_coordinates(d);
  LackOfFit worst;
  std::size_t ref_rank = e.full_rank;
  double ref_sse = e.full_sse;
  if (extra && extra->cols() > 0) {
    const JointFit f = joint_fit(*e.factors, e.A, e.y, *extra);
    ref_rank = f.rank, ref_sse = f.sse;
  }
  worst.reference_sse = ref_sse;
  // Each coordinate's joint fit on its own (in parallel), the p-values compared in order.
  std::vector<std::optional<JointFit>> fits(coords.size());
  parallel_blocks(coords.size(), 1, e.threads,
                  [&](std::size_t c, std::size_t, std::size_t, unsigned) {
                    const std::vector<double>& v = coords[c].second;
                    MatrixXd G = bin_offsets(d, v, bin_edges(v));
                    if (extra && extra->cols() > 0) {
                      MatrixXd EG(G.rows(), extra->cols() + G.cols());
                      EG << *extra, G;
                      G = std::move(EG);
                    }
                    fits[c] = joint_fit(*e.factors, e.A, e.y, G);
                  });
  for (std::size_t c = 0; c < coords.size(); ++c) {
    const std::string& name = coords[c].first;
    const JointFit& f = *fits[c];
    const double q = static_cast<double>(f.rank) - static_cast<double>(ref_rank);
    const double d2 = static_cast<double>(n) - static_cast<double>(f.rank);
    if (q <= 0 || d2 <= 0 || !(f.sse > 0)) continue;
    const double p = std::min(1.0, f_sf(((ref_sse - f.sse) / q) / (f.sse / d2), q, d2) *
                                       static_cast<double>(coords.size()));
    if (p < worst.p_value)
      worst = {p, name, std::max(0.0, ref_sse - f.sse - q * f.sse / d2), ref_sse};
  }
  return worst;
}

}  // namespace weilgen::gap_detail
