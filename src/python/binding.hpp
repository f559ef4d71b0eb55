// What the Python module's files share: keyword arguments as the CLI's flag text, the machine
// argument (a name, a file or a weilgen.Model), documents as Python objects, the exceptions,
// and running C++ without the GIL. The module is a front end like cli/: the analyses, their
// flag parsers and their documents are the libraries' (docs/python.md).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "weilgen/analysis/study.hpp"
#include "weilgen/base/range.hpp"

namespace weilgen::python {

namespace py = pybind11;

// ---- keywords.cpp: keyword arguments as flags --------------------------------------------

// One flag of a verb as `weilgen <verb> --flags-json` describes it (cli/flags.hpp, flags_json):
// the package loads the table at import (weilgen/_flags.json, written by the build from the CLI)
// and the keywords are checked against it as the CLI checks the flags.
struct FlagSpec {
  std::string kind;                  // switch, repeatable, number, whole, text
  std::optional<std::string> def;    // the default as --help shows it
  std::optional<NumberRange> range;  // numbers: what the flag admits
};
void use_flag_tables(const std::string& json_text);
// The flag `keyword` of the verb of `function` (iso230_2: iso230-2; Model: the model flags), or
// null when the table has none.
const FlagSpec* flag_spec(const std::string& function, const std::string& keyword);
// What each function implements: function -> its keywords (the parity test compares them with
// the CLI's flags, tests/python/test_parity.py).
std::map<std::string, std::vector<std::string>>& implemented_keywords();

// The keyword arguments of one call, checked against the function's keywords. A keyword's
// flag is its name with '_' as '-' (rank_tol: --rank-tol); messages name the flag, as the
// CLI's do. Values are checked as the CLI checks them (kind and range of the flag table) before
// anything runs. Values that are None count as not given.
class Keywords {
 public:
  // ArgumentError for a keyword the function does not take, or a value its flag refuses.
  Keywords(const char* function, const py::kwargs& kwargs, const std::vector<const char*>& names);

  // Given, and not the flag's default (the wrapper passes every default: left out is the CLI's
  // default, and a flag at its default counts as not given, as for the CLI's checks of flags
  // that need another).
  bool given(const char* name) const;
  // A flag that takes text: a str or os.PathLike (a number is written as Python writes it).
  std::optional<std::string> text(const char* name) const;
  // Flags that take NAME=VALUE items (--set, --param, --pdge) or lists: None -> {}; a str ->
  // {str}; a list or tuple -> one flag per element (a dict element: "K=V,K=V"); a dict -> one
  // flag "K=V,K=V" when `one_flag` (--at, --grid, --tolerance), else one "K=V" flag per item.
  // A value may be a str ("0.03mm", "-1500:1500:5"), a number, or a (start, stop, count) tuple.
  std::vector<std::string> items(const char* name, bool one_flag) const;
  // A comma-separated list (--outputs, --errors): a str, or a list of str.
  std::optional<std::string> list(const char* name) const;
  std::optional<double> number(const char* name) const;
  // A whole number >= 0 (--samples, --seed, --threads).
  std::optional<std::uint64_t> count(const char* name) const;
  std::optional<long> integer(const char* name) const;
  bool flag(const char* name) const;  // a switch: True or False

  template <typename T>
  void set(const char* name, T& field) const;  // field = the value when given

  std::string flag_name(const char* name) const;  // "--rank-tol" for rank_tol

 private:
  py::handle value(const char* name) const;
  std::string function_;
  py::dict kwargs_;
};

// Python's text for a number (the shortest that reads back exactly), a str as it is.
std::string value_text(py::handle v, const std::string& flag);

// ---- model.cpp: weilgen.Model and the machine argument ------------------------------------

// The machine argument of an analysis: a shipped machine's name, a machine file (str or
// os.PathLike) or a weilgen.Model. Fills the model part of a request (machine, order, engine,
// compiler, params, log) from it and the keywords order, engine, compiler, param and quiet;
// `opened` is the Model's model, or null for a name or file. ArgumentError for model keywords
// given with a Model (it was opened with its own).
void model_request(py::handle machine, const Keywords& kw, StudyRequest& request,
                   std::shared_ptr<const Model>& opened);
// The keywords model_request reads.
const std::vector<const char*>& model_keywords();
void register_model(py::module_& m);

// ---- documents.cpp: JSON documents as Python objects --------------------------------------

// null -> None, numbers -> int/float, objects -> dict, arrays of numbers (null as NaN) ->
// numpy arrays (int64 when every element is an integer; a rectangular nest of such arrays
// becomes one n-dimensional array), other arrays -> list. An object keyed by error names
// (dR_dmu, a step's spreads) lists them in the model's order (`errors`), not the JSON's
// alphabetical one.
py::object to_python(const nlohmann::json& document, const std::vector<std::string>& errors = {});
void register_documents(py::module_& m);  // weilgen.plain

// ---- errors.cpp: exceptions, messages, the GIL --------------------------------------------

void register_errors(py::module_& m);
// The CLI's stderr messages for a Python caller: model messages ("compiling model ...") go to
// sys.stderr at once unless `quiet`; the readers' warnings are collected while the GIL is
// released and issued as Python warnings (weilgen.Warning) by issue().
class Messages {
 public:
  explicit Messages(bool quiet) : quiet_(quiet) {}
  std::function<void(const std::string&)> log() const;
  std::function<void(const std::string&)> warn();
  void issue();

 private:
  bool quiet_;
  std::mutex mutex_;
  std::vector<std::string> warnings_;
};

// Runs `f` with the GIL released (a model evaluation, or opening a model).
template <typename F>
auto without_gil(F&& f) {
  py::gil_scoped_release release;
  return f();
}

// Runs an analysis without the GIL and interruptibly: called from the main thread, `f` runs on a
// worker thread while the caller polls Python's signal handlers every 20 ms; a handler's
// exception (KeyboardInterrupt for Ctrl-C) cancels the run (base/parallel.hpp, CancelScope) and
// is raised once the worker has stopped. From another thread (where Python runs no signal
// handlers) it is without_gil(f).
nlohmann::json run_analysis(const std::function<nlohmann::json()>& f);

// ---- the analyses ---------------------------------------------------------------------------

void register_study_functions(py::module_& m);    // sensitivity, reliability, allocate
void register_data_functions(py::module_& m);     // iso230_2, fit_pdge, identify, gap
void register_generate_function(py::module_& m);  // generate
void register_plan_function(py::module_& m);      // plan

template <typename T>
void Keywords::set(const char* name, T& field) const {
  if constexpr (std::is_same_v<T, std::string>) {
    if (auto v = text(name)) field = *v;
  } else if constexpr (std::is_same_v<T, bool>) {
    if (given(name)) field = flag(name);
  } else if constexpr (std::is_floating_point_v<T>) {
    if (auto v = number(name)) field = *v;
  } else if constexpr (std::is_signed_v<T>) {
    if (auto v = integer(name)) {
      if (*v < std::numeric_limits<T>::min() || *v > std::numeric_limits<T>::max())
        throw std::invalid_argument(flag_name(name) + ": " + std::to_string(*v) +
                                    " is out of range");
      field = static_cast<T>(*v);
    }
  } else {
    if (auto v = count(name)) {
      if (*v > std::numeric_limits<T>::max())
        throw std::invalid_argument(flag_name(name) + ": " + std::to_string(*v) +
                                    " is out of range");
      field = static_cast<T>(*v);
    }
  }
}

}  // namespace weilgen::python
