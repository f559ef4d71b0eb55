#include <exception>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "verbs.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/machine/description.hpp"

namespace {

struct Verb {
  int (*run)(const weilgen::cli::Args&);
  const char* summary;
};

const std::map<std::string, Verb>& verbs() {
  static const std::map<std::string, Verb> v = {
      {"generate",
       {weilgen::cli::verb_generate,
        "generate <machine>... [--order r] [--out DIR] [--check] [--c-api]\n"
        "      multiply the error HTMs over the Weil algebra and write the C++ header\n"
        "      and the closed-form report (generated/<machine>.hpp, .md)"}},
#ifndef WEILGEN_CODEGEN_ONLY
      {"show",
       {weilgen::cli::verb_show,
        "show <machine> [--output dx] [--format text|latex|json|sympy] [--notation iso|alias]\n"
        "      [--order r]\n"
        "      print the closed-form error expressions"}},
      {"list", {weilgen::cli::verb_list, "list\n      list the shipped machines"}},
      {"sensitivity",
       {weilgen::cli::verb_sensitivity,
        "sensitivity <machine> (--at ...|--grid ...) [--method local|sobol|exact|all]\n"
        "      [--samples N]\n"
        "      coefficients, exact and quasi-Monte Carlo Sobol' indices per pose and output"}},
      {"reliability",
       {weilgen::cli::verb_reliability,
        "reliability <machine> --grid ... --tolerance dx=0.03mm [--limit two-sided|one-sided|\n"
        "      radial] [--method auto|exact|form|is|mc]\n"
        "      P(deviation within tolerance) per pose and output, with sensitivities"}},
      {"allocate",
       {weilgen::cli::verb_allocate,
        "allocate <machine> --grid ... --tolerance ... --min 0.95 --mean 0.97\n"
        "      tighten the most sensitive errors until the reliability targets hold"}},
      {"iso230-2",
       {weilgen::cli::verb_iso230_2,
        "iso230-2 <data.csv> [--axis X] [--json FILE] [--csv FILE] [--plot FILE]\n"
        "         [--report F.html] [--tolerance SPEC] [--expansion PPM_PER_K] ...\n"
        "      ISO 230-2 positioning figures, with the thermal-drift-eliminated evaluation"}},
      {"ballbar",
       {weilgen::cli::verb_ballbar,
        "ballbar <trace.csv> [--radius 100] [--plane XY] [--plot F.svg] [--json F]\n"
        "        [--report F.html] [--machine M]\n"
        "      a ballbar trace on its own: ISO 230-4 G, F, H and the causes, ranked"}},
      {"import",
       {weilgen::cli::verb_import,
        "import <file> [--format auto|carto|wide|tidy] [--axis X] [--out FILE]\n"
        "      a laser export (Renishaw XL-80/CARTO wide CSV, generic wide) as the tidy CSV"}},
      {"fit-pdge",
       {weilgen::cli::verb_fit_pdge,
        "fit-pdge <data.csv> [--basis poly|fourier|legendre|chebyshev|all] [--order n|auto]\n"
        "      fit position-dependent errors, choose the order by cross-validation"}},
      {"identify",
       {weilgen::cli::verb_identify,
        "identify <machine> --data FILE [--pdge poly:3|E_YY=fourier:3] [--predict FILE]\n"
        "      [--emit-params FILE]\n"
        "      fit the error parameters, report what cannot be identified, predict, emit"}},
      {"plan",
       {weilgen::cli::verb_plan,
        "plan <machine> --poses N|--target-sd 2um [--instrument points|line6d|ballbar|rtest]\n"
        "      [--noise 1um] [--criterion D|A|E|I] [--out poses.csv] [--json F] [--plot F]\n"
        "      where to measure: the fewest poses that identify the machine, their uncertainty"}},
      {"gap",
       {weilgen::cli::verb_gap,
        "gap <machine> --data FILE [--holdout ...] [--effects ...] [--json F] [--report F.md]\n"
        "      where model and machine disagree, which unmodelled effect, how far it shrinks"}},
      {"linuxcnc",
       {weilgen::cli::verb_linuxcnc,
        "linuxcnc <machine> --out DIR [--params P] [--name NAME]\n"
        "      a LinuxCNC HAL component compensating the machine's errors in the servo thread"}},
#endif
  };
  return v;
}

void print_help() {
  std::cout << "weilgen " << weilgen::kVersion
            << " — symbolic-to-numeric code generator for machine-tool error models\n\n"
               "Usage: weilgen <verb> [options]     weilgen <verb> --help for a verb's options\n\n"
               "Verbs:\n";
  for (const auto& [name, v] : verbs()) std::cout << "  " << v.summary << "\n\n";
  std::cout << "<machine> is a path to a machine file (machines/README.md documents the format)\n"
               "or the name of a shipped machine (see `weilgen list`).\n"
               "Exit status: 0 success, 1 failure or stale files (--check), 2 bad arguments,\n"
               "3 bad input file.\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h" ||
      std::string(argv[1]) == "help") {
    print_help();
    return argc < 2 ? 2 : 0;
  }
  if (std::string(argv[1]) == "--version") {
    std::cout << "weilgen " << weilgen::kVersion << "\n";
    return 0;
  }
  if (std::string(argv[1]) == "--flags-json") {
    // Every verb's flag table (cli/flags.hpp, flags_json): the Python module's keywords and its
    // parity test are built from it (docs/python.md).
    nlohmann::json all = nlohmann::json::object();
    for (const auto& [name, v] : verbs()) {
      std::ostringstream table;
      std::streambuf* const out = std::cout.rdbuf(table.rdbuf());
      v.run({"--flags-json"});
      std::cout.rdbuf(out);
      all[name] = nlohmann::json::parse(table.str());
    }
    std::cout << all.dump(1) << "\n";
    return 0;
  }
  const auto it = verbs().find(argv[1]);
  if (it == verbs().end()) {
    std::cerr << "weilgen: unknown verb '" << argv[1] << "' (try weilgen --help)\n";
    return 2;
  }
  weilgen::cli::Args args(argv + 2, argv + argc);
  try {
    return it->second.run(args);
  } catch (const std::invalid_argument& e) {
    std::cerr << "weilgen " << argv[1] << ": " << e.what() << "\n";
    return 2;
  } catch (const weilgen::InputError& e) {
    std::cerr << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    std::cerr << "weilgen " << argv[1] << ": " << e.what() << "\n";
    return 1;
  }
}
