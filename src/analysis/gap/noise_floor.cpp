#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <set>
#include <stdexcept>

#include "internal.hpp"
#include "weilgen/base/format.hpp"

namespace weilgen::gap_detail {

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

}  // namespace

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

}  // namespace weilgen::gap_detail
