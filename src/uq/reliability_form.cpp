// FORM: improved HL-RF (Zhang & Der Kiureghian 1995: the HL-RF direction with an Armijo step on
// the merit m(u) = |u|^2/2 + c |g(u)|) in standard normal space, the design points of every
// failure side, and the FORM sensitivities dR/dmu, dR/dsigma.
#include <algorithm>
#include <cmath>
#include <limits>

#include "reliability_detail.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/uq/reliability.hpp"

namespace weilgen::reliability_detail {

namespace {

// Beyond this distance from the origin Phi(-|u|) underflows: the side has no failure point.
constexpr double kFarAway = 37.5;

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}
double norm(const std::vector<double>& a) { return std::sqrt(dot(a, a)); }

// dg/du from dr/dx at u.
void gradient_u(const LimitState& g, const std::vector<double>& u,
                const std::vector<double>& grad_x, std::vector<double>& grad_u) {
  const auto& act = g.space->active();
  const auto& in = g.space->problem().inputs;
  for (std::size_t k = 0; k < act.size(); ++k)
    grad_u[k] = -g.side * grad_x[act[k]] * in[act[k]].dx_du(u[k]);
}

std::string side_name(int side) { return side > 0 ? "+1" : "-1"; }

}  // namespace

FormPoint run_form(const LimitState& g, const std::vector<double>& start,
                   const ReliabilityOptions& options, std::size_t& count) {
  const StandardSpace& space = *g.space;
  const std::size_t n = space.dim();
  std::vector<double> u(start), gu(n), x(space.num_inputs()), gx(space.num_inputs());
  std::vector<double> un(n), xn(space.num_inputs()), d(n);
  double gval = g.value_gradient(0, u.data(), gu.data(), x.data(), gx.data(), count);
  const double scale = norm(gu);  // g is normalised by the start's gradient: u units
  FormPoint fp;
  fp.point.side = g.side;
  int it = 0;
  bool converged = false, lost = false;
  if (!(scale > 0) || !std::isfinite(scale)) {
    fp.note = "zero gradient at the start";
    lost = true;
  } else {
    for (it = 1; it <= options.form_max_iterations; ++it) {
      const double gt = gval / scale;
      const double gn = norm(gu) / scale;
      if (!(gn > 0) || !std::isfinite(gn)) {
        lost = true;
        fp.note = "zero gradient";
        break;
      }
      // HL-RF: the point of the linearised surface nearest the origin, reached by u + d.
      double gu_u = 0;
      for (std::size_t k = 0; k < n; ++k) gu_u += gu[k] / scale * u[k];
      const double coef = (gu_u - gt) / (gn * gn);
      for (std::size_t k = 0; k < n; ++k) d[k] = coef * gu[k] / scale - u[k];
      // Converged when the point is on the surface to form_tolerance and the HL-RF step is below
      // sqrt(form_tolerance): beta is stationary, its error is of the order of the step squared
      // (near-spherical limit states converge in direction only linearly).
      const double unorm = norm(u), ref = std::max(1.0, unorm);
      if (std::abs(gt) <= options.form_tolerance * ref &&
          norm(d) <= std::sqrt(options.form_tolerance) * ref) {
        converged = true;
        break;
      }
      // Armijo step on the merit function; d is a descent direction when c > |u| / |grad g|.
      const double c = 2 * unorm / gn + 10;
      const double m0 = 0.5 * unorm * unorm + c * std::abs(gt);
      const double slope = std::min(0.0, dot(u, d) - c * std::abs(gt));
      double lambda = 1, g_new = 0;
      bool accepted = false;
      for (int ls = 0; ls < 40; ++ls, lambda *= 0.5) {
        for (std::size_t k = 0; k < n; ++k) un[k] = u[k] + lambda * d[k];
        g_new = g.value(0, un.data(), xn.data(), count);
        if (!std::isfinite(g_new)) continue;
        const double m1 = 0.5 * dot(un, un) + c * std::abs(g_new / scale);
        if (m1 <= m0 + 1e-4 * lambda * slope) {
          accepted = true;
          break;
        }
      }
      if (!accepted) {
        // At the precision of the merit function: converged when the step is small.
        converged = norm(d) <= std::sqrt(options.form_tolerance) * std::max(1.0, unorm);
        if (!converged) fp.note = "the line search found no decrease";
        break;
      }
      u.swap(un);
      x.swap(xn);
      gval = g_new;
      space.gradient_x(0, x.data(), gx.data(), count);
      gradient_u(g, u, gx, gu);
      if (norm(u) > kFarAway) {
        lost = true;
        break;
      }
    }
  }
  it = std::min(it, options.form_max_iterations);
  const double gnorm = norm(gu);
  fp.u = u;
  fp.grad_x = gx;
  fp.grad_norm = gnorm;
  fp.alpha.assign(n, 0.0);
  if (gnorm > 0 && std::isfinite(gnorm))
    for (std::size_t k = 0; k < n; ++k) fp.alpha[k] = -gu[k] / gnorm;
  double beta = dot(fp.alpha, u);
  if (lost && (norm(u) > kFarAway || gnorm == 0)) {
    // No failure point within reach (g > 0) or nothing but failure (g <= 0).
    beta = gval > 0 ? kInf : -kInf;
  } else if (!converged && fp.note.empty()) {
    fp.note = "did not converge in " + std::to_string(options.form_max_iterations) + " iterations";
  }
  // Public form, indexed like the inputs.
  DesignPoint& p = fp.point;
  p.u.assign(space.num_inputs(), 0.0);
  p.alpha.assign(space.num_inputs(), 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    p.u[space.active()[k]] = u[k];
    p.alpha[space.active()[k]] = fp.alpha[k];
  }
  p.x = x;
  p.beta = beta;
  p.converged = converged;
  p.iterations = it;
  return fp;
}

