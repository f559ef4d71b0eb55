// How error parameters θ give error values at a pose (ErrorParameterisation), and the --pdge
// flags that choose each PDGE's basis: shared by identify, gap and plan.
#include "weilgen/analysis/error_parameterisation.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/machine/derived.hpp"

namespace weilgen {

namespace {

int error_of_name(const Description& d, const std::string& name, const std::string& what) {
  const int k = d.error_index(name);
  if (k < 0)
    throw std::invalid_argument(what + ": unknown error '" + name + "' (machine " + d.name +
                                " has " + join(error_names(d)) + ")");
  return k;
}

// The joint with the range its link takes over the corners of the independent axes' travel
// (exact for a link linear in each axis, as Y23.2 = -Y23.1 or A12 = A04).
Joint linked_range(const Description& d, const Joint& j, const std::vector<double>& params) {
  Joint out = j;
  const std::vector<int> axes = d.axes();
  double lo = INFINITY, hi = -INFINITY;
  const std::size_t n = axes.size();
  for (std::size_t corner = 0; corner < (std::size_t{1} << std::min<std::size_t>(n, 16));
       ++corner) {
    std::map<std::string, double> values;
    for (std::size_t p = 0; p < d.parameters.size(); ++p)
      values[d.parameters[p].name] = p < params.size() ? params[p] : d.parameters[p].value;
    for (std::size_t a = 0; a < n; ++a) {
      const Joint& ja = d.bodies[static_cast<std::size_t>(axes[a])].joint;
      values[ja.coordinate] = (corner >> a) & 1 ? ja.max : ja.min;
    }
    resolve_links(d, values);
    lo = std::min(lo, values.at(j.coordinate));
    hi = std::max(hi, values.at(j.coordinate));
  }
  out.min = lo;
  out.max = hi;
  return out;
}

}  // namespace

PdgeBasisChoice parse_pdge_flags(const Description& desc, const std::vector<std::string>& flags,
                                 PdgeBasisChoice base) {
  for (const std::string& flag : flags) {
    const auto eq = flag.find('=');
    const std::string what = "--pdge \"" + flag + "\"";
    try {
      if (eq == std::string::npos) {
        parse_basis(trim(flag));
        base.all = trim(flag);
      } else {
        const std::string name = trim(flag.substr(0, eq)), spec = trim(flag.substr(eq + 1));
        const int k = error_of_name(desc, name, what);
        parse_basis(spec);
        base.per_error.emplace_back(desc.errors[static_cast<std::size_t>(k)].name, spec);
      }
    } catch (const std::invalid_argument& e) {
      const std::string m = e.what();
      throw std::invalid_argument(m.rfind("--pdge", 0) == 0 ? m : what + ": " + m);
    }
  }
  return base;
}

ErrorParameterisation::ErrorParameterisation(const Description& desc, const PdgeBasisChoice& choice,
                                             std::vector<double> parameters)
    : desc_(&desc), param_values_(std::move(parameters)) {
  if (param_values_.empty())
    for (const Parameter& p : desc.parameters) param_values_.push_back(p.value);
  const std::vector<int> axes = desc.axes();
  const std::size_t ne = desc.errors.size();
  bases_.resize(ne);
  first_.resize(ne);
  axis_index_.assign(ne, -1);
  coordinate_.resize(ne);
  to_base_.resize(ne);
  for (std::size_t k = 0; k < ne; ++k) {
    const ErrorDef& e = desc.errors[k];
    to_base_[k] = e.to_base;
    first_[k] = params_.size();
    const Joint& j = desc.bodies[static_cast<std::size_t>(e.body)].joint;
    if (e.dependence == Dependence::PIGE || j.type == JointType::Fixed) {
      params_.push_back({static_cast<int>(k), 0, e.name, e.unit});
      continue;
    }
    // Precedence: per-error flag, run-wide flag, the error's basis, the machine's, fallback.
    std::string spec = choice.fallback.empty() ? default_pdge_basis(j) : choice.fallback;
    SourceLoc where;
    const bool rotary = j.type == JointType::Revolute;
    const std::string& machine = rotary ? desc.pdge_basis_revolute : desc.pdge_basis;
    if (!machine.empty())
      spec = machine, where = rotary ? desc.pdge_basis_revolute_loc : desc.pdge_basis_loc;
    if (!e.basis.empty()) spec = e.basis, where = e.basis_loc;
    if (choice.all) spec = *choice.all, where = {};
    for (const auto& [name, s] : choice.per_error)
      if (name == e.name) spec = s, where = {};
    // A linked joint without a range of its own takes its link's range over the travel.
    Joint placed = j;
    if (!(j.max > j.min) && j.link) placed = linked_range(desc, j, param_values_);
    if (!(placed.max > placed.min)) {
      throw InputError(j.loc, "joint " + j.coordinate + ": " + e.name +
                                  " is position dependent but the joint has no travel range "
                                  "(range: [min, max]) to place its basis on");
    }
    try {
      bases_[k] = basis_on_joint(parse_basis(spec), placed);
    } catch (const std::invalid_argument& ex) {
      if (where.line > 0) throw InputError(where, ex.what());
      throw std::invalid_argument(e.name + ": " + ex.what());
    }
    coordinate_[k] = j.coordinate;
    for (std::size_t a = 0; a < axes.size(); ++a)
      if (axes[a] == e.body) axis_index_[k] = static_cast<int>(a);
    const std::vector<std::string> names = bases_[k]->term_names();
    for (std::size_t t = 0; t < names.size(); ++t)
      params_.push_back({static_cast<int>(k), t, e.name + "[" + names[t] + "]", e.unit});
  }
}

double ErrorParameterisation::position_of(std::size_t k, const double* axes) const {
  if (axis_index_[k] >= 0) return axes[axis_index_[k]];
  // A linked coordinate: evaluate the links from the independent axes and the parameters.
  std::map<std::string, double> values;
  for (std::size_t p = 0; p < desc_->parameters.size(); ++p)
    values[desc_->parameters[p].name] = param_values_[p];
  const std::vector<int> ax = desc_->axes();
  for (std::size_t a = 0; a < ax.size(); ++a)
    values[desc_->bodies[static_cast<std::size_t>(ax[a])].joint.coordinate] = axes[a];
  resolve_links(*desc_, values);
  return values.at(coordinate_[k]);
}

void ErrorParameterisation::derivatives(const double* axes, double* jac) const {
  for (std::size_t k = 0; k < bases_.size(); ++k) {
    double* out = jac + first_[k];
    if (!bases_[k]) {
      out[0] = to_base_[k];
      continue;
    }
    bases_[k]->evaluate(position_of(k, axes), out);
    for (std::size_t t = 0; t < bases_[k]->size(); ++t) out[t] *= to_base_[k];
  }
}

void ErrorParameterisation::errors_at(const double* axes, const double* theta,
                                      double* errors) const {
  std::vector<double> jac(params_.size());
  derivatives(axes, jac.data());
  std::fill(errors, errors + bases_.size(), 0.0);
  for (std::size_t p = 0; p < params_.size(); ++p) errors[params_[p].error] += jac[p] * theta[p];
}

}  // namespace weilgen
