// The identified errors of a HAL component that `weilgen linuxcnc` writes (<component>_errors.cpp),
// as a real C++ file: the generator (src/codegen/emit_hal.cpp) emits everything after the marker
// line with the stand-in names replaced by the model's; without identified parameters it replaces
// the block between the identified markers by a function that gives zeros. Compiled on its own
// against the stand-in model and parameters (templates/standin.hpp, standin_params.hpp) by the
// build (target hal_component_template_check).
// clang-format off: the text below is emitted byte for byte.
// ---- weilgen template: emitted from the next line ----
// The errors the HAL component adds to its error parameters at every pose, built in from the
// identified parameters (`weilgen identify --emit-params`), and the model parameters they were
// identified with. C++ without exceptions or RTTI: it needs libm only, no C++ runtime.
#include <array>
#include <cstddef>
#include <cstring>

#include "standin.hpp"

namespace model = weilgen_models::standin;

// ---- weilgen template: identified begin ----
#include "standin_params.hpp"

namespace identified = weilgen_models::standin_params;

namespace {
constexpr bool same_text(const char* a, const char* b) {
  return *a == *b && (*a == '\0' || same_text(a + 1, b + 1));
}
}  // namespace
static_assert(same_text(model::kModelKey, identified::kModelKey),
              "the parameters were identified with another model (kModelKey): identify again with "
              "this machine file and weilgen version");

extern "C" void standin_identified_errors(const double* axes, double* errors) noexcept {
  std::array<double, model::kNumAxes> q{};
  std::memcpy(q.data(), axes, sizeof q);
  std::array<double, model::kNumErrors> e{};
  identified::Errors(q, &e);
  std::memcpy(errors, e.data(), sizeof e);
}

extern "C" void standin_identified_params(double* params) noexcept {
  for (std::size_t i = 0; i < model::kNumParams; ++i) params[i] = identified::kParams[i];
}
// ---- weilgen template: identified end ----
