#include "weilgen/codegen/emit_hal.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "weilgen/base/error.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/codegen/emit_c_api.hpp"
#include "weilgen/codegen/emit_cpp.hpp"
#include "weilgen/machine/model_key.hpp"

namespace weilgen::gen {

// The texts of templates/hal_component.c, hal_errors.cpp and hal_Makefile after their marker
// lines, embedded at build time (src/codegen/CMakeLists.txt).
extern const char* const kHalComponentTemplate;
extern const char* const kHalErrorsTemplate;
extern const char* const kHalMakefileTemplate;

namespace {

constexpr std::size_t kHalNameLength = 47;  // HAL_NAME_LEN of LinuxCNC's hal.h

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool is_component_name(const std::string& s) {
  if (s.empty() || !std::isalpha(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

// The identified parameters must be those of this model: their namespace and kModelKey.
void check_params_header(const HalComponentOptions& o, const std::string& model,
                         const std::string& key) {
  const auto line_at = [&](std::size_t at) {
    return 1 + static_cast<int>(std::count(o.params_header.begin(),
                                           o.params_header.begin() + static_cast<long>(at), '\n'));
  };
  const std::string ns = "namespace " + model + "_params {";
  if (o.params_header.find(ns) == std::string::npos)
    throw InputError({o.params_header_path, 0, 0},
                     "not the identified parameters of model " + model + " (no '" + ns +
                         "'): write them with weilgen identify " + model + " --emit-params");
  const std::string tag = "kModelKey = \"";
  const auto at = o.params_header.find(tag);
  if (at == std::string::npos)
    throw InputError({o.params_header_path, 0, 0},
                     "no kModelKey: not a header written by weilgen identify --emit-params");
  const std::string found = o.params_header.substr(at + tag.size(), 16);
  if (found != key)
    throw InputError({o.params_header_path, line_at(at), 0},
                     "kModelKey \"" + found + "\" is not the model's \"" + key +
                         "\": the parameters were identified with another machine file, order "
                         "or weilgen version; identify again (weilgen identify --emit-params)");
}

// The joint a trivkins configuration with the default coordinates XYZABCUVW gives an axis.
std::string joint_of(const std::string& axis) {
  const std::string letters = "XYZABCUVW";
  const auto at = axis.size() == 1 ? letters.find(axis[0]) : std::string::npos;
  return at == std::string::npos ? "?" : std::to_string(at);
}

std::string hal_lines(const SymbolicModel& m, const std::string& name,
                      const std::string& source_label, const std::vector<double>& errors,
                      bool identified) {
  const Description& d = m.desc;
  std::ostringstream os;
  os << "# LinuxCNC configuration lines for the HAL component " << name
     << " (weilgen linuxcnc, docs/controllers.md):\n# real-time geometric compensation with the "
     << "model " << d.name << " (" << source_label << ").\n"
     << "# Build and install the component first, in this directory: make && sudo make install.\n"
     << "# Joint numbers assume trivkins with coordinates=XYZABCUVW order; <driver ...> stands "
        "for\n"
     << "# the configuration's drive pins (stepgen.N.position-cmd, pid.N.command, ...).\n"
     << "loadrt " << name << "\n"
     << "# Order in the servo thread: the drivers' read functions, " << name << ".feedback,\n"
     << "# motion-command-handler, motion-controller, " << name
     << ".compensate, the drivers' write\n# functions: put these addf lines there.\n"
     << "addf " << name << ".feedback servo-thread\naddf " << name
     << ".compensate servo-thread\nnet machine-is-enabled motion.motion-enabled => " << name
     << ".enable\n";
  for (const auto& a : m.axes) {
    const Joint& j = d.bodies[a.body].joint;
    const std::string pin = lower(j.coordinate), joint = "joint." + joint_of(j.coordinate);
    os << "# axis " << j.coordinate << " (" << j.unit << ")\n"
       << "net " << pin << "-pos-cmd " << joint << ".motor-pos-cmd => " << name << "." << pin
       << ".pos-cmd\n"
       << "net " << pin << "-pos-comp " << name << "." << pin << ".pos-comp => <driver " << pin
       << " position command>\n"
       << "net " << pin << "-pos-fb-raw <driver " << pin << " position feedback> => " << name << "."
       << pin << ".pos-fb-in\n"
       << "net " << pin << "-pos-fb " << name << "." << pin << ".pos-fb => " << joint
       << ".motor-pos-fb\n";
  }
  os << "# Errors (base units mm, rad), added to the "
     << (identified ? "identified errors built in" : "model") << "; built-in values:\n";
  for (std::size_t i = 0; i < d.errors.size(); ++i)
    os << "# setp " << name << ".error." << d.errors[i].name << " "
       << format_literal(errors.empty() ? 0.0 : errors[i]) << "\n";
  if (!d.parameters.empty())
    os << "# Model parameters (mm, deg), input pins starting at the "
       << (identified ? "identified" : "machine file's") << " values; set or net them:\n";
  for (const auto& p : d.parameters) os << "# setp " << name << ".param." << p.name << " ...\n";
  return os.str();
}

}  // namespace

std::string hal_component_name(const Description& desc, const HalComponentOptions& options) {
  return options.name.empty() ? "weilgen_" + desc.name : options.name;
}

std::vector<GeneratedFile> linuxcnc_files(const Description& desc,
                                          const HalComponentOptions& options,
                                          const std::string& out_dir) {
  const std::string name = hal_component_name(desc, options);
  const std::string flag = options.name.empty() ? "the default name " + name : "--name " + name;
  if (!is_component_name(name))
    throw std::invalid_argument(flag + ": a component name is [A-Za-z][A-Za-z0-9_]*");
  if (!options.error_defaults.empty() && options.error_defaults.size() != desc.errors.size())
    throw std::invalid_argument("error defaults: " + std::to_string(desc.errors.size()) +
                                " values expected");

  const SymbolicModel m = build_model(desc);
  const CNames c = c_names(m);  // checks the names before anything else
  std::size_t longest = std::string(".compensate").size();
  for (const auto& a : c.axes)
    longest = std::max(longest, 1 + a.size() + std::string(".pos-fb-in").size());
  for (const auto& e : desc.errors) longest = std::max(longest, 7 + e.name.size());  // .error.
  for (const auto& p : desc.parameters) longest = std::max(longest, 7 + p.name.size());
  if (name.size() + longest > kHalNameLength)
    throw std::invalid_argument(flag + ": its pin names would be " +
                                std::to_string(name.size() + longest) + " characters, HAL allows " +
                                std::to_string(kHalNameLength) + "; give a shorter --name");
  const bool identified = !options.params_header.empty();
  if (identified) check_params_header(options, c.lower, model_key(desc.source_hash, m.order));

  const std::string label = source_label(desc.source_file);
  std::string axis_pins, defaults;
  for (std::size_t i = 0; i < c.axes.size(); ++i)
    axis_pins += std::string(i ? ", " : "") + "\"" + lower(c.axes[i]) + "\"";
  for (std::size_t i = 0; i < desc.errors.size(); ++i)
    defaults += std::string(i ? ", " : "") +
                format_literal(options.error_defaults.empty() ? 0.0 : options.error_defaults[i]);
  const std::string names = "#define COMPONENT \"" + name +
                            "\"\nstatic const char *const axis_pins[" + c.upper + "_NUM_AXES] = {" +
                            axis_pins + "};\nstatic const double error_defaults[" + c.upper +
                            "_NUM_ERRORS] = {" + defaults + "};\n";
  const std::string zero_errors =
      "// No identified parameters: the errors are the component's error parameters alone, and\n"
      "// the model parameters start at the machine file's defaults.\n"
      "extern \"C\" void standin_identified_errors(const double*, double* errors) noexcept {\n"
      "  for (std::size_t i = 0; i < model::kNumErrors; ++i) errors[i] = 0.0;\n}\n\n"
      "extern \"C\" void standin_identified_params(double* params) noexcept {\n"
      "  for (std::size_t i = 0; i < model::kNumParams; ++i) params[i] = "
      "model::kParams[i].default_value;\n}\n";
  std::vector<std::pair<std::string, std::string>> error_blocks;
  if (!identified)
    error_blocks.push_back({"identified", instantiate_template(zero_errors, c.lower, c.upper, {})});

  const std::string banner = " GENERATED by weilgen linuxcnc from " + label + " (component " +
                             name + ", docs/controllers.md). Do not edit: run weilgen linuxcnc.";
  const std::string base = (std::filesystem::path(out_dir) / "").string();
  std::vector<GeneratedFile> files = {
      {base + c.lower + ".hpp", emit_cpp_header(m, label)},
      {base + c.lower + "_c.h", emit_c_api_header(m, label)},
      {base + c.lower + "_c.cpp", emit_c_api_source(m, label)},
      {base + name + "_hal.c",
       "/*" + banner + " */\n" +
           instantiate_template(kHalComponentTemplate, c.lower, c.upper, {{"names", names}})},
      {base + name + "_errors.cpp",
       "//" + banner + "\n" +
           instantiate_template(kHalErrorsTemplate, c.lower, c.upper, error_blocks)},
      {base + "Makefile", "#" + banner + "\n" +
                              instantiate_template(kHalMakefileTemplate, c.lower, c.upper,
                                                   {{"component", "COMPONENT := " + name + "\n"}})},
      {base + name + ".hal", hal_lines(m, name, label, options.error_defaults, identified)}};
  if (identified) files.push_back({base + c.lower + "_params.hpp", options.params_header});
  return files;
}

}  // namespace weilgen::gen
