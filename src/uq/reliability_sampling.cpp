// Wang & Yuan 2021's axis-orthogonal importance sampling (eqs. 23-28). Work is cut into fixed
// blocks of lines with one random stream per block and per-block partial results combined in block
// order: bit-identical for any thread count.
#include <algorithm>
#include <boost/math/tools/toms748_solve.hpp>
#include <cmath>
#include <cstdint>
#include <limits>

#include "reliability_detail.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/base/parallel.hpp"
#include "weilgen/uq/reliability.hpp"

namespace weilgen::reliability_detail {

namespace {

constexpr std::size_t kLinesPerBlock = 64;
// A root is accepted without bracketing when |g| / |grad g*| is below this (u units).
constexpr double kRootAccept = 1e-13;

// Count, mean and sum of squared deviations, combined by Chan et al.'s pairwise formula.
struct Moments {
  double n = 0, mean = 0, m2 = 0;
  void add(double v) {
    n += 1;
    const double d = v - mean;
    mean += d / n;
    m2 += d * (v - mean);
  }
  void merge(const Moments& o) {
    if (o.n == 0) return;
    if (n == 0) {
      *this = o;
      return;
    }
    const double tot = n + o.n, d = o.mean - mean;
    mean += d * o.n / tot;
    m2 += o.m2 + d * d * n * o.n / tot;
    n = tot;
  }
};

struct LineResult {
  double h_hi = kInf;   // failure for s >= h_hi
  double h_lo = -kInf;  // failure for s <= h_lo
  bool root_failed = false;
  double probability() const { return std::min(1.0, normal_cdf(-h_hi) + normal_cdf(h_lo)); }
};

// The limit state along the line b + s alpha, normalised so that its slope at the design point
// is -1: phi(s) = g(b + s alpha) / |grad_u g(u*)|.
class Line {
 public:
  Line(const LimitState& g, const FormPoint& fp, unsigned thread, std::size_t& count)
      : g_(g),
        fp_(fp),
        thread_(thread),
        count_(count),
        u_(fp.u.size()),
        x_(g.space->num_inputs()) {}

  void set_base(const std::vector<double>& b) { b_ = &b; }

  double operator()(double s) {
    const auto& a = fp_.alpha;
    for (std::size_t k = 0; k < u_.size(); ++k) u_[k] = (*b_)[k] + s * a[k];
    return g_.value(thread_, u_.data(), x_.data(), count_) / fp_.grad_norm;
  }

  // Adds weight * (dg/dtheta) / (dg/ds) at the point s of the line for theta = every input's
  // mean and stddev: with weight phi(h) at an upper root (P = Phi(-h)) and -phi(h) at a lower
  // root (P = Phi(h)) this is the root's contribution to dP/dtheta, since dh/dtheta =
  // -(dg/dtheta) / (dg/ds). Returns false when dg/ds vanishes (a tangent line).
  bool add_derivatives(double s, double weight, std::vector<double>& dmu,
                       std::vector<double>& dsigma) {
    const StandardSpace& space = *g_.space;
    const auto& a = fp_.alpha;
    const auto& act = space.active();
    const auto& in = space.problem().inputs;
    for (std::size_t k = 0; k < u_.size(); ++k) u_[k] = (*b_)[k] + s * a[k];
    space.to_x(u_.data(), x_.data());
    grad_x_.resize(x_.size());
    space.gradient_x(thread_, x_.data(), grad_x_.data(), count_);
    double dg_ds = 0;
    for (std::size_t k = 0; k < act.size(); ++k)
      dg_ds += -g_.side * grad_x_[act[k]] * in[act[k]].dx_du(u_[k]) * a[k];
    if (!(std::abs(dg_ds) > 0) || !std::isfinite(dg_ds)) return false;
    const double w = weight / dg_ds;
    for (std::size_t i = 0; i < x_.size(); ++i) {
      const double dg = -g_.side * grad_x_[i];
      dmu[i] += w * dg;
      if (space.stddev(i) > 0) dsigma[i] += w * dg * (x_[i] - space.mean(i)) / space.stddev(i);
    }
    return true;
  }