std::vector<FormPoint> form_design_points(const StandardSpace& space,
                                          const ReliabilityOptions& options, std::size_t& count,
                                          std::string& note) {
  const ReliabilityProblem& problem = space.problem();
  const std::size_t n = space.dim();
  // A fixed direction for restarts when the gradient vanishes at the origin (e.g. a norm of
  // zero-mean outputs).
  std::vector<double> w(n);
  Rng rng(0x5eed, 0, 0);
  for (auto& v : w) v = rng.normal();
  const double wn = norm(w);
  for (auto& v : w) v /= wn;

  std::vector<FormPoint> points;
  const std::vector<int> sides =
      problem.limit == LimitKind::TwoSided ? std::vector<int>{+1, -1} : std::vector<int>{+1};
  for (int side : sides) {
    const LimitState g{&space, side, problem.tolerance};
    FormPoint fp = run_form(g, std::vector<double>(n, 0.0), options, count);
    for (double r : {0.5, 2.0}) {
      if (fp.note != "zero gradient at the start") break;
      std::vector<double> start(w);
      for (auto& v : start) v *= r;
      fp = run_form(g, start, options, count);
    }
    const std::string tag = "FORM side " + side_name(side) + ": ";
    if (!fp.note.empty()) append_note(note, tag + fp.note);
    if (std::isinf(fp.point.beta))
      append_note(note, tag + (fp.point.beta > 0 ? "no failure point found (P_f,side = 0)"
                                                 : "no safe point found (P_f,side = 1)"));
    points.push_back(fp);
    // A mirror lobe: HL-RF restarted from -u*. Kept when it converges on the other hemisphere.
    if (fp.point.converged && std::isfinite(fp.point.beta) && std::abs(fp.point.beta) > 1e-6) {
      std::vector<double> start(fp.u);
      for (auto& v : start) v = -v;
      FormPoint mirror = run_form(g, start, options, count);
      if (mirror.point.converged && std::isfinite(mirror.point.beta) &&
          dot(mirror.alpha, fp.alpha) < 0) {
        append_note(note, tag + "a second (mirror) design point, beta " +
                              std::to_string(mirror.point.beta));
        points.push_back(mirror);
      }
    }
  }
  return points;
}

double form_failure(const std::vector<FormPoint>& points) {
  double pf = 0;
  for (const auto& p : points) pf += normal_cdf(-p.point.beta);
  return std::min(1.0, pf);
}

void form_sensitivities(const StandardSpace& space, const std::vector<FormPoint>& points,
                        std::vector<double>& dR_dmu, std::vector<double>& dR_dsigma) {
  const auto& in = space.problem().inputs;
  dR_dmu.assign(in.size(), 0.0);
  dR_dsigma.assign(in.size(), 0.0);
  for (const auto& p : points) {
    const double beta = p.point.beta;
    if (!std::isfinite(beta) || !(p.grad_norm > 0)) continue;
    // dR/dtheta = phi(beta) dbeta/dtheta, dbeta/dtheta = (dg/dtheta) / |grad_u g| with
    // x = mu + sigma z(u): dg/dmu_i = dg/dx_i, dg/dsigma_i = dg/dx_i (x_i* - mu_i) / sigma_i.
    const double w = normal_pdf(beta) / p.grad_norm;
    for (std::size_t i = 0; i < in.size(); ++i) {
      const double dg_dx = -p.point.side * p.grad_x[i];
      dR_dmu[i] += w * dg_dx;
      if (!in[i].is_constant())
        dR_dsigma[i] += w * dg_dx * (p.point.x[i] - space.mean(i)) / space.stddev(i);
    }
  }
}

ReliabilityResult form_reliability(const StandardSpace& space, const ReliabilityOptions& options) {
  ReliabilityResult res;
  res.method = ReliabilityMethod::Form;
  const auto points = form_design_points(space, options, res.evaluations, res.note);
  res.failure = form_failure(points);
  res.reliability = 1.0 - res.failure;
  res.ci_lo = res.ci_hi = res.reliability;
  for (const auto& p : points) res.design_points.push_back(p.point);
  form_sensitivities(space, points, res.dR_dmu, res.dR_dsigma);
  return res;
}

}  // namespace weilgen::reliability_detail
