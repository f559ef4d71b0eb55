// A real machine's ballbar geometry and deviation, from its description and model: the
// measure layer's ballbar functions (weilgen/measure/ballbar.hpp) take these as callbacks.
#pragma once

#include <memory>
#include <vector>

#include "weilgen/machine/description.hpp"
#include "weilgen/measure/ballbar.hpp"
#include "weilgen/model/model.hpp"

namespace weilgen {

// The machine's axes, units and ranges; nominal kinematics from the exact numeric chain at zero
// errors with these parameter values (Description::parameters order; empty: the defaults).
BallbarMachine ballbar_machine(const Description& desc, const std::vector<double>& parameters = {});
// As above with the model's description and parameter values.
BallbarMachine ballbar_machine(const Model& model);

// A deviation callback over a model with fixed errors (base units, Description::errors order).
// Holds its own ModelData: one callback per thread.
DeviationFn model_deviation(std::shared_ptr<const Model> model, std::vector<double> errors);

}  // namespace weilgen
