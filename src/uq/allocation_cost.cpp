// The cost-aware allocation: minimise sum_i w_i / sigma_i subject to the reliability targets
// (one constraint per case for the minimum, one per group for the mean) with NLopt's SLSQP and
// the gradients dR/dsigma of the cases, started from the step procedure's end point.
#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <nlopt.hpp>
#include <stdexcept>

#include "allocation_detail.hpp"
#include "weilgen/uq/allocation.hpp"

namespace weilgen {

using namespace allocation_detail;

namespace {

struct CostProblem {
  const AllocationProblem* problem;
  const AllocationOptions* options;
  std::vector<std::size_t> vars;  // inputs that are optimised (stddev > 0 at the start)
  std::vector<double> sigma0;     // every input's starting stddev (the variables' scale)
  std::vector<double> weights;    // every input
  std::vector<double> base;       // stddev of every input (non-variables fixed)
  double scale = 1;               // objective scale: the cost at the start point
  std::size_t evaluations = 0;
  std::size_t num_cases = 0;
  // The best point seen that meets every constraint.
  std::vector<double> best;
  double best_cost = std::numeric_limits<double>::infinity();
  std::exception_ptr error;

  std::vector<double> sigma_of(const double* y) const {
    std::vector<double> s(base);
    for (std::size_t j = 0; j < vars.size(); ++j) s[vars[j]] = y[j] * sigma0[vars[j]];
    return s;
  }
  double cost(const std::vector<double>& sigma) const {
    double c = 0;
    for (std::size_t i : vars) c += weights[i] / sigma[i];
    return c;
  }
  std::vector<AllocationCase> cases(const std::vector<double>& sigma) {
    ++evaluations;
    return evaluate_checked(*problem, with_stddevs(problem->inputs, sigma));
  }
  bool feasible(const std::vector<double>& sigma) {
    return group_stats(*problem, cases(sigma), *options).met;
  }
};

double objective(unsigned n, const double* y, double* grad, void* data) {
  auto* cp = static_cast<CostProblem*>(data);
  double f = 0;
  for (unsigned j = 0; j < n; ++j) {
    const std::size_t i = cp->vars[j];
    const double w = cp->weights[i] / cp->sigma0[i] / cp->scale;
    f += w / y[j];
    if (grad) grad[j] = -w / (y[j] * y[j]);
  }
  return f;
}

// result[c] = min_target - R_c (c < cases), result[cases + g] = mean_target - mean_g R.
void constraints(unsigned m, double* result, unsigned n, const double* y, double* grad,
                 void* data) {
  auto* cp = static_cast<CostProblem*>(data);
  try {
    const std::vector<double> sigma = cp->sigma_of(y);
    const std::vector<AllocationCase> cases = cp->cases(sigma);
    if (cases.size() != cp->num_cases)
      throw std::invalid_argument("allocation: evaluate returned a different number of cases");
    const std::size_t C = cases.size(), G = cp->problem->groups.size();
    std::vector<double> count(G, 0.0);
    for (unsigned k = 0; k < m; ++k) result[k] = 0;
    if (grad) std::fill(grad, grad + static_cast<std::size_t>(m) * n, 0.0);
    for (std::size_t c = 0; c < C; ++c) count[cases[c].group] += 1;
    for (std::size_t c = 0; c < C; ++c) {
      const std::size_t g = cases[c].group;
      result[c] = cp->options->min_target - cases[c].reliability;
      result[C + g] -= cases[c].reliability / count[g];
      if (grad) {
        for (unsigned j = 0; j < n; ++j) {
          const std::size_t i = cp->vars[j];
          const double d = cases[c].dR_dsigma[i] * cp->sigma0[i];  // dR/dy_j
          grad[c * n + j] = -d;
          grad[(C + g) * n + j] -= d / count[g];
        }
      }
    }
    for (std::size_t g = 0; g < G; ++g) result[C + g] += cp->options->mean_target;
    // Feasibility by the same arithmetic as the reported statistics.
    const bool ok = group_stats(*cp->problem, cases, *cp->options).met;
    if (ok) {
      const double cost = cp->cost(sigma);
      if (cost < cp->best_cost) {
        cp->best_cost = cost;
        cp->best = sigma;
      }
    }
  } catch (...) {
    cp->error = std::current_exception();
    throw nlopt::forced_stop();
  }
}

void append(std::string& note, const std::string& text) {
  if (!note.empty()) note += "; ";
  note += text;
}

}  // namespace

AllocationResult CostAwareAllocation::run(const AllocationProblem& problem,
                                          const AllocationResult& steps) const {
  const AllocationOptions& options = options_;
  validate(problem, options);
  const std::size_t n = problem.inputs.size();
  AllocationResult res = steps;
  CostProblem cp;
  cp.problem = &problem;
  cp.options = &options;
  cp.sigma0 = stddevs(problem.inputs);
  cp.weights = options.cost_weights.empty() ? std::vector<double>(n, 1.0) : options.cost_weights;
  const std::vector<double> sigma_step =
      steps.steps.empty() ? cp.sigma0 : steps.steps.back().stddev;
  if (sigma_step.size() != n) throw std::invalid_argument("allocation: steps of a wrong size");
  for (std::size_t i = 0; i < n; ++i)
    if (cp.sigma0[i] > 0) cp.vars.push_back(i);
  cp.base = cp.sigma0;
  res.cost_step = cp.cost(sigma_step);
  if (cp.vars.empty()) {
    append(res.note, "cost-aware: every input is constant");
    return res;
  }

  // Bounds and start (scaled variables y = sigma / sigma0).
  const std::size_t m = cp.vars.size();
  std::vector<double> lo(m), hi(m), y(m);
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t i = cp.vars[j];
    double l = options.sigma_lower.empty() ? std::min(0.01 * cp.sigma0[i], sigma_step[i])
                                           : options.sigma_lower[i];
    double h = options.sigma_upper.empty() ? cp.sigma0[i] : options.sigma_upper[i];
    if (!(l > 0) || !(h >= l) || !std::isfinite(h))
      throw std::invalid_argument("allocation: the sigma bounds of " + input_name(problem, i) +
                                  " must satisfy 0 < lower <= upper");
    lo[j] = l / cp.sigma0[i];
    hi[j] = h / cp.sigma0[i];
    y[j] = std::min(hi[j], std::max(lo[j], sigma_step[i] / cp.sigma0[i]));
  }
  const std::vector<double> start = cp.sigma_of(y.data());
  cp.scale = cp.cost(start);
  cp.num_cases = evaluate_checked(problem, problem.inputs).size();
  ++cp.evaluations;

