// weilgen linuxcnc: a LinuxCNC HAL component doing real-time geometric compensation with a
// machine's model, its C API, identified errors built in, a Makefile (Makefile.modinc) and the
// configuration lines. docs/controllers.md.
#include <filesystem>
#include <iostream>

#include "flags.hpp"
#include "verbs.hpp"
#include "weilgen/analysis/tolerance_file.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/codegen/emit_hal.hpp"
#include "weilgen/machine/yaml_loader.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

int verb_linuxcnc(const Args& args) {
  po::options_description opts(
      "weilgen linuxcnc <machine> --out DIR [--params P] [--name NAME]\n\n"
      "Writes a LinuxCNC HAL component that compensates the machine's geometric errors in the\n"
      "servo thread with the model's Compensate: pins <name>.<axis>.pos-cmd in, pos-comp out\n"
      "(to the drives), pos-fb-in / pos-fb for the feedback, enable, active, status; the\n"
      "errors as parameters <name>.error.<E> (mm, rad). Into DIR: the model header and its C\n"
      "API, <name>_hal.c, <name>_errors.cpp, a Makefile over LinuxCNC's Makefile.modinc\n"
      "(make && sudo make install) and <name>.hal, the configuration lines.\n"
      "docs/controllers.md.\n\nOptions");
  std::string out, params, name;
  opts.add_options()("help,h", "show this help")("out", po::value<std::string>(&out),
                                                 "output directory (required)")(
      "params", po::value<std::string>(&params),
      "errors built in: a header from weilgen identify --emit-params (.hpp: the errors at\n"
      "every pose), or a tolerance file of const entries in JSON or YAML (.json, .yaml:\n"
      "fixed errors, the defaults of the error parameters)")(
      "name", po::value<std::string>(&name),
      "HAL component and module name (default weilgen_<machine>)");
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("linuxcnc", args, opts, "machine", 1, vm)) return *stop;
  if (!vm.count("machine")) return usage_error("linuxcnc", "no machine given");
  if (out.empty()) return usage_error("linuxcnc", "no --out directory given");
  std::error_code ec;
  if (std::filesystem::exists(out, ec) && !std::filesystem::is_directory(out, ec))
    return usage_error("linuxcnc", "--out " + out + " is not a directory");

  const std::string machine = resolve_machine(vm["machine"].as<std::string>());
  const Description desc = load_machine_file(machine);
  gen::HalComponentOptions o;
  o.name = name;
  if (!params.empty()) {
    const std::string ext = std::filesystem::path(params).extension().string();
    if (ext == ".hpp" || ext == ".h" || ext == ".hh") {
      if (!read_file(params, o.params_header))
        throw InputError({params, 0, 0}, "cannot read the identified parameters");
      o.params_header_path = params;
    } else if (ext == ".json" || ext == ".yaml" || ext == ".yml") {
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
  check_output_paths({{"machine file", machine}, {"--params", params}}, outputs);
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
