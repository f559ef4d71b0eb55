// weilgen linuxcnc: a LinuxCNC HAL component doing real-time geometric compensation with a
// machine's model, its C API, identified errors built in or read from a file, a Makefile
// (Makefile.modinc) and the configuration (joints, signs, safety wiring). docs/controllers.md.
#include <filesystem>
#include <iostream>

#include "flags.hpp"
#include "verbs.hpp"
#include "weilgen/analysis/tolerance_file.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/codegen/emit_hal.hpp"
#include "weilgen/machine/linuxcnc.hpp"
#include "weilgen/machine/yaml_loader.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

int verb_linuxcnc(const Args& args) {
  po::options_description opts(
      "weilgen linuxcnc <machine> --out DIR [--params P] [--params-file F] [--name NAME]\n"
      "                 [--units mm|inch] [--sign X=-1,...] [--offset X=250,...]\n\n"
      "Writes a LinuxCNC HAL component that compensates the machine's geometric errors in the\n"
      "servo thread with the model's Compensate: per axis pos-cmd (joint.N.pos-cmd) and\n"
      "motor-pos-cmd in, pos-comp out (to the drive), pos-fb-in / pos-fb for the feedback; enable\n"
      "and homed, limits (max-correction, max-step: ramps), a latched fault; the constant errors\n"
      "as input pins <name>.error.<E> (mm, rad); identified errors built in or read from a file\n"
      "(module parameter params_file, reloaded on <name>.reload). LinuxCNC's joints are the tool\n"
      "relative to the workpiece: an axis that carries the workpiece gets sign -1 (the machine\n"
      "file's linuxcnc: section and the flags override). Into DIR: the model header and its C\n"
      "API, <name>_hal.c, <name>_errors.cpp, the parameter-file reader, a Makefile over\n"
      "LinuxCNC's Makefile.modinc (make && sudo make install) and <name>.hal, the configuration.\n"
      "docs/controllers.md.\n\nOptions");
  std::string out, params, name, params_file, units, signs, offsets;
  opts.add_options()("help,h", "show this help")("out", po::value<std::string>(&out),
                                                 "output directory (required)")(
      "params", po::value<std::string>(&params),
      "errors built in: a header from weilgen identify --emit-params (.hpp: the errors at\n"
      "every pose), or a tolerance file of const entries in JSON or YAML (.json, .yaml:\n"
      "fixed errors, the defaults of the error pins)")(
      "params-file", po::value<std::string>(&params_file),
      "identified parameters read by the component when it loads (and on reload): the JSON of\n"
      "weilgen identify --emit-params-json; written into the .hal file's loadrt line as\n"
      "params_file=F (checked against the model now; give an absolute path)")(
      "name", po::value<std::string>(&name),
      "HAL component and module name (default weilgen_<machine>)")(
      "units", po::value<std::string>(&units),
      "LinuxCNC's linear units, [TRAJ]LINEAR_UNITS: mm or inch (default: the machine file's\n"
      "linuxcnc: units, else mm)")(
      "sign", po::value<std::string>(&signs),
      "LinuxCNC joint signs, model = offset + sign * joint: X=-1,Z=1 (default: the machine\n"
      "file's, else -1 for an axis that carries the workpiece)")(
      "offset", po::value<std::string>(&offsets),
      "model coordinate at LinuxCNC's joint zero: X=250,C=-90 (the axis' unit unless written)");
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("linuxcnc", args, opts, "machine", 1, vm)) return *stop;
  if (!vm.count("machine")) return usage_error("linuxcnc", "no machine given");
  if (out.empty()) return usage_error("linuxcnc", "no --out directory given");
  std::error_code ec;
  if (std::filesystem::exists(out, ec) && !std::filesystem::is_directory(out, ec))
    return usage_error("linuxcnc", "--out " + out + " is not a directory");
  if (!units.empty() && units != "mm" && units != "inch")
    return usage_error("linuxcnc", "--units " + units + ": mm or inch");

  const std::string machine = resolve_machine(vm["machine"].as<std::string>());
  const Description desc = load_machine_file(machine);
  gen::HalComponentOptions o;
  o.name = name;
  o.linuxcnc.units = units;
  try {
    if (!signs.empty()) o.linuxcnc.signs = parse_linuxcnc_signs(desc, signs);
    if (!offsets.empty()) o.linuxcnc.offsets = parse_linuxcnc_offsets(desc, offsets);
  } catch (const std::invalid_argument& e) {
    return usage_error("linuxcnc", e.what());
  }
  if (!params_file.empty()) {
    if (!read_file(params_file, o.params_file_text))
      throw InputError({params_file, 0, 0}, "cannot read the identified parameters");
    o.params_file = params_file;
  }
  if (!params.empty()) {
    const std::string ext = std::filesystem::path(params).extension().string();
    if (ext == ".hpp" || ext == ".h" || ext == ".hh") {
      if (!read_file(params, o.params_header))
        throw InputError({params, 0, 0}, "cannot read the identified parameters");
      o.params_header_path = params;
    } else if (ext == ".json" || ext == ".yaml" || ext == ".yml") {
      std::string text;
      if (read_file(params, text) && text.find("\"weilgen_params\"") != std::string::npos)
        return usage_error("linuxcnc", "--params " + params +
                                           ": identified parameters in JSON are read at run "
                                           "time: give them as --params-file");
      o.error_defaults = read_error_values(params, desc);
    } else {
      return usage_error("linuxcnc", "--params " + params +
                                         ": expected a .hpp from identify --emit-params or a "
                                         ".json / .yaml of const errors");
    }
  }
  const std::vector<gen::GeneratedFile> files = gen::linuxcnc_files(desc, o, out);
  std::vector<PathArg> outputs;
  for (const auto& f : files) outputs.push_back({"--out", f.path});
  check_output_paths(
      {{"machine file", machine}, {"--params", params}, {"--params-file", params_file}}, outputs);
  for (const auto& f : files) {
    write_file_atomically(f.path, f.contents);
    std::cout << "wrote " << f.path << "\n";
  }
  const std::string component = gen::hal_component_name(desc, o);
  std::cout << "build and install: make -C " << out << " && sudo make -C " << out
            << " install\nthen in the configuration: loadrt " << component << " (see " << out << "/"
            << component << ".hal)\n";
  return 0;
}

}  // namespace weilgen::cli
