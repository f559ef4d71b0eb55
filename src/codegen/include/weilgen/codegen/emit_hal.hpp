// The LinuxCNC HAL component of a model (`weilgen linuxcnc`): real-time geometric compensation
// in a servo thread, built the way LinuxCNC builds out-of-tree components (Makefile.modinc),
// over the model's C API. The texts come from templates/hal_component.c, hal_errors.cpp and
// hal_Makefile. docs/controllers.md.
#pragma once

#include <string>
#include <vector>

#include "weilgen/codegen/generate.hpp"

namespace weilgen::gen {

struct HalComponentOptions {
  // HAL component and module name ([A-Za-z][A-Za-z0-9_]*); empty: weilgen_<model>.
  std::string name;
  // Defaults of the component's error parameters, base units (mm, rad), kErrors order; empty:
  // all zero.
  std::vector<double> error_defaults;
  // The text of an `identify --emit-params` header for this model, built in as the errors at a
  // pose; empty: none. `params_header_path` names it in messages.
  std::string params_header;
  std::string params_header_path;
};

// Every file of the component in `out_dir`: the model header <model>.hpp and its C API
// (<model>_c.h, <model>_c.cpp), <name>_hal.c, <name>_errors.cpp, <model>_params.hpp (a copy of
// the identified parameters, when given), Makefile and <name>.hal (configuration lines).
// Throws std::invalid_argument for a bad name (naming --name) or one whose pin names exceed
// HAL's 47 characters, InputError for identified parameters of another model (the file and the
// line of its kModelKey or namespace) and for names that clash in C (emit_c_api.hpp).
std::vector<GeneratedFile> linuxcnc_files(const Description& desc,
                                          const HalComponentOptions& options,
                                          const std::string& out_dir);

// The component name linuxcnc_files uses for `options`.
std::string hal_component_name(const Description& desc, const HalComponentOptions& options);

}  // namespace weilgen::gen
