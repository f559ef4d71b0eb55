// Crude Monte Carlo with a Wilson interval. Fixed blocks of samples, one random stream per
// block, failure counts summed in block order: bit-identical for any thread count.
#include <algorithm>
#include <cmath>
#include <limits>

#include "reliability_detail.hpp"
#include "weilgen/base/parallel.hpp"
#include "weilgen/uq/reliability.hpp"

namespace weilgen::reliability_detail {

namespace {

constexpr std::size_t kSamplesPerBlock = 4096;

double sample_input(const InputDistribution& d, Rng& rng) {
  if (d.is_constant()) return d.mean();
  switch (d.kind()) {
    case InputDistribution::Kind::Normal:
      return d.mean() + d.stddev() * rng.normal();
    case InputDistribution::Kind::Uniform:
      return d.lo() + (d.hi() - d.lo()) * rng.uniform();
    case InputDistribution::Kind::TruncatedNormal:
      return d.quantile(rng.uniform());
  }
  return d.mean();
}

}  // namespace

ReliabilityResult monte_carlo(const StandardSpace& space, const ReliabilityOptions& options) {
  ReliabilityResult res;
  res.method = ReliabilityMethod::MonteCarlo;
  const ReliabilityProblem& problem = space.problem();
  const std::size_t N = options.samples;
  const std::size_t blocks = (N + kSamplesPerBlock - 1) / kSamplesPerBlock;
  std::vector<std::size_t> failures(blocks, 0), evals(blocks, 0);
  const double t = problem.tolerance;
  const bool two_sided = problem.limit == LimitKind::TwoSided;
  parallel_blocks(N, kSamplesPerBlock, options.threads,
                  [&](std::size_t block, std::size_t begin, std::size_t end, unsigned thread) {
                    Rng rng(options.seed, 0, block);
                    std::vector<double> x(problem.inputs.size());
                    std::size_t fail = 0;
                    for (std::size_t i = begin; i < end; ++i) {
                      for (std::size_t j = 0; j < x.size(); ++j)
                        x[j] = sample_input(problem.inputs[j], rng);
                      const double r = space.response(thread, x.data(), evals[block]);
                      if (two_sided ? !(std::abs(r) <= t) : !(r <= t)) ++fail;
                    }
                    failures[block] = fail;
                  });
  std::size_t k = 0;
  for (std::size_t b = 0; b < blocks; ++b) {
    k += failures[b];
    res.evaluations += evals[b];
  }
  const double n = static_cast<double>(N), p = static_cast<double>(k) / n;
  res.failure = p;
  res.reliability = 1.0 - p;
  if (k > 0) {
    res.cov = std::sqrt((1 - p) / (n * p));
  } else {
    res.cov = std::numeric_limits<double>::infinity();
    append_note(res.note, "MC: no failure sampled");
  }
  // Wilson score interval of the failure probability.
  const double z = confidence_z(options.confidence), z2 = z * z;
  const double centre = (p + z2 / (2 * n)) / (1 + z2 / n);
  const double half = z / (1 + z2 / n) * std::sqrt(p * (1 - p) / n + z2 / (4 * n * n));
  res.ci_lo = std::max(0.0, 1.0 - (centre + half));
  res.ci_hi = std::min(1.0, 1.0 - (centre - half));
  // Sensitivities and design points from FORM.
  const auto points = form_design_points(space, options, res.evaluations, res.note);
  for (const auto& fp : points) res.design_points.push_back(fp.point);
  form_sensitivities(space, points, res.dR_dmu, res.dR_dsigma);
  return res;
}

}  // namespace weilgen::reliability_detail