  nlopt::opt opt(nlopt::LD_SLSQP, static_cast<unsigned>(m));
  opt.set_lower_bounds(lo);
  opt.set_upper_bounds(hi);
  opt.set_min_objective(objective, &cp);
  opt.add_inequality_mconstraint(constraints, &cp,
                                 std::vector<double>(cp.num_cases + problem.groups.size(), 1e-10));
  opt.set_xtol_rel(1e-7);
  opt.set_ftol_rel(1e-12);
  opt.set_maxeval(static_cast<int>(std::max<std::size_t>(1, options.cost_max_evaluations)));
  double fmin = 0;
  try {
    const nlopt::result r = opt.optimize(y, fmin);
    // NLopt's positive codes are successes: 1 success, 2 stopval, 3 ftol, 4 xtol reached.
    append(res.note, "cost-aware: SLSQP converged (NLopt result " +
                         std::to_string(static_cast<int>(r)) +
                         (r == nlopt::FTOL_REACHED      ? ", ftol reached)"
                          : r == nlopt::XTOL_REACHED    ? ", xtol reached)"
                          : r == nlopt::MAXEVAL_REACHED ? ", evaluation limit reached)"
                                                        : ")"));
  } catch (const nlopt::forced_stop&) {
    if (cp.error) std::rethrow_exception(cp.error);
    append(res.note, "cost-aware: SLSQP was stopped");
  } catch (const std::exception& e) {
    if (cp.error) std::rethrow_exception(cp.error);
    append(res.note, std::string("cost-aware: SLSQP failed (") + e.what() + ")");
  }

  // The optimiser's point may sit a hair outside an active constraint: bisect along the segment
  // towards a feasible point (the best one seen, else the start) for the nearest feasible one.
  std::vector<double> final_sigma = cp.sigma_of(y.data());
  if (!cp.feasible(final_sigma)) {
    const std::vector<double>* anchor = !cp.best.empty() ? &cp.best : nullptr;
    if (!anchor && cp.feasible(start)) anchor = &start;
    if (anchor) {
      double a = 0, b = 1;  // a infeasible, b feasible
      std::vector<double> s(n);
      for (int it = 0; it < 40; ++it) {
        const double c = 0.5 * (a + b);
        for (std::size_t i = 0; i < n; ++i) s[i] = (1 - c) * final_sigma[i] + c * (*anchor)[i];
        if (cp.feasible(s)) {
          b = c;
          if (cp.cost(s) < cp.best_cost) {
            cp.best_cost = cp.cost(s);
            cp.best = s;
          }
        } else {
          a = c;
        }
      }
      if (cp.best.empty()) cp.best = *anchor;
    }
  } else if (cp.cost(final_sigma) <= cp.best_cost) {
    cp.best = final_sigma;
    cp.best_cost = cp.cost(final_sigma);
  }
  const std::vector<double> chosen_sigma = cp.best.empty() ? final_sigma : cp.best;
  const GroupStats st = group_stats(problem, cp.cases(chosen_sigma), options);
  res.cost_aware_stddev = chosen_sigma;
  res.cost_aware = cp.cost(chosen_sigma);
  res.cost_aware_met = st.met;
  res.cost_aware_group_min = st.min;
  res.cost_aware_group_mean = st.mean;
  res.cost_aware_evaluations = cp.evaluations;
  if (!st.met) append(res.note, "cost-aware: no point meeting the targets was found");
  return res;
}

}  // namespace weilgen
