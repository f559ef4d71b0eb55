#include "weilgen/codegen/emit_hal.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "weilgen/base/constants.hpp"
#include "weilgen/base/error.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/codegen/emit_c_api.hpp"
#include "weilgen/codegen/emit_cpp.hpp"
#include "weilgen/machine/model_key.hpp"

namespace weilgen::gen {

// The texts of templates/hal_component.c, hal_errors.cpp, hal_Makefile and hal_params_file.h/.c
// after their marker lines, embedded at build time (src/codegen/CMakeLists.txt).
extern const char* const kHalComponentTemplate;
extern const char* const kHalErrorsTemplate;
extern const char* const kHalMakefileTemplate;
extern const char* const kHalParamsHeaderTemplate;
extern const char* const kHalParamsSourceTemplate;

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

// The identified parameters' JSON (identify --emit-params-json) must be this model's.
void check_params_file(const HalComponentOptions& o, const std::string& model,
                       const std::string& key) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(o.params_file_text);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError({o.params_file, 0, 0}, std::string("not JSON: ") + e.what());
  }
  if (!j.is_object() || !j.contains("weilgen_params"))
    throw InputError({o.params_file, 0, 0},
                     "not identified parameters (no weilgen_params): write them with weilgen "
                     "identify " +
                         model + " --emit-params-json");
  const std::string machine = j.value("machine", std::string()),
                    found = j.value("model_key", std::string());
  if (machine != model)
    throw InputError({o.params_file, 0, 0},
                     "the parameters of machine '" + machine + "', not of " + model);
  if (found != key)
    throw InputError(
        {o.params_file, 0, 0},
        "model_key \"" + found + "\" is not the model's \"" + key +
            "\": the parameters were identified with another machine file, order "
            "or weilgen version; identify again (weilgen identify --emit-params-json)");
}

std::string c_list(const std::vector<double>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + format_literal(v[i]);
  return s;
}

// The default limits of one axis in joint units: 0.1 mm or 0.05 deg of correction, a change of
// 1 um or 0.001 deg per servo period (1 mm/s, 1 deg/s at 1 kHz).
double joint_units(const LinuxcncJoint& x, const Joint& j, double mm_or_deg) {
  const double base = x.rotary ? mm_or_deg * kPi / 180 : mm_or_deg;
  return base / j.to_base / x.scale;
}

std::string sign_text(int sign) { return sign < 0 ? "-1" : "+1"; }

