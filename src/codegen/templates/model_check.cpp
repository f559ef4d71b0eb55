// The model header template (templates/model.hpp) compiled on its own, as the stand-in model its
// blocks hold, with the strict flags of a controller build (CTest model_template): its fixed
// text is valid C++ and its tables agree with its counts.
#include "model.hpp"

namespace model = weilgen_models::standin;

static_assert(model::kAxes.size() == model::kNumAxes, "kAxes has kNumAxes rows");
static_assert(model::kErrors.size() == model::kNumErrors, "kErrors has kNumErrors rows");
static_assert(model::kParams.size() == model::kNumParams, "kParams has kNumParams rows");
static_assert(model::kOutputs.size() == 6 && model::kOutputUnits.size() == 6, "six outputs");
static_assert(model::kHigherTerms.size() == model::kNumHigherTerms, "no higher terms");

int main() {
  // The rotary axis' unit factor is deg -> rad, the error's um -> mm.
  const bool ok = model::kAxes[1].revolute && model::kAxes[1].to_base > 0.0174 &&
                  model::kAxes[1].to_base < 0.0175 && model::kErrors[0].to_base == 0.001;
  return ok ? 0 : 1;
}
