#include "weilgen/codegen/model_eval.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace weilgen::gen {

std::array<double, 6> evaluate_model(const SymbolicModel& m, const std::vector<double>& axes,
                                     const std::vector<double>& errors,
                                     const std::vector<double>& params) {
  if (axes.size() != m.axes.size() || errors.size() != m.errors.size())
    throw std::invalid_argument("evaluate_model: wrong number of axes or errors");
  GiNaC::exmap values;
  for (std::size_t i = 0; i < m.axes.size(); ++i) {
    const auto& a = m.axes[i];
    values[a.coordinate] = axes[i];
    if (a.revolute) {
      const double q = axes[i] * m.desc.bodies[a.body].joint.to_base;
      values[a.cos] = std::cos(q);
      values[a.sin] = std::sin(q);
    }
  }
  for (std::size_t i = 0; i < m.errors.size(); ++i) values[m.errors[i]] = errors[i];
  const auto defaults = m.desc.parameter_defaults();
  for (std::size_t i = 0; i < m.params.size(); ++i)
    values[m.params[i]] = params.empty() ? defaults.at(m.desc.parameters[i].name) : params.at(i);
  for (const Reciprocal& r : m.reciprocals)
    values[r.symbol] = GiNaC::pow(r.divisor.subs(values), -1);
  std::array<double, 6> out{};
  for (int o = 0; o < kNumDeviationOutputs; ++o) {
    const GiNaC::ex v = m.outputs[o].to_ex(m.errors).subs(values).evalf();
    if (!GiNaC::is_a<GiNaC::numeric>(v))
      throw std::runtime_error("evaluate_model: output did not evaluate to a number");
    out[o] = GiNaC::ex_to<GiNaC::numeric>(v).to_double();
  }
  return out;
}

CoefficientEvaluator::CoefficientEvaluator(const SymbolicModel& m, const std::vector<double>& axes,
                                           const std::vector<double>& params) {
  if (axes.size() != m.axes.size())
    throw std::invalid_argument("CoefficientEvaluator: wrong number of axes");
  const auto set = [&](const GiNaC::ex& s, double v) {
    symbols_[s] = v;
    exact_[s] = v;
  };
  for (std::size_t i = 0; i < m.axes.size(); ++i) {
    const auto& a = m.axes[i];
    set(a.coordinate, axes[i]);
    if (a.revolute) {
      const double q = axes[i] * m.desc.bodies[a.body].joint.to_base;
      set(a.cos, std::cos(q));
      set(a.sin, std::sin(q));
    }
  }
  const auto defaults = m.desc.parameter_defaults();
  for (std::size_t i = 0; i < m.params.size(); ++i)
    set(m.params[i], params.empty() ? defaults.at(m.desc.parameters[i].name) : params.at(i));
  for (const Reciprocal& r : m.reciprocals) set(r.symbol, 1 / walk(r.divisor));
}

double CoefficientEvaluator::operator()(const GiNaC::ex& c) {
  const auto it = memo_.find(c);
  if (it != memo_.end()) return it->second;
  const double v = walk(c);
  memo_.emplace(c, v);
  return v;
}

double CoefficientEvaluator::walk(const GiNaC::ex& e) {
  if (GiNaC::is_a<GiNaC::numeric>(e)) return GiNaC::ex_to<GiNaC::numeric>(e).to_double();
  if (GiNaC::is_a<GiNaC::symbol>(e)) {
    const auto it = symbols_.find(e);
    if (it == symbols_.end())
      throw std::invalid_argument("CoefficientEvaluator: no value for " +
                                  GiNaC::ex_to<GiNaC::symbol>(e).get_name());
    return it->second;
  }
  if (GiNaC::is_a<GiNaC::add>(e) || GiNaC::is_a<GiNaC::mul>(e)) {
    // Operands in GiNaC's order vary between runs; sorted values round the same every time.
    std::vector<double> v(e.nops());
    for (std::size_t i = 0; i < e.nops(); ++i) v[i] = walk(e.op(i));
    std::sort(v.begin(), v.end());
    const bool sum = GiNaC::is_a<GiNaC::add>(e);
    double r = sum ? 0 : 1;
    for (double x : v) r = sum ? r + x : r * x;
    return r;
  }
  if (GiNaC::is_a<GiNaC::power>(e)) return std::pow(walk(e.op(0)), walk(e.op(1)));
  // Functions of linked angles, constants such as Pi: GiNaC's numeric evaluation.
  const GiNaC::ex v = e.subs(exact_, GiNaC::subs_options::no_pattern).evalf();
  if (!GiNaC::is_a<GiNaC::numeric>(v))
    throw std::runtime_error("CoefficientEvaluator: a coefficient did not evaluate to a number");
  return GiNaC::ex_to<GiNaC::numeric>(v).to_double();
}

}  // namespace weilgen::gen
