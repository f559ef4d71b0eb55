// The extension `weilgen._weilgen` under the package `weilgen` (src/python/weilgen/):
// weilgen.Model's C++ part, the analyses taking the CLI's flags as keywords and returning the
// documents its
// --json writes, and the exceptions. The package gives them signatures, docstrings and a stub
// built from the CLI's flag table (docs/python.md).
#include "binding.hpp"
#include "weilgen/base/version.hpp"

PYBIND11_MODULE(_weilgen, m) {
  namespace wp = weilgen::python;
  m.doc() = "weilgen's extension module: use the package `weilgen` (docs/python.md).";
  m.attr("__version__") = weilgen::kVersion;
  m.def("_use_flag_tables", &wp::use_flag_tables, pybind11::arg("json_text"),
        "The verbs' flag tables (`weilgen --flags-json`): kinds, defaults and ranges.");
  m.def(
      "_implemented", [] { return wp::implemented_keywords(); },
      "function -> the keywords the extension implements");
  wp::register_errors(m);
  wp::register_documents(m);
  wp::register_model(m);
  wp::register_study_functions(m);
  wp::register_data_functions(m);
  wp::register_generate_function(m);
  wp::register_plan_function(m);
}
