// weilgen.Model: a machine's error model, opened like the CLI opens it (built in, cached,
// compiled at run time or the numeric chain: analysis/study.hpp's open_model), evaluated over
// many poses at once.
#include <algorithm>
#include <sstream>

#include "binding.hpp"
#include "weilgen/base/parallel.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/codegen/emit_report.hpp"
#include "weilgen/codegen/model_builder.hpp"
#include "weilgen/machine/model_key.hpp"
#include "weilgen/machine/outputs.hpp"
#include "weilgen/machine/yaml_loader.hpp"
#include "weilgen/report/json_common.hpp"

namespace weilgen::python {

namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

struct PyModel {
  std::shared_ptr<const Model> model;
  StudyRequest request;  // how it was opened: machine, order, engine, compiler, params
  // The model at other parameter values (deviation(..., params=...)): the last one asked for.
  std::vector<double> other_values;
  std::shared_ptr<const Model> other;
  std::shared_ptr<const gen::SymbolicModel> symbolic;  // closed_form's, built on first use
};

const char* base_unit(const ErrorDef& e) {
  return e.effect == ErrorEffect::Rotation ? "rad" : "mm";
}

std::string shape_text(const Array& a) {
  std::vector<std::string> dims;
  for (py::ssize_t d = 0; d < a.ndim(); ++d) dims.push_back(std::to_string(a.shape(d)));
  return "(" + join(dims) + (a.ndim() == 1 ? ",)" : ")");
}

// An N x width (or width) array of float64 named `what` in messages: the rows and whether it
// has a leading dimension.
struct Rows {
  Array array;
  std::size_t n = 1;
  bool stacked = false;
  const double* row(std::size_t i, std::size_t width) const {
    return array.data() + (stacked ? i * width : 0);
  }
};

Rows rows(const std::string& function, py::handle value, const char* what, std::size_t width,
          const std::vector<std::string>& names, const char* unit) {
  Rows r;
  try {
    r.array = py::cast<Array>(value);
  } catch (const py::error_already_set&) {  // numpy's ValueError or TypeError
    throw std::invalid_argument(function + ": " + what + " must be an array of numbers");
  } catch (const py::cast_error&) {
    throw std::invalid_argument(function + ": " + what + " must be an array of numbers");
  }
  const auto expect = [&] {
    return function + ": " + what + " must have shape (" + std::to_string(width) + ",) or (N, " +
           std::to_string(width) + ") — " + join(names) + " in " + unit + " — not " +
           shape_text(r.array);
  };
  if (r.array.ndim() == 1) {
    if (static_cast<std::size_t>(r.array.shape(0)) != width) throw std::invalid_argument(expect());
  } else if (r.array.ndim() == 2) {
    if (static_cast<std::size_t>(r.array.shape(1)) != width) throw std::invalid_argument(expect());
    r.n = static_cast<std::size_t>(r.array.shape(0));
    r.stacked = true;
  } else {
    throw std::invalid_argument(expect());
  }
  return r;
}

std::vector<std::string> axis_names(const Description& d) {
  std::vector<std::string> v;
  for (int b : d.axes()) v.push_back(d.bodies[static_cast<std::size_t>(b)].joint.coordinate);
  return v;
}
std::vector<std::string> axis_units(const Description& d) {
  std::vector<std::string> v;
  for (int b : d.axes()) v.push_back(d.bodies[static_cast<std::size_t>(b)].joint.unit);
  return v;
}
std::vector<std::string> param_names(const Description& d) {
  std::vector<std::string> v;
  for (const auto& p : d.parameters) v.push_back(p.name);
  return v;
}

// The model at the parameter values `params` (None: as opened; a dict by name; a sequence in
// .params order, mm or deg).
std::shared_ptr<const Model> at_params(PyModel& pm, const std::string& function,
                                       py::handle params) {
  if (params.is_none()) return pm.model;
  const Description& d = pm.model->description();
  std::vector<double> values = pm.model->parameters();
  const std::vector<std::string> names = param_names(d);
  if (py::isinstance<py::dict>(params)) {
    for (auto item : py::reinterpret_borrow<py::dict>(params)) {
      const std::string name = py::str(item.first);
      const auto it = std::find(names.begin(), names.end(), name);
      if (it == names.end())
        throw std::invalid_argument(function + ": params: unknown parameter \"" + name +
                                    "\" (machine " + d.name + " has " +
                                    (names.empty() ? std::string("none") : join(names)) + ")");
      values[static_cast<std::size_t>(it - names.begin())] =
          py::float_(py::reinterpret_borrow<py::object>(item.second)).cast<double>();
    }
  } else {
    const Rows r = rows(function, params, "params", names.size(), names, "mm or deg");
    if (r.stacked)
      throw std::invalid_argument(function +
                                  ": params: one set of parameters (a dict, or a sequence in "
                                  ".params order), not one per row");
    values.assign(r.row(0, 0), r.row(0, 0) + names.size());
  }
  if (values == pm.model->parameters()) return pm.model;
  if (!pm.other || values != pm.other_values) {
    StudyRequest request = pm.request;
    request.params.clear();
    std::shared_ptr<Model> m = without_gil([&] { return open_model(request, d); });
    m->set_parameters(values);
    pm.other = std::move(m);
    pm.other_values = values;
  }
  return pm.other;
}

// Evaluates `body(model, data, i)` for every row in parallel blocks (results do not depend on
// the thread count: each row is independent), without the GIL.
template <typename Body>
void for_rows(const Model& model, std::size_t n, const Body& body) {
  without_gil([&] {
    const unsigned threads = n < 4096 ? 1u : resolve_threads(0);
    std::vector<ModelData> data(threads, ModelData(model));
    parallel_blocks(n, 1024, threads,
                    [&](std::size_t, std::size_t begin, std::size_t end, unsigned t) {
                      for (std::size_t i = begin; i < end; ++i) body(data[t], i);
                    });
    return 0;
  });
}

py::array_t<double> deviation(PyModel& pm, py::handle axes, py::handle errors, py::handle params) {
  const std::shared_ptr<const Model> model = at_params(pm, "deviation", params);
  const Description& d = model->description();
  const std::size_t k = model->num_axes(), ne = model->num_errors();
  const Rows a = rows("deviation", axes, "axes", k, axis_names(d), "mm or deg");
  const Rows e = rows("deviation", errors, "errors", ne, error_names(d), "mm or rad");
  if (a.stacked && e.stacked && a.n != e.n)
    throw std::invalid_argument("deviation: axes has " + std::to_string(a.n) +
                                " rows but errors has " + std::to_string(e.n));
  const bool stacked = a.stacked || e.stacked;
  const std::size_t n = a.stacked ? a.n : e.n;
  py::array_t<double> out = stacked
                                ? py::array_t<double>({static_cast<py::ssize_t>(n), py::ssize_t{6}})
                                : py::array_t<double>(py::ssize_t{6});
  double* o = out.mutable_data();
  for_rows(*model, n, [&](ModelData& data, std::size_t i) {
    model->deviation(data, a.row(i, k), e.row(i, ne), o + 6 * i);
  });
  return out;
}

py::array_t<double> coefficients(PyModel& pm, py::handle axes, py::handle params) {
  const std::shared_ptr<const Model> model = at_params(pm, "coefficients", params);
  const std::size_t k = model->num_axes(), ne = model->num_errors();
  const Rows a =
      rows("coefficients", axes, "axes", k, axis_names(model->description()), "mm or deg");
  const auto n6 = py::ssize_t{6}, pne = static_cast<py::ssize_t>(ne);
  py::array_t<double> out = a.stacked
                                ? py::array_t<double>({static_cast<py::ssize_t>(a.n), n6, pne})
                                : py::array_t<double>({n6, pne});
  double* o = out.mutable_data();
  for_rows(*model, a.n, [&](ModelData& data, std::size_t i) {
    model->coefficients(data, a.row(i, k), o + 6 * ne * i);
  });
  return out;
}

// `weilgen show`'s text for the model's machine and order: every output or `output` alone, in
// `format` text, latex, sympy (Python syntax) or json (the document, as a dict).
py::object closed_form(PyModel& pm, const std::string& output, const std::string& notation,
                       const std::string& format) {
  if (format != "text" && format != "latex" && format != "json" && format != "sympy")
    throw std::invalid_argument(
        "closed_form: format must be 'text', 'latex', 'sympy-string' or "
        "'json', not '" +
        format + "'");
  if (notation != "iso" && notation != "alias")
    throw std::invalid_argument("closed_form: notation must be 'iso' or 'alias', not '" + notation +
                                "'");
  int only = -1;
  for (std::size_t o = 0; o < kNumDeviationOutputs; ++o)
    if (output == output_name(o)) only = static_cast<int>(o);
  if (!output.empty() && only < 0)
    throw std::invalid_argument("closed_form: unknown output '" + output + "' (dx dy dz da db dc)");
  if (!pm.symbolic) {
    const Description& d = pm.model->description();
    const int order = pm.model->order();
    pm.symbolic = without_gil(
        [&] { return std::make_shared<const gen::SymbolicModel>(gen::build_model(d, order)); });
  }
  const gen::SymbolicModel& m = *pm.symbolic;
  const gen::Notation n = notation == "iso" ? gen::Notation::Iso : gen::Notation::Alias;
  if (format == "json") {
    nlohmann::json j = json_document("show", gen::closed_forms_json(m, n));
    if (only >= 0) j["outputs"] = {{output, j["outputs"][output]}};
    return to_python(j);
  }
  const auto style = format == "latex"   ? gen::FormStyle::Latex
                     : format == "sympy" ? gen::FormStyle::Sympy
                                         : gen::FormStyle::Text;
  std::string text;
  for (int o = 0; o < kNumDeviationOutputs; ++o)
    if (only < 0 || only == o) text += gen::closed_form(m, o, style, n) + "\n";
  return py::str(text);
}

// The shipped machines (`weilgen list`): name, title, file, axes, axis units, errors, order.
py::list machines() {
  py::list out;
  for (const std::string& file : shipped_machine_files()) {
    const Description d = load_machine_file(file);
    py::dict m;
    m["name"] = d.name;
    m["title"] = d.title;
    m["file"] = file;
    m["axes"] = axis_names(d);
    m["axis_units"] = axis_units(d);
    m["errors"] = d.errors.size();
    m["order"] = d.algebra.order;
    m["params"] = param_names(d);
    out.append(std::move(m));
  }
  return out;
}

}  // namespace

