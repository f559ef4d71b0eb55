#include "weilgen/analysis/ballbar_model.hpp"

#include <stdexcept>
#include <string>
#include <utility>

#include "weilgen/model/numeric_chain.hpp"
#include "weilgen/uq/dense.hpp"

namespace weilgen {

BallbarMachine ballbar_machine(const Description& desc, const std::vector<double>& parameters) {
  BallbarMachine m;
  m.name = desc.name;
  for (int b : desc.axes()) {
    const Joint& j = desc.bodies[static_cast<std::size_t>(b)].joint;
    m.coordinates.push_back(j.coordinate);
    m.units.push_back(j.unit);
    m.to_base.push_back(j.to_base);
    m.prismatic.push_back(j.type == JointType::Prismatic);
    m.min.push_back(j.min);
    m.max.push_back(j.max);
  }
  auto chain = std::make_shared<NumericChain>(desc);
  if (!parameters.empty()) chain->set_parameters(parameters);
  const std::size_t num_axes = m.coordinates.size();
  m.nominal = [chain, num_axes](const double* axes, double* position_mm) {
    const std::vector<double> q(axes, axes + num_axes);
    const std::vector<double> zero(chain->num_errors(), 0.0);
    const Eigen::Matrix4d t = chain->tool_in_workpiece(q, zero);
    for (int k = 0; k < 3; ++k) position_mm[k] = t(k, 3);
  };
  return m;
}

BallbarMachine ballbar_machine(const Model& model) {
  return ballbar_machine(model.description(), model.parameters());
}

DeviationFn model_deviation(std::shared_ptr<const Model> model, std::vector<double> errors) {
  if (!model) throw std::invalid_argument("ballbar: no model");
  if (errors.size() != model->num_errors()) {
    throw std::invalid_argument("ballbar: " + std::to_string(errors.size()) + " error values for " +
                                std::to_string(model->num_errors()) + " errors of " +
                                model->name());
  }
  auto data = std::make_shared<ModelData>(*model);
  return [model, data, errors = std::move(errors)](const double* axes, double* out6) {
    model->deviation(*data, axes, errors.data(), out6);
  };
}

}  // namespace weilgen
