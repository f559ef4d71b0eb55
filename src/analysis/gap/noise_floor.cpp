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

// Differences per region of the robust floor: enough for a MAD within a few per cent, few enough
// that the noise is about constant inside a region.
constexpr std::size_t kRegionDifferences = 60;
// Differences beyond this many robust scales of their region count as this many.
constexpr double kClip = 4;

// A sequence of values (repeats of one observation, or the held-out residual of one output in
// time order) and the variance of each of its centred successive differences d_i − d̄ in units
// of σ² (of d_0 alone when there is one difference).
struct Sequence {
  std::vector<double> value, var;
};

// White noise: Var(d_i − d̄) = 2σ²(1 + 1/k² − [i is the first or last]/k) for k differences.
std::vector<double> white_variances(std::size_t values) {
  if (values < 2) return {};
  const std::size_t k = values - 1;
  if (k == 1) return {2.0};
  const double kk = static_cast<double>(k);
  std::vector<double> v(k);
  for (std::size_t i = 0; i < k; ++i)
    v[i] = 2 * (1 + 1 / (kk * kk) - ((i == 0 || i + 1 == k) ? 1.0 / kk : 0.0));
  return v;
}

// Robust pooled scale of successive differences: each sequence of 3 or more has its mean
// difference removed (a linear drift along it does not count), and each centred difference is
// rescaled to variance 2σ² by its exact variance under the null hypothesis (white noise for
// repeats; the held-out residual's own covariance, HeldoutCovariance, for the small-scale
// estimate). The differences, in sequence order (time, so neighbours are near in the layout),
// are cut into regions of about kRegionDifferences; in each, σ² is the mean square of the
// differences, each clipped at kClip robust scales (1.4826 · median|d − median d|), over 2; the
// floor is the mean σ² over the regions. The clip keeps a step or a few drift jumps between
// repeats from inflating the floor as they would a plain mean square; the mean square (not the
// median's scale) follows noise whose σ differs across the layout (a tracker's noise growing
// with range: with a 1…4× spread one MAD reads σ 15 % low, and the held-out gap test
// over-rejects). Bias (simulated, 600 differences): −1 % for normal noise (the clip), −3 % for a
// 1…4× mixture inside every region. Degrees of freedom: the MAD's efficiency (0.37) times the
// MSSD's (2/3) times the number of differences (kept from the MAD floor: conservative).
void mssd(const std::vector<Sequence>& sequences, double& sigma2, double& dof,
          std::size_t& differences) {
  std::vector<double> all;
  for (const auto& s : sequences) {
    if (s.value.size() < 2) continue;
    std::vector<double> d;
    for (std::size_t i = 1; i < s.value.size(); ++i) d.push_back(s.value[i] - s.value[i - 1]);
    const std::size_t k = d.size();
    const double mean =
        k < 2 ? 0.0 : std::accumulate(d.begin(), d.end(), 0.0) / static_cast<double>(k);
    for (std::size_t i = 0; i < k; ++i)
      if (s.var[i] > 1e-9) all.push_back((d[i] - mean) * std::sqrt(2 / s.var[i]));
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
  const std::size_t regions = std::max<std::size_t>(1, all.size() / kRegionDifferences);
  double sum = 0;
  for (std::size_t g = 0; g < regions; ++g) {
    const std::size_t b = g * all.size() / regions, e = (g + 1) * all.size() / regions;
    std::vector<double> part(all.begin() + static_cast<long>(b),
                             all.begin() + static_cast<long>(e));
    const double m = median(part);
    std::vector<double> dev(part.size());
    for (std::size_t i = 0; i < part.size(); ++i) dev[i] = std::abs(part[i] - m);
    const double robust = 1.4826 * median(dev);  // scale of the differences (√2 σ)
    // The mean square with each difference clipped at kClip robust scales: a few gross jumps
    // add at most kClip² each, while noise whose σ differs inside the region is still counted
    // at its mean square (a median reads a mixture of σ low).
    const double clip = kClip * robust;
    double ss = 0;
    for (double x : part) ss += std::min((x - m) * (x - m), clip * clip);
    sum += ss / static_cast<double>(part.size()) / 2;
  }
  sigma2 = sum / static_cast<double>(regions);
  dof = 0.37 * (2.0 / 3.0) * static_cast<double>(differences);
}

}  // namespace

NoiseFloor noise_floor(const GapData& d, const VectorXd& heldout, const HeldoutCovariance& cov) {
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
  std::vector<std::vector<std::size_t>*> repeats_in_time;
  for (auto& [key, idx] : groups) {
    if (idx.size() < 2) continue;
    repeated += idx.size();
    std::stable_sort(idx.begin(), idx.end(),
                     [&](std::size_t a, std::size_t b) { return time_of(a) < time_of(b); });
    repeats_in_time.push_back(&idx);
  }
  // In the time order of their first reading, so that neighbouring groups are near in the
  // layout (the regions of mssd).
  std::stable_sort(
      repeats_in_time.begin(), repeats_in_time.end(),
      [&](const auto* a, const auto* b) { return time_of(a->front()) < time_of(b->front()); });
  std::array<std::vector<Sequence>, kObservationKinds> seq;
  for (const auto* idx : repeats_in_time) {
    Sequence s;
    for (std::size_t i : *idx) s.value.push_back(obs[i].value);
    s.var = white_variances(s.value.size());
    seq[static_cast<std::size_t>(obs[idx->front()].output)].push_back(std::move(s));
  }
  const bool repeats = repeated * 10 >= obs.size() * 3;  // >= 30 % of observations repeated
  // Small-scale sequences: the held-out residual in time (or row) order, per output. Its
  // successive differences carry the folds' prediction errors, which neighbours far apart in
  // the design (a rotary layout, a small set) do not share: their exact variance comes from the
  // folds' factors, so the floor reads σ and not σ times the leverage.
  std::array<std::vector<Sequence>, kObservationKinds> small;
  {
    std::vector<std::size_t> order(obs.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return time_of(a) < time_of(b); });
    std::array<std::vector<std::size_t>, kObservationKinds> idx;
    for (std::size_t i : order)
      if (std::isfinite(heldout[static_cast<Index>(i)]))
        idx[static_cast<std::size_t>(obs[i].output)].push_back(i);
    for (std::size_t o = 0; o < kObservationKinds; ++o) {
      Sequence s;
      for (std::size_t i : idx[o]) s.value.push_back(heldout[static_cast<Index>(i)]);
      s.var = cov.difference_variances(idx[o]);
      small[o].push_back(std::move(s));
    }
  }
  struct Estimate {
    std::array<double, kObservationKinds> per_output{};
    double sigma = kNaN, dof = 0;
    std::size_t n = 0;
  };
  auto estimate = [](const std::array<std::vector<Sequence>, kObservationKinds>& sq) {
    Estimate e;
    std::vector<Sequence> all;
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
