#include <boost/program_options.hpp>
#include <iostream>

#include "flags.hpp"
#include "verbs.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/codegen/generate.hpp"
#include "weilgen/machine/algebra_size.hpp"
#include "weilgen/machine/yaml_loader.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

int usage_error(const std::string& verb, const std::string& message) {
  std::cerr << "weilgen " << verb << ": " << message << " (try weilgen " << verb << " --help)\n";
  return 2;
}

template <typename Positional>
std::optional<int> parse_args(const std::string& verb, const Args& args,
                              const po::options_description& visible, const char* positional,
                              int max_positional, po::variables_map& vm) {
  // The flag table for the Python module and its parity test (docs/python.md).
  if (args.size() == 1 && args[0] == "--flags-json") {
    std::cout << flags_json(verb, visible, positional, max_positional).dump(1) << "\n";
    return 0;
  }
  po::options_description hidden;
  hidden.add_options()(positional, po::value<Positional>(), "")(
      "unexpected-argument", po::value<std::vector<std::string>>(), "");
  po::options_description all;
  all.add(visible).add(hidden);
  po::positional_options_description pos;
  pos.add(positional, max_positional);
  if (max_positional >= 0) pos.add("unexpected-argument", -1);  // named in the message
  try {
    po::store(po::command_line_parser(args).options(all).positional(pos).run(), vm);
    po::notify(vm);
  } catch (const po::error& e) {
    return usage_error(verb, e.what());
  }
  if (vm.count("unexpected-argument"))
    return usage_error(
        verb,
        "unexpected argument '" + vm["unexpected-argument"].as<std::vector<std::string>>().front() +
            "' (this verb takes " +
            (max_positional == 0 ? std::string("no file") : "one " + std::string(positional)) +
            ")");
  if (vm.count("help")) {
    std::cout << visible << "\n";
    return 0;
  }
  return std::nullopt;
}

template std::optional<int> parse_args<std::string>(const std::string&, const Args&,
                                                    const po::options_description&, const char*,
                                                    int, po::variables_map&);
template std::optional<int> parse_args<std::vector<std::string>>(const std::string&, const Args&,
                                                                 const po::options_description&,
                                                                 const char*, int,
                                                                 po::variables_map&);

int verb_generate(const Args& args) {
  po::options_description opts(
      "weilgen generate <machine>... [options]\n\n"
      "Builds each machine's error model over its Weil algebra and writes <out>/<name>.hpp\n"
      "(standalone C++ header) and <out>/<name>.md (closed-form report). Nothing is written\n"
      "unless every machine generated without error; then each file is written atomically\n"
      "(a run is atomic per file, not as a set: docs/robustness.md).\n\nOptions");
  int order = 0;
  std::string out = "generated";
  opts.add_options()("help,h", "show this help")(
      "order", ranged(&order, NumberRange::whole_numbers(1, kMaxAlgebraOrder)),
      "truncation order r >= 1, overriding the file's algebra.order; the outputs are then\n"
      "named <name>_o<r>")("out", po::value<std::string>(&out)->default_value("generated"),
                           "output directory")(
      "check",
      "write nothing; exit 1 and list the stale files when the files in --out differ\n"
      "from what would be generated")(
      "c-api",
      "also write the C API: <out>/<name>_c.h (C99, extern \"C\" under C++) and\n"
      "<out>/<name>_c.cpp, its implementation over <name>.hpp (docs/controllers.md)");
  po::variables_map vm;
  if (auto stop = parse_args<std::vector<std::string>>("generate", args, opts, "machine", -1, vm))
    return *stop;
  if (!vm.count("machine")) return usage_error("generate", "no machine given");

  // Every machine read and its size checked before anything is generated.
  std::vector<Description> machines;
  std::vector<PathArg> inputs;
  for (const auto& m : vm["machine"].as<std::vector<std::string>>()) {
    inputs.push_back({"machine file", resolve_machine(m)});
    machines.push_back(load_machine_file(inputs.back().path));
    check_order(machines.back(), order, false);
  }
  std::vector<gen::GeneratedFile> files;
  for (const Description& d : machines) {
    auto f = gen::generate_files(d, order, out, vm.count("c-api") > 0);
    files.insert(files.end(), f.begin(), f.end());
  }
  if (vm.count("check")) {
    const auto stale = gen::stale_files(files);
    for (const auto& s : stale) std::cout << s << "\n";
    if (!stale.empty()) {
      std::cout << stale.size()
                << " generated file(s) out of date: run `weilgen generate` and "
                   "commit the result\n";
      return 1;
    }
    std::cout << files.size() << " generated file(s) up to date\n";
    return 0;
  }
  // Every file checked before the first is written; each is then written atomically.
  std::vector<PathArg> outputs;
  for (const auto& f : files) outputs.push_back({"--out", f.path});
  check_output_paths(inputs, outputs);
  for (const auto& f : files) {
    std::string old;
    if (read_file(f.path, old) && old == f.contents) continue;  // keep mtime: no rebuilds
    write_file_atomically(f.path, f.contents);
    std::cout << "wrote " << f.path << "\n";
  }
  return 0;
}

}  // namespace weilgen::cli
