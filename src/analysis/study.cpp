#include "weilgen/analysis/study.hpp"

#include <stdexcept>

#include "weilgen/base/parallel.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/units.hpp"
#include "weilgen/codegen/generate.hpp"
#include "weilgen/machine/algebra_size.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/model/builtin_models.hpp"
#include "weilgen/model/model_loader.hpp"

namespace weilgen {

namespace {

GeneratedHeader generate_for_loader(const Description& d, int order) {
  GeneratedHeader h;
  h.text = gen::generate_header(d, order, &h.name_space);
  return h;
}

std::vector<double> parse_params(const Description& d, const std::vector<std::string>& flags,
                                 std::vector<double> values) {
  for (const auto& flag : flags) {
    const auto eq = flag.find('=');
    if (eq == std::string::npos)
      throw std::invalid_argument("--param: \"" + flag + "\": expected NAME=VALUE");
    const std::string name = trim(flag.substr(0, eq));
    std::size_t k = 0;
    while (k < d.parameters.size() && d.parameters[k].name != name) ++k;
    if (k == d.parameters.size()) {
      std::string known;
      for (const auto& p : d.parameters) known += (known.empty() ? "" : ", ") + p.name;
      throw std::invalid_argument("--param: unknown parameter \"" + name + "\" (machine " + d.name +
                                  " has " + (known.empty() ? "none" : known) + ")");
    }
    const std::string unit = d.parameters[k].unit;
    values[k] =
        parse_quantity_unit(flag.substr(eq + 1), unit, "--param " + name).in(parse_unit(unit));
  }
  return values;
}

}  // namespace

std::shared_ptr<Model> open_model(const StudyRequest& r, const Description& desc) {
  if (r.order < 0 || r.order > kMaxAlgebraOrder)
    throw std::invalid_argument("--order must be a whole number from 1 to " +
                                std::to_string(kMaxAlgebraOrder));
  // Too large: refused now; large: a warning when (and only when) the model is generated.
  const std::string size_warning =
      check_algebra_size(desc, r.order, "--order " + std::to_string(r.order));
  LoadOptions lo;
  lo.order = r.order;
  if (r.engine == "auto")
    lo.engine = EngineChoice::Auto;
  else if (r.engine == "compiled")
    lo.engine = EngineChoice::Compiled;
  else if (r.engine == "numeric")
    lo.engine = EngineChoice::Numeric;
  else
    throw std::invalid_argument("--engine must be auto, compiled or numeric, not '" + r.engine +
                                "'");
  lo.compiler = r.compiler;
  lo.builtins = builtin_models();
  lo.generate = [size_warning, log = r.log](const Description& d, int order) {
    if (!size_warning.empty() && log) log(size_warning);
    return generate_for_loader(d, order);
  };
  lo.log = r.log;
  std::shared_ptr<Model> model = load_model(desc, lo);
  // Parameters are part of what the machine is: set before the model is shared.
  if (!r.params.empty()) model->set_parameters(parse_params(desc, r.params, model->parameters()));
  return model;
}

namespace {
// Poses, distributions, tolerances and threads: checked before a model is compiled.
Study study_inputs(const StudyRequest& r, const Description& desc, bool need_tolerances) {
  Study s;
  s.poses = parse_poses(desc, r.at, r.grid);
  s.inputs = error_distributions(desc, r.tolerance_files, r.set);
  if (need_tolerances) {
    if (r.tolerance.empty()) throw std::invalid_argument("no --tolerance given (e.g. dx=0.03mm)");
    s.tolerances = parse_tolerances(r.tolerance);
  }
  s.threads = resolve_threads(r.threads);
  return s;
}
}  // namespace

Study open_study(const StudyRequest& r, bool need_tolerances) {
  if (r.machine.empty()) throw std::invalid_argument("no machine given");
  const Description desc = load_machine_file(resolve_machine(r.machine));
  // A model too large to generate is refused before the other inputs are read.
  if (r.order != 0) check_algebra_size(desc, r.order, "--order " + std::to_string(r.order));
  Study s = study_inputs(r, desc, need_tolerances);
  s.model = open_model(r, desc);
  return s;
}

Study open_study(const StudyRequest& r, std::shared_ptr<const Model> model, bool need_tolerances) {
  Study s = study_inputs(r, model->description(), need_tolerances);
  s.model = std::move(model);
  return s;
}

void MeasurementRequest::check_machine() const {
  if (model.machine.empty() && !opened) throw std::invalid_argument("no machine given");
}

Description MeasurementRequest::description() const {
  return opened ? opened->description() : load_machine_file(resolve_machine(model.machine));
}

std::vector<double> MeasurementRequest::parameters(const Description& desc) const {
  if (opened) return opened->parameters();
  std::vector<double> values;
  for (const Parameter& p : desc.parameters) values.push_back(p.value);
  return parse_params(desc, model.params, values);
}

std::shared_ptr<const Model> MeasurementRequest::open(const Description& desc) const {
  return opened ? opened : open_model(model, desc);
}

}  // namespace weilgen
