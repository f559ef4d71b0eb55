#include "weilgen/codegen/model_eval.hpp"

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

}  // namespace weilgen::gen