 private:
  const LimitState& g_;
  const FormPoint& fp_;
  unsigned thread_;
  std::size_t& count_;
  const std::vector<double>* b_ = nullptr;
  std::vector<double> u_, x_, grad_x_;
};

// Root of phi in [lo, hi] where phi(lo) and phi(hi) differ in sign (TOMS 748).
double bracketed_root(Line& phi, double lo, double hi, double flo, double fhi, bool& failed) {
  if (flo == 0) return lo;
  if (fhi == 0) return hi;
  std::uintmax_t iters = 100;
  const auto tol = [](double a, double b) {
    return std::abs(b - a) <= 1e-11 * std::max(1.0, std::abs(a));
  };
  const auto r = boost::math::tools::toms748_solve([&](double s) { return phi(s); }, lo, hi, flo,
                                                   fhi, tol, iters);
  if (iters >= 100) failed = true;
  return 0.5 * (r.first + r.second);
}

// From a point (s, f) walks in direction dir (+1 or -1) until phi reaches the wanted side
// (failure: phi <= 0, or safe: phi > 0), with secant-predicted steps (overshoot 1.25) between
// kMinStep and kMaxStep so that safe or failure intervals wider than kMaxStep are not stepped
// over. On success (a, fa) is the last point before the change and (b, fb) the first after it.
constexpr double kMinStep = 1e-3, kMaxStep = 0.5;
bool walk(Line& phi, double s, double f, int dir, bool want_fail, double limit, double& a,
          double& fa, double& b, double& fb) {
  double step = std::min(kMaxStep, std::max(kMinStep, 1.25 * std::abs(f)));
  for (int i = 0; i < 1000; ++i) {
    const double sn = s + dir * step;
    if (dir > 0 ? sn > limit : sn < limit) return false;
    const double fn = phi(sn);
    if (want_fail ? fn <= 0 : fn > 0) {
      a = s;
      fa = f;
      b = sn;
      fb = fn;
      return true;
    }
    const double slope = (fn - f) / step;  // change of phi per unit moved along dir
    const bool toward = want_fail ? slope < 0 : slope > 0;
    const double predicted = toward ? std::abs(fn / slope) : 2 * step;
    step = std::min(kMaxStep, std::max(kMinStep, 1.25 * predicted));
    s = sn;
    f = fn;
  }
  return false;
}

// The roots along one line. The safe set along the line is taken to be one interval: the upper
// root h_hi is searched from the design point's level beta, upwards when beta is safe and
// downwards when it fails; with `scan_lower` the line is also walked downwards from the safe
// interval for a failure region below it (h_lo). Failure beyond |beta| + 6 is neglected
// (Phi(-|beta| - 6) / Phi(-|beta|) < 1e-8).
LineResult line_roots(Line& phi, double beta, bool scan_lower) {
  LineResult res;
  const double lim = std::abs(beta) + 6;
  const double s0 = beta;
  const double f0 = phi(s0);
  double safe = s0, fsafe = f0;  // a safe point below h_hi, where the lower walk starts
  double a, fa, b, fb;
  if (std::abs(f0) <= kRootAccept) {
    res.h_hi = s0;
    if (!scan_lower) return res;
    safe = s0 - kMinStep;
    fsafe = phi(safe);
    if (fsafe <= 0) return res;  // a touching point: no safe interval to walk down from
  } else if (f0 > 0) {
    if (walk(phi, s0, f0, +1, true, lim, a, fa, b, fb))
      res.h_hi = bracketed_root(phi, a, b, fa, fb, res.root_failed);
  } else {
    if (!walk(phi, s0, f0, -1, false, -lim, a, fa, b, fb)) {  // no safe point on the line
      res.h_hi = -kInf;
      return res;
    }
    res.h_hi = bracketed_root(phi, b, a, fb, fa, res.root_failed);
    safe = b;
    fsafe = fb;
  }
  if (scan_lower && walk(phi, safe, fsafe, -1, true, -lim, a, fa, b, fb))
    res.h_lo = bracketed_root(phi, b, a, fb, fa, res.root_failed);
  return res;
}

// A base point H~ p~ orthogonal to alpha: the first n-1 columns of the Householder reflection H
// with H alpha = -sign(alpha_n) e_n (stable for any alpha), applied to p~.
struct Rotation {
  std::vector<double> v;
  double vv = 1;
  explicit Rotation(const std::vector<double>& alpha) : v(alpha) {
    v.back() += alpha.back() >= 0 ? 1.0 : -1.0;
    vv = 0;
    for (double c : v) vv += c * c;
  }
  // b = H (p~, 0).
  void base(const double* p, std::vector<double>& b) const {
    const std::size_t n = v.size();
    double vp = 0;
    for (std::size_t k = 0; k + 1 < n; ++k) vp += v[k] * p[k];
    const double f = 2 * vp / vv;
    for (std::size_t k = 0; k + 1 < n; ++k) b[k] = p[k] - f * v[k];
    b[n - 1] = -f * v[n - 1];
  }
};

struct SideEstimate {
  Moments m;
  std::vector<double> dmu, dsigma;  // dP_side/dtheta (sampling sensitivities)
  std::size_t root_failures = 0;
  bool scanned_lower = false;
};

// One line's probability, and with `derivs` its contributions to dP/dtheta.
double line_probability(Line& phi, double beta, bool scan_lower, bool derivs,
                        std::vector<double>& dmu, std::vector<double>& dsigma,
                        std::size_t& failures) {
  const LineResult r = line_roots(phi, beta, scan_lower);
  bool failed = r.root_failed;
  if (derivs) {
    if (std::isfinite(r.h_hi) && !phi.add_derivatives(r.h_hi, normal_pdf(r.h_hi), dmu, dsigma))
      failed = true;
    if (std::isfinite(r.h_lo) && !phi.add_derivatives(r.h_lo, -normal_pdf(r.h_lo), dmu, dsigma))
      failed = true;
  }
  if (failed) ++failures;
  return r.probability();
}

SideEstimate sample_side(const StandardSpace& space, const FormPoint& fp, bool has_mirror,
                         std::size_t stream, const ReliabilityOptions& options,
                         std::size_t& evaluations) {
  SideEstimate est;
  const std::size_t n = space.dim(), ni = space.num_inputs();
  const bool derivs = options.sensitivities == SensitivityMethod::Sampling;
  est.dmu.assign(ni, 0.0);
  est.dsigma.assign(ni, 0.0);
  const LimitState g{&space, fp.point.side, space.problem().tolerance};
  const double beta = fp.point.beta;
  // The central line (p~ = 0) decides whether lines must also be scanned below the design point.
  std::vector<double> zero(n, 0.0);
  Line central(g, fp, 0, evaluations);
  central.set_base(zero);
  if (n == 1) {  // a single line, walked both ways: no sampling needed
    est.m.n = static_cast<double>(options.samples);
    est.m.mean =
        line_probability(central, beta, true, derivs, est.dmu, est.dsigma, est.root_failures);
    return est;
  }
  est.scanned_lower = has_mirror || line_roots(central, beta, true).h_lo > -kInf;
  const Rotation rot(fp.alpha);
  const std::size_t N = options.samples;
  const std::size_t blocks = (N + kLinesPerBlock - 1) / kLinesPerBlock;
  std::vector<Moments> moments(blocks);
  std::vector<std::size_t> evals(blocks, 0), fails(blocks, 0);
  std::vector<std::vector<double>> dmu(derivs ? blocks : 0), dsigma(derivs ? blocks : 0);
  parallel_blocks(N, kLinesPerBlock, options.threads,
                  [&](std::size_t block, std::size_t begin, std::size_t end, unsigned thread) {
                    Rng rng(options.seed, stream, block);
                    std::vector<double> p(n - 1), b(n), bm(ni, 0.0), bs(ni, 0.0);
                    Line phi(g, fp, thread, evals[block]);
                    phi.set_base(b);
                    for (std::size_t i = begin; i < end; ++i) {
                      for (auto& v : p) v = rng.normal();
                      rot.base(p.data(), b);
                      moments[block].add(line_probability(phi, beta, est.scanned_lower, derivs, bm,
                                                          bs, fails[block]));
                    }
                    if (derivs) {
                      dmu[block] = std::move(bm);
                      dsigma[block] = std::move(bs);
                    }
                  });
  for (std::size_t k = 0; k < blocks; ++k) {
    est.m.merge(moments[k]);
    evaluations += evals[k];
    est.root_failures += fails[k];
    if (derivs) {
      for (std::size_t i = 0; i < ni; ++i) {
        est.dmu[i] += dmu[k][i];
        est.dsigma[i] += dsigma[k][i];
      }
    }
  }
  for (std::size_t i = 0; i < ni; ++i) {
    est.dmu[i] /= static_cast<double>(N);
    est.dsigma[i] /= static_cast<double>(N);
  }
  return est;
}

}  // namespace

ReliabilityResult importance_sampling(const StandardSpace& space,
                                      const ReliabilityOptions& options) {
  ReliabilityResult res;
  res.method = ReliabilityMethod::ImportanceSampling;
  const auto points = form_design_points(space, options, res.evaluations, res.note);
  double pf = 0, var = 0;
  std::size_t root_failures = 0, stream = 0;
  const std::size_t ni = space.num_inputs();
  std::vector<double> dP_dmu(ni, 0.0), dP_dsigma(ni, 0.0);
  for (std::size_t k = 0; k < points.size(); ++k) {
    const FormPoint& fp = points[k];
    if (k > 0 && points[k - 1].point.side == fp.point.side) continue;  // a mirror lobe
    ++stream;
    const double beta = fp.point.beta;
    if (std::isinf(beta) || !(fp.grad_norm > 0)) {
      pf += normal_cdf(-beta);
      continue;
    }
    const bool has_mirror = k + 1 < points.size() && points[k + 1].point.side == fp.point.side;
    const SideEstimate est = sample_side(space, fp, has_mirror, stream, options, res.evaluations);
    pf += est.m.mean;
    if (est.m.n > 1) var += est.m.m2 / (est.m.n - 1) / est.m.n;
    root_failures += est.root_failures;
    for (std::size_t i = 0; i < ni; ++i) {
      dP_dmu[i] += est.dmu[i];
      dP_dsigma[i] += est.dsigma[i];
    }
    if (est.scanned_lower)
      append_note(res.note, "IS side " + std::string(fp.point.side > 0 ? "+1" : "-1") +
                                ": failure also below the design point, lines scanned both ways");
  }
  if (root_failures > 0)
    append_note(res.note, "IS: " + std::to_string(root_failures) +
                              " lines had a root that did not converge or a tangent crossing");
  const double se = std::sqrt(var);
  res.failure = std::min(1.0, pf);
  res.reliability = 1.0 - res.failure;
  res.cov = res.failure > 0 ? se / res.failure : 0.0;
  const double z = confidence_z(options.confidence);
  res.ci_lo = std::max(0.0, 1.0 - (res.failure + z * se));
  res.ci_hi = std::min(1.0, 1.0 - (res.failure - z * se));
  for (const auto& p : points) res.design_points.push_back(p.point);
  if (options.sensitivities == SensitivityMethod::Sampling) {
    res.dR_dmu.resize(ni);
    res.dR_dsigma.resize(ni);
    for (std::size_t i = 0; i < ni; ++i) {
      res.dR_dmu[i] = -dP_dmu[i];
      res.dR_dsigma[i] = -dP_dsigma[i];
    }
  } else {
    form_sensitivities(space, points, res.dR_dmu, res.dR_dsigma);
  }
  return res;
}

}  // namespace weilgen::reliability_detail
