#include "weilgen/model/model.hpp"

#include <algorithm>
#include <stdexcept>

#include "weilgen/model/numeric_chain.hpp"

namespace weilgen {

namespace {
std::vector<double> default_parameters(const Description& desc) {
  const auto defaults = desc.parameter_defaults();
  std::vector<double> v;
  for (const auto& p : desc.parameters) v.push_back(defaults.at(p.name));
  return v;
}
}  // namespace

const char* engine_name(ModelEngine engine) {
  switch (engine) {
    case ModelEngine::BuiltIn:
      return "built-in";
    case ModelEngine::Compiled:
      return "compiled";
    case ModelEngine::NumericChain:
      return "numeric chain";
  }
  return "";
}

Model::Model(Description desc, const WeilgenModelAbi* abi, ModelEngine engine, std::string origin,
             std::shared_ptr<void> keep_alive)
    : desc_(std::move(desc)),
      order_(abi->order),
      engine_(engine),
      origin_(std::move(origin)),
      num_axes_(desc_.axes().size()),
      params_(default_parameters(desc_)),
      abi_(abi),
      keep_alive_(std::move(keep_alive)) {
  if (abi->num_axes != num_axes_ || abi->num_errors != desc_.errors.size() ||
      abi->num_params != params_.size())
    throw std::runtime_error("compiled model " + std::string(abi->name) +
                             " does not match its machine description (axes/errors/parameters)");
}

Model::Model(Description desc, int order, std::string origin)
    : desc_(std::move(desc)),
      order_(order),
      engine_(ModelEngine::NumericChain),
      origin_(std::move(origin)),
      num_axes_(desc_.axes().size()),
      params_(default_parameters(desc_)),
      chain_(std::make_unique<NumericChain>(desc_)) {}

Model::~Model() = default;

void Model::set_parameters(std::vector<double> values) {
  if (values.size() != params_.size())
    throw std::invalid_argument("set_parameters: expected " + std::to_string(params_.size()) +
                                " values");
  params_ = std::move(values);
  if (chain_) chain_->set_parameters(params_);
}

void Model::deviation(ModelData& data, const double* axes, const double* errors,
                      double* out6) const {
  if (abi_) {
    abi_->deviation(axes, errors, params_.data(), out6, out6 + 3);
    return;
  }
  data.chain_axes_.assign(axes, axes + num_axes_);
  data.chain_errors_.assign(errors, errors + num_errors());
  const std::array<double, 6> d = chain_->deviation(data.chain_axes_, data.chain_errors_);
  std::copy(d.begin(), d.end(), out6);
}

void Model::deviation_batch(ModelData& data, const double* axes, std::size_t count,
                            const double* errors, double* position, double* orientation) const {
  if (abi_) {
    abi_->deviation_batch(axes, params_.data(), count, errors, position, orientation);
    return;
  }
  for (std::size_t j = 0; j < count; ++j) {
    deviation(data, axes, errors + j * num_errors(), data.out.data());
    if (position) std::copy_n(data.out.begin(), 3, position + 3 * j);
    if (orientation) std::copy_n(data.out.begin() + 3, 3, orientation + 3 * j);
  }
}

void Model::coefficients(ModelData& data, const double* axes, double* coeff) const {
  const std::size_t ne = num_errors();
  if (abi_) {
    abi_->coefficients(axes, params_.data(), coeff, coeff + 3 * ne);
    return;
  }
  // Fourth-order central differences of the exact chain at zero error, step 1e-3 (mm or rad):
  // truncation ~h^4 relative, rounding ~1e-13 mm / h, both below 1e-9 of a coefficient.
  constexpr double h = 1e-3;
  data.chain_axes_.assign(axes, axes + num_axes_);
  data.chain_errors_.assign(ne, 0.0);
  const auto at = [&](std::size_t j, double v) {
    data.chain_errors_[j] = v;
    const std::array<double, 6> d = chain_->deviation(data.chain_axes_, data.chain_errors_);
    data.chain_errors_[j] = 0.0;
    return d;
  };
  for (std::size_t j = 0; j < ne; ++j) {
    const auto p1 = at(j, h), m1 = at(j, -h), p2 = at(j, 2 * h), m2 = at(j, -2 * h);
    for (std::size_t o = 0; o < 6; ++o)
      coeff[o * ne + j] = (8 * (p1[o] - m1[o]) - (p2[o] - m2[o])) / (12 * h);
  }
}

void Model::deviation_and_coefficients(ModelData& data, const double* axes, const double* errors,
                                       double* out6, double* coeff) const {
  if (abi_) {
    const std::size_t ne = num_errors();
    abi_->deviation_and_coefficients(axes, errors, params_.data(), out6, out6 ? out6 + 3 : nullptr,
                                     coeff, coeff ? coeff + 3 * ne : nullptr);
    return;
  }
  if (out6) deviation(data, axes, errors, out6);
  if (coeff) coefficients(data, axes, coeff);
}

ModelData::ModelData(const Model& model)
    : axes(model.num_axes(), 0.0),
      errors(model.num_errors(), 0.0),
      out(6, 0.0),
      coeff(6 * model.num_errors(), 0.0),
      chain_axes_(model.num_axes(), 0.0),
      chain_errors_(model.num_errors(), 0.0) {}

}  // namespace weilgen
