// The `weilgen` Python module: weilgen.Model, the analyses as functions returning the CLI's
// JSON documents, and the exceptions (docs/python.md).
#include "binding.hpp"
#include "weilgen/base/version.hpp"

PYBIND11_MODULE(weilgen, m) {
  namespace wp = weilgen::python;
  m.doc() =
      "weilgen: machine-tool error models (docs/python.md).\n\n"
      "Model(machine) opens a machine's model (deviation, coefficients); sensitivity,\n"
      "reliability, allocate, iso230_2, fit_pdge, identify and gap run the CLI's analyses with\n"
      "its flags as keywords and return the documents its --json writes.";
  m.attr("__version__") = weilgen::kVersion;
  wp::register_errors(m);
  wp::register_documents(m);
  wp::register_model(m);
  wp::register_study_functions(m);
  wp::register_data_functions(m);
}
