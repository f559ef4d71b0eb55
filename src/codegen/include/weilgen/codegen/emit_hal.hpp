// The LinuxCNC HAL component of a model (`weilgen linuxcnc`): real-time geometric compensation
// in a servo thread, built the way LinuxCNC builds out-of-tree components (Makefile.modinc),
// over the model's C API. The texts come from templates/hal_component.c, hal_errors.cpp and
// hal_Makefile. docs/controllers.md.
#pragma once

#include <string>
#include <vector>

#include "weilgen/codegen/generate.hpp"
#include "weilgen/machine/linuxcnc.hpp"

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
  // The LinuxCNC joints: --units, --sign, --offset over the machine file's `linuxcnc:` section.
  LinuxcncOverrides linuxcnc;
  // Identified parameters read at run time (identify --emit-params-json): the path the .hal
  // file's loadrt line names as params_file, and the file's text, checked against the model.
  std::string params_file;
  std::string params_file_text;
};

// Every file of the component in `out_dir`: the model header <model>.hpp and its C API
// (<model>_c.h, <model>_c.cpp), <name>_hal.c, <name>_errors.cpp, the parameter-file reader
// <model>_params_file.h and .c, <model>_params.hpp (a copy of the identified parameters, when
// given), Makefile and <name>.hal (the configuration: kinematics, joints, signs, safety wiring).
// Throws std::invalid_argument for a bad name (naming --name) or one whose pin names exceed
// HAL's 47 characters, InputError for identified parameters of another model (the file and the
// line of its kModelKey or namespace; a params file's machine or model_key), for a `linuxcnc:`
// section that gives two axes one letter or joint, and for names that clash in C.
std::vector<GeneratedFile> linuxcnc_files(const Description& desc,
                                          const HalComponentOptions& options,
                                          const std::string& out_dir);

// The component name linuxcnc_files uses for `options`.
std::string hal_component_name(const Description& desc, const HalComponentOptions& options);

}  // namespace weilgen::gen