std::string hal_lines(const SymbolicModel& m, const LinuxcncMapping& map, const std::string& name,
                      const std::string& source_label, const HalComponentOptions& o,
                      bool identified) {
  const Description& d = m.desc;
  std::vector<LinuxcncJoint> joints = map.axes;  // in joint order
  std::sort(joints.begin(), joints.end(),
            [](const LinuxcncJoint& a, const LinuxcncJoint& b) { return a.joint < b.joint; });
  std::ostringstream os;
  os << "# LinuxCNC configuration of the HAL component " << name
     << " (weilgen linuxcnc, docs/controllers.md):\n# real-time geometric compensation with the "
     << "model " << d.name << " (" << source_label << ").\n"
     << "# Build and install the component first, in this directory: make && sudo make install.\n"
     << "#\n# The INI file this configuration assumes:\n"
     << "#   [KINS] KINEMATICS = trivkins coordinates=" << map.coordinates << "\n"
     << "#   [KINS] JOINTS = " << map.num_joints << "\n"
     << "#   [TRAJ] LINEAR_UNITS = " << map.linear_units << ", ANGULAR_UNITS = degree\n"
     << "#\n# LinuxCNC's joint positions are the tool relative to the workpiece; the model's axes "
        "are the\n# positions of their own bodies: model = offset + sign * scale * joint. Check "
        "the signs on the\n# machine (docs/controllers.md): jog each joint + and watch "
     << name << ".<axis>.pos-cmd and the\n# model's nominal pose.\n"
     << "#   axis  joint  letter  sign  scale  offset  unit  why\n";
  for (const LinuxcncJoint& x : joints)
    os << "#   " << x.coordinate << "  " << x.joint << "  " << x.letter << "  " << sign_text(x.sign)
       << "  " << format_number(x.scale) << "  " << format_number(x.offset) << "  " << x.unit
       << "  " << x.sign_reason << "\n";
  os << "#\n# Source this file from the main .hal file right after `addf motion-controller "
        "servo-thread`:\n# "
     << name << ".feedback goes in front of motion-controller (position -2), " << name
     << ".compensate\n# after it, before the drivers' write functions. Then feed the drivers "
        "from these signals instead\n# of joint.N.motor-pos-cmd and joint.N.motor-pos-fb:\n";
  for (const LinuxcncJoint& x : joints) {
    const std::string p = "weilgen-" + lower(x.coordinate);
    os << "#   net " << p << "-pos-comp => <driver " << x.joint << " position command>\n"
       << "#   net " << p << "-pos-fb-in <= <driver " << x.joint << " position feedback>\n";
  }
  os << "loadrt " << name;
  if (!o.params_file.empty()) os << " params_file=" << o.params_file;
  os << "\n";
  if (o.params_file.empty())
    os << "# identified parameters from a file instead (weilgen identify --emit-params-json), "
          "read at\n# load and again on a rising "
       << name << ".reload:\n#   loadrt " << name << " params_file=/absolute/path/" << d.name
       << "_params.json\n";
  os << "addf " << name << ".feedback servo-thread -2\naddf " << name
     << ".compensate servo-thread\n"
     << "# no correction until the machine is on and homed:\n"
     << "net machine-is-enabled motion.motion-enabled => " << name << ".enable\n"
     << "net weilgen-all-homed motion.is-all-homed => " << name << ".homed\n";
  for (const LinuxcncJoint& x : joints) {
    const Joint& j = d.bodies[static_cast<std::size_t>(d.axes()[x.axis])].joint;
    const std::string pin = name + "." + lower(x.coordinate), p = "weilgen-" + lower(x.coordinate);
    const std::string joint = "joint." + std::to_string(x.joint);
    os << "# axis " << x.coordinate << " = joint " << x.joint << " (" << x.letter << ", " << x.unit
       << "): model " << x.coordinate << " = " << format_number(x.offset) << " "
       << (x.sign < 0 ? "- " : "+ ") << format_number(x.scale) << " * joint (" << j.unit << ")\n"
       << "net " << p << "-pos-cmd " << joint << ".pos-cmd => " << pin << ".pos-cmd\n"
       << "net " << p << "-motor-cmd " << joint << ".motor-pos-cmd => " << pin << ".motor-pos-cmd\n"
       << "net " << p << "-pos-comp " << pin << ".pos-comp\n"
       << "net " << p << "-pos-fb-in => " << pin << ".pos-fb-in\n"
       << "net " << p << "-motor-fb " << pin << ".pos-fb => " << joint << ".motor-pos-fb\n"
       << "setp " << pin << ".max-correction "
       << format_number(joint_units(x, j, x.rotary ? 0.05 : 0.1)) << "  # " << x.unit << "\n"
       << "setp " << pin << ".max-step " << format_number(joint_units(x, j, 0.001)) << "  # "
       << x.unit << " per servo period\n";
  }
  os << "# A latched fault (" << name << ".fault-code says why; cleared by a rising " << name
     << ".fault-reset):\n# show it, or stop the machine (docs/controllers.md, \"Safety "
        "wiring\"):\n"
     << "net weilgen-fault " << name << ".fault\n"
     << "#   loadrt message names=weilgen-msg messages=\"weilgen compensation fault\"\n"
     << "#   addf weilgen-msg servo-thread\n#   net weilgen-fault => weilgen-msg.trigger\n"
     << "#   loadrt not names=weilgen-ok\n#   addf weilgen-ok servo-thread\n"
     << "#   net weilgen-fault => weilgen-ok.in\n"
     << "#   net weilgen-ok weilgen-ok.out => iocontrol.0.emc-enable-in\n";
  os << "# Constant errors: input pins in base units (mm, rad), added to the "
     << (identified ? "identified errors" : "model's zero errors")
     << "; set them, or net a thermal model's outputs to them. Built-in values:\n";
  for (std::size_t i = 0; i < d.errors.size(); ++i)
    os << "# setp " << name << ".error." << d.errors[i].name << " "
       << format_number(o.error_defaults.empty() ? 0.0 : o.error_defaults[i]) << "\n";
  if (!d.parameters.empty())
    os << "# Model parameters (mm, deg), input pins starting at the "
       << (identified || !o.params_file.empty() ? "identified" : "machine file's")
       << " values; set or net them:\n";
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
  const LinuxcncMapping map = linuxcnc_mapping(desc, options.linuxcnc);
  std::size_t longest = std::string(".reload-failures").size();
  for (const auto& a : c.axes)
    longest = std::max(longest, 1 + a.size() + std::string(".max-correction").size());
  for (const auto& e : desc.errors) longest = std::max(longest, 7 + e.name.size());  // .error.
  for (const auto& p : desc.parameters) longest = std::max(longest, 7 + p.name.size());
  if (name.size() + longest > kHalNameLength)
    throw std::invalid_argument(flag + ": its pin names would be " +
                                std::to_string(name.size() + longest) + " characters, HAL allows " +
                                std::to_string(kHalNameLength) + "; give a shorter --name");
  const bool identified = !options.params_header.empty();
  const std::string key = model_key(desc.source_hash, m.order);
  if (identified) check_params_header(options, c.lower, key);
  if (!options.params_file.empty()) check_params_file(options, c.lower, key);

  const std::string label = source_label(desc.source_file);
  std::string axis_pins, defaults;
  for (std::size_t i = 0; i < c.axes.size(); ++i)
    axis_pins += std::string(i ? ", " : "") + "\"" + lower(c.axes[i]) + "\"";
  for (std::size_t i = 0; i < desc.errors.size(); ++i)
    defaults += std::string(i ? ", " : "") +
                format_literal(options.error_defaults.empty() ? 0.0 : options.error_defaults[i]);
  std::vector<double> sign, scale, offset, tmin, tmax, max_correction, max_step;
  for (const LinuxcncJoint& x : map.axes) {
    const Joint& j = desc.bodies[static_cast<std::size_t>(desc.axes()[x.axis])].joint;
    sign.push_back(x.sign);
    scale.push_back(x.scale);
    offset.push_back(x.offset);
    tmin.push_back(x.travel_min);
    tmax.push_back(x.travel_max);
    max_correction.push_back(joint_units(x, j, x.rotary ? 0.05 : 0.1));
    max_step.push_back(joint_units(x, j, 0.001));
  }
  const std::string n = "[" + c.upper + "_NUM_AXES] = {";
  const std::string names =
      "#define COMPONENT \"" + name + "\"\nstatic const char *const axis_pins" + n + axis_pins +
      "};\nstatic const double error_defaults[" + c.upper + "_NUM_ERRORS] = {" + defaults +
      "};\n/* model = offset + sign * scale * joint; travel in model units; limits in joint units. "
      "*/\nstatic const double axis_sign" +
      n + c_list(sign) + "};\nstatic const double axis_scale" + n + c_list(scale) +
      "};\nstatic const double axis_offset" + n + c_list(offset) +
      "};\nstatic const double travel_min" + n + c_list(tmin) +
      "};\nstatic const double travel_max" + n + c_list(tmax) +
      "};\nstatic const double default_max_correction" + n + c_list(max_correction) +
      "};\nstatic const double default_max_step" + n + c_list(max_step) +
      "};\n#define IDENTIFIED_BUILT_IN " + (identified ? "1" : "0") + "\n";
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
      {base + c.lower + "_params_file.h",
       "/*" + banner + " */\n" +
           instantiate_template(kHalParamsHeaderTemplate, c.lower, c.upper, {})},
      {base + c.lower + "_params_file.c",
       "/*" + banner + " */\n" +
           instantiate_template(kHalParamsSourceTemplate, c.lower, c.upper, {})},
      {base + name + ".hal", hal_lines(m, map, name, label, options, identified)}};
  if (identified) files.push_back({base + c.lower + "_params.hpp", options.params_header});
  return files;
}

}  // namespace weilgen::gen
