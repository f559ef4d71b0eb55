#include <boost/program_options.hpp>
#include <iostream>

#include "flags.hpp"
#include "verbs.hpp"
#include "weilgen/codegen/emit_report.hpp"
#include "weilgen/machine/algebra_size.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/report/json_common.hpp"

namespace po = boost::program_options;

namespace weilgen::cli {

int verb_show(const Args& args) {
  po::options_description opts(
      "weilgen show <machine> [options]\n\n"
      "Prints the closed-form deviation of the tool point relative to the workpiece\n"
      "(dx dy dz in mm, da db dc in rad), grouped by error.\n\nOptions");
  std::string output, format = "text", notation = "iso";
  int order = 0;
  opts.add_options()("help,h", "show this help")("output", po::value<std::string>(&output),
                                                 "only this output: dx dy dz da db dc")(
      "format", po::value<std::string>(&format)->default_value("text"),
      "text | latex | json | sympy (Python syntax, * and **, that sympy.sympify reads)")(
      "notation", po::value<std::string>(&notation)->default_value("iso"),
      "iso (ISO 230-1 names) | alias (each error's first alias, e.g. the paper's symbols)")(
      "order", ranged(&order, NumberRange::whole_numbers(1, kMaxAlgebraOrder)),
      "truncation order r >= 1 overriding the file's");
  po::variables_map vm;
  if (auto stop = parse_args<std::string>("show", args, opts, "machine", 1, vm)) return *stop;
  if (!vm.count("machine")) return usage_error("show", "no machine given");
  if (format != "text" && format != "latex" && format != "json" && format != "sympy")
    return usage_error("show", "--format must be text, latex, json or sympy, not '" + format + "'");
  if (notation != "iso" && notation != "alias")
    return usage_error("show", "--notation must be iso or alias, not '" + notation + "'");
  int only = -1;
  if (!output.empty()) {
    for (int o = 0; o < kNumDeviationOutputs; ++o)
      if (output == output_name(static_cast<std::size_t>(o))) only = o;
    if (only < 0) return usage_error("show", "unknown output '" + output + "' (dx dy dz da db dc)");
  }
  const Description d = load_machine_file(resolve_machine(vm["machine"].as<std::string>()));
  check_order(d, order, false);
  const gen::SymbolicModel m = gen::build_model(d, order);
  const gen::Notation n = notation == "iso" ? gen::Notation::Iso : gen::Notation::Alias;
  if (format == "json") {
    auto j = json_document("show", gen::closed_forms_json(m, n));
    if (only >= 0) {
      auto one = j["outputs"][output_name(static_cast<std::size_t>(only))];
      j["outputs"] = {{output_name(static_cast<std::size_t>(only)), one}};
    }
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  const auto style = format == "latex"   ? gen::FormStyle::Latex
                     : format == "sympy" ? gen::FormStyle::Sympy
                                         : gen::FormStyle::Text;
  for (int o = 0; o < kNumDeviationOutputs; ++o)
    if (only < 0 || only == o) std::cout << gen::closed_form(m, o, style, n) << "\n";
  return 0;
}

}  // namespace weilgen::cli