const std::vector<const char*>& model_keywords() {
  static const std::vector<const char*> names = {"order", "engine", "compiler", "param", "quiet"};
  return names;
}

void model_request(py::handle machine, const Keywords& kw, StudyRequest& r,
                   std::shared_ptr<const Model>& opened) {
  if (py::isinstance<PyModel>(machine)) {
    for (const char* name : {"order", "engine", "compiler", "param"})
      if (kw.given(name))
        throw std::invalid_argument(std::string(name) +
                                    "= is for a machine name or file; this weilgen.Model was "
                                    "opened with its own (pass the name instead)");
    const PyModel& pm = machine.cast<const PyModel&>();
    opened = pm.model;
    r.machine = pm.request.machine;
    r.order = pm.request.order;
    r.engine = pm.request.engine;
    r.compiler = pm.request.compiler;
    r.params = pm.request.params;
  } else {
    r.machine = value_text(machine, "machine");
    kw.set("order", r.order);
    kw.set("engine", r.engine);
    kw.set("compiler", r.compiler);
    r.params = kw.items("param", false);
    opened = nullptr;
  }
  r.log = Messages(kw.flag("quiet")).log();
}

void register_model(py::module_& m) {
  m.def("_machines", &machines);
  m.def("_use_machines_dir", &use_shipped_machines_dir, py::arg("dir"));
  py::class_<PyModel>(m, "Model", R"doc(A machine's error model (docs/python.md).

Model(machine, order=None, *, engine=None, compiler=None, param=None, quiet=False)

machine: a shipped machine's name ('gantry_grinder') or a machine file. order: the algebra
order (None: the file's). engine: 'auto' (built in, cached or compiled; the numeric chain
without a compiler), 'compiled' or 'numeric'. compiler: the C++ compiler for machines that are
not built in ('none': no compilation). param: machine parameters, {'tool_length': 150} or
['tool_length=150mm'] (mm, deg). quiet: no model messages on stderr.)doc")
      .def(py::init([](py::handle machine, py::handle order, const py::kwargs& kwargs) {
             py::kwargs all(kwargs);
             if (!order.is_none()) all["order"] = order;
             const Keywords kw("Model", all, model_keywords());
             PyModel pm;
             std::shared_ptr<const Model> opened;
             model_request(machine, kw, pm.request, opened);
             if (opened) {
               pm.model = opened;
               return pm;
             }
             if (pm.request.machine.empty()) throw std::invalid_argument("no machine given");
             pm.model = without_gil([&] {
               const Description desc = load_machine_file(resolve_machine(pm.request.machine));
               return std::shared_ptr<const Model>(open_model(pm.request, desc));
             });
             return pm;
           }),
           py::arg("machine"), py::arg("order") = py::none())
      .def_property_readonly("name", [](const PyModel& p) { return p.model->name(); })
      .def_property_readonly("order", [](const PyModel& p) { return p.model->order(); })
      .def_property_readonly(
          "engine", [](const PyModel& p) { return std::string(engine_name(p.model->engine())); },
          "'built-in', 'compiled' or 'numeric chain'")
      .def_property_readonly(
          "origin", [](const PyModel& p) { return p.model->origin(); },
          "where the model comes from: 'built-in', 'compiled (<path>)', 'numeric chain (...)'")
      .def_property_readonly(
          "source", [](const PyModel& p) { return p.model->description().source_file; },
          "the machine file")
      .def_property_readonly(
          "key",
          [](const PyModel& p) {
            return model_key(p.model->description().source_hash, p.model->order());
          },
          "the content key of the model (machine text, order, weilgen version)")
      .def_property_readonly(
          "axes", [](const PyModel& p) { return axis_names(p.model->description()); },
          "the axis coordinates, in the order of deviation()'s axes columns (the header's kAxes)")
      .def_property_readonly(
          "axis_units", [](const PyModel& p) { return axis_units(p.model->description()); },
          "each axis's unit: 'mm' (linear) or 'deg' (rotary)")
      .def_property_readonly(
          "errors", [](const PyModel& p) { return error_names(p.model->description()); },
          "the error names (ISO 230-1: E_XX, E_C0Y ...), in the order of the errors columns")
      .def_property_readonly(
          "error_units",
          [](const PyModel& p) {
            std::vector<std::string> v;
            for (const auto& e : p.model->description().errors) v.push_back(base_unit(e));
            return v;
          },
          "the unit deviation() takes each error in: 'mm' (translations) or 'rad' (rotations)")
      .def_property_readonly(
          "params", [](const PyModel& p) { return param_names(p.model->description()); },
          "the machine parameters' names (tool_length ...), in the order of params arrays")
      .def_property_readonly(
          "param_units",
          [](const PyModel& p) {
            std::vector<std::string> v;
            for (const auto& q : p.model->description().parameters) v.push_back(q.unit);
            return v;
          },
          "each parameter's unit: 'mm' or 'deg'")
      .def_property_readonly(
          "param_values",
          [](const PyModel& p) {
            const auto& v = p.model->parameters();
            py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
            std::copy(v.begin(), v.end(), a.mutable_data());
            return a;
          },
          "the parameter values the model evaluates with (mm, deg)")
      .def_property_readonly(
          "outputs",
          [](const PyModel&) {
            std::vector<std::string> v;
            for (std::size_t o = 0; o < kNumDeviationOutputs; ++o) v.push_back(output_name(o));
            return v;
          },
          "dx dy dz da db dc: the columns of deviation() and rows of coefficients()")
      .def_property_readonly(
          "output_units",
          [](const PyModel&) {
            std::vector<std::string> v;
            for (std::size_t o = 0; o < kNumDeviationOutputs; ++o) v.push_back(output_unit(o));
            return v;
          },
          "'mm' for dx dy dz, 'rad' for da db dc")
      .def_property_readonly(
          "info", [](const PyModel& p) { return to_python(model_json(*p.model)); },
          "the model block of every document: machine, source, order, key, engine, origin, axes")
      .def("deviation", &deviation, py::arg("axes"), py::arg("errors"),
           py::arg("params") = py::none(),
           R"doc(The tool point's deviation: (dx, dy, dz) in mm and (da, db, dc) in rad.

axes: (N, k) or (k,) axis positions in .axes order and .axis_units (mm, deg).
errors: (N, n) or (n,) error values in .errors order and .error_units (mm, rad).
Either may be one row for all. params: None, a dict by name, or a sequence in .params order.
Returns (N, 6), or (6,) when both are one row.)doc")
      .def("coefficients", &coefficients, py::arg("axes"), py::arg("params") = py::none(),
           R"doc(d(output)/d(error) at zero error: (N, 6, n), or (6, n) for one row of axes.

Rows dx dy dz in mm per error unit, da db dc in rad per error unit (errors in .error_units).)doc")
      .def_property_readonly(
          "axis_ranges",
          [](const PyModel& p) {
            py::list out;
            const Description& d = p.model->description();
            for (int b : d.axes()) {
              const Joint& j = d.bodies[static_cast<std::size_t>(b)].joint;
              out.append(j.min < j.max ? py::object(py::make_tuple(j.min, j.max)) : py::none());
            }
            return out;
          },
          "each axis's travel (min, max) in its unit (mm, deg), or None when the file gives none")
      .def_property_readonly(
          "_state",
          [](const PyModel& p) {
            py::dict s;
            s["machine"] = p.request.machine;
            s["order"] = p.request.order;
            s["engine"] = p.request.engine;
            s["compiler"] = p.request.compiler;
            s["param"] = p.request.params;
            return s;
          },
          "how the model was opened (pickling opens it again)")
      .def("_closed_form", &closed_form, py::arg("output"), py::arg("notation"), py::arg("format"))
      .def("__repr__", [](const PyModel& p) {
        std::ostringstream os;
        os << "<weilgen.Model " << p.model->name() << " order " << p.model->order() << " ("
           << engine_name(p.model->engine()) << "): " << p.model->num_axes() << " axes, "
           << p.model->num_errors() << " errors, " << p.model->num_params() << " parameters>";
        return os.str();
      });
}

}  // namespace weilgen::python
