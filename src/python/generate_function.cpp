// weilgen.generate: `weilgen generate` with its flags as keywords (docs/python.md): each
// machine's model header and closed-form report, written atomically once every machine has
// generated, or (check=True) the files that are out of date.
#include "binding.hpp"
#include "weilgen/base/atomic_file.hpp"
#include "weilgen/base/output_paths.hpp"
#include "weilgen/codegen/generate.hpp"
#include "weilgen/machine/algebra_size.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/report/json_common.hpp"

namespace weilgen::python {

namespace {

const std::vector<const char*>& generate_keywords() {
  static const std::vector<const char*> v = {"order", "out", "check", "c_api"};
  return v;
}

py::object generate(py::handle machine, const py::kwargs& kwargs) {
  const Keywords kw("generate", kwargs, generate_keywords());
  std::vector<std::string> names;
  if (py::isinstance<py::list>(machine) || py::isinstance<py::tuple>(machine)) {
    for (py::handle m : machine) names.push_back(value_text(m, "machine"));
  } else if (!machine.is_none()) {
    names.push_back(value_text(machine, "machine"));
  }
  if (names.empty()) throw std::invalid_argument("no machine given");
  int order = 0;
  kw.set("order", order);
  std::string out = "generated";
  kw.set("out", out);
  const bool check = kw.flag("check"), c_api = kw.flag("c_api");
  Messages messages(true);
  const nlohmann::json doc = run_analysis([&] {
    // Every machine read and its size checked before anything is generated.
    std::vector<Description> machines;
    std::vector<PathArg> inputs;
    for (const std::string& m : names) {
      inputs.push_back({"machine file", resolve_machine(m)});
      machines.push_back(load_machine_file(inputs.back().path));
      const std::string warning =
          check_algebra_size(machines.back(), order, "--order " + std::to_string(order));
      if (!warning.empty()) messages.warn()(warning);
    }
    std::vector<gen::GeneratedFile> files;
    for (const Description& d : machines) {
      auto f = gen::generate_files(d, order, out, c_api);
      files.insert(files.end(), f.begin(), f.end());
    }
    nlohmann::json body;
    body["files"] = nlohmann::json::array();
    for (const auto& f : files) body["files"].push_back(f.path);
    if (check) {
      body["stale"] = gen::stale_files(files);
      return json_document("generate", body);
    }
    std::vector<PathArg> outputs;
    for (const auto& f : files) outputs.push_back({"--out", f.path});
    check_output_paths(inputs, outputs);
    body["written"] = nlohmann::json::array();
    for (const auto& f : files) {
      std::string old;
      if (read_file(f.path, old) && old == f.contents) continue;  // unchanged: keep its mtime
      write_file_atomically(f.path, f.contents);
      body["written"].push_back(f.path);
    }
    return json_document("generate", body);
  });
  messages.issue();
  return to_python(doc);
}

}  // namespace

void register_generate_function(py::module_& m) {
  m.def("generate", &generate, py::arg("machine"));
  implemented_keywords()["generate"].assign(generate_keywords().begin(), generate_keywords().end());
}

}  // namespace weilgen::python
