// Where generation spends its time: the phases of `weilgen generate` timed one by one in one
// process (CPU seconds from std::clock, so that other load on a shared machine inflates them
// less than wall time), with the sizes they produce.
//
//   weilgen_bench_codegen_phases machines/pipe_cutter.yaml 3 [build|header|report]
//
// A phase name as third argument runs the phases up to that one only (to profile it alone).
// Phases: build_model (the chain over the Weil algebra: truncated products, the Neumann inverse,
// the logarithm, fractions over divisors, the nominal Jacobian), emit_cpp_header (CSE, printing)
// and emit_report_markdown (the closed forms).
#include <cstdio>
#include <ctime>
#include <stdexcept>
#include <string>

#include "weilgen/codegen/emit_cpp.hpp"
#include "weilgen/codegen/emit_report.hpp"
#include "weilgen/codegen/generate.hpp"
#include "weilgen/codegen/model_builder.hpp"
#include "weilgen/machine/yaml_loader.hpp"

namespace {
double cpu_seconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }
}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: %s MACHINE.yaml ORDER [build|header|report]\n", argv[0]);
    return 2;
  }
  try {
    const int order = std::stoi(argv[2]);
    double t = cpu_seconds();
    const weilgen::Description desc = weilgen::load_machine_file(argv[1]);
    const double t_load = cpu_seconds() - t;
    t = cpu_seconds();
    const weilgen::gen::SymbolicModel model = weilgen::gen::build_model(desc, order);
    const double t_build = cpu_seconds() - t;
    std::size_t terms = 0;
    for (const auto& p : model.outputs) terms += p.terms().size();
    const std::string last = argc == 4 ? argv[3] : "report";
    const std::string label = weilgen::gen::source_label(argv[1]);
    t = cpu_seconds();
    const std::string header =
        last == "build" ? std::string() : weilgen::gen::emit_cpp_header(model, label);
    const double t_header = cpu_seconds() - t;
    t = cpu_seconds();
    const std::string report =
        last == "report" ? weilgen::gen::emit_report_markdown(model, label) : std::string();
    const double t_report = cpu_seconds() - t;
    std::printf("| phase | CPU s | result |\n| --- | ---: | --- |\n");
    std::printf("| load machine file | %.3f | %zu errors |\n", t_load, desc.errors.size());
    std::printf("| build_model | %.3f | %zu (output, monomial) terms, %zu higher monomials |\n",
                t_build, terms, model.higher_monomials().size());
    std::printf("| emit_cpp_header | %.3f | %.1f KiB |\n", t_header, header.size() / 1024.0);
    std::printf("| emit_report_markdown | %.3f | %.1f KiB |\n", t_report, report.size() / 1024.0);
    std::printf("| total | %.3f | |\n", t_load + t_build + t_header + t_report);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 3;
  }
  return 0;
}
