#include <Python.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <thread>

#include "binding.hpp"
#include "weilgen/base/error.hpp"
#include "weilgen/base/parallel.hpp"

namespace weilgen::python {

namespace {

// The exception classes, created once at import and kept for the life of the process.
PyObject* g_error = nullptr;
PyObject* g_argument_error = nullptr;
PyObject* g_input_error = nullptr;
PyObject* g_run_error = nullptr;
PyObject* g_warning = nullptr;

PyObject* new_class(const char* name, const char* doc, py::tuple bases) {
  PyObject* c = PyErr_NewExceptionWithDoc(name, doc, bases.ptr(), nullptr);
  if (!c) throw py::error_already_set();
  return c;
}

// Raises `type(message)` with exit_code (the CLI's exit status for the same problem) and,
// for a file, where in it.
void raise(PyObject* type, const std::string& message, int exit_code,
           const SourceLoc* loc = nullptr) {
  py::object exc = py::reinterpret_borrow<py::object>(type)(message);
  exc.attr("exit_code") = exit_code;
  if (loc) {
    exc.attr("file") = loc->file;
    exc.attr("line") = loc->line;
    exc.attr("column") = loc->column;
  }
  PyErr_SetObject(type, exc.ptr());
}

}  // namespace

void register_errors(py::module_& m) {
  g_error = new_class("weilgen.Error",
                      "Base of every weilgen error. exit_code: the CLI's exit status for the same "
                      "problem (2 bad arguments, 3 bad input file, 1 failure).",
                      py::make_tuple(py::handle(PyExc_Exception)));
  g_argument_error = new_class(
      "weilgen.ArgumentError",
      "A bad argument; the message names the CLI flag (--grid: ...), as `weilgen` prints it.",
      py::make_tuple(py::handle(g_error), py::handle(PyExc_ValueError)));
  g_input_error = new_class(
      "weilgen.InputError",
      "Bad input in a file; the message is file:line:column: ..., and file, line and column are "
      "attributes (0 when unknown).",
      py::make_tuple(py::handle(g_error), py::handle(PyExc_ValueError)));
  g_run_error = new_class("weilgen.RunError",
                          "A run that failed: a model that did not compile, gnuplot missing ...",
                          py::make_tuple(py::handle(g_error), py::handle(PyExc_RuntimeError)));
  g_warning = new_class("weilgen.Warning", "A reader's warning (an unknown column allowed ...).",
                        py::make_tuple(py::handle(PyExc_UserWarning)));
  m.add_object("Error", py::handle(g_error));
  m.add_object("ArgumentError", py::handle(g_argument_error));
  m.add_object("InputError", py::handle(g_input_error));
  m.add_object("RunError", py::handle(g_run_error));
  m.add_object("Warning", py::handle(g_warning));

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      raise(g_input_error, e.what(), 3, &e.loc());
    } catch (const std::invalid_argument& e) {
      raise(g_argument_error, e.what(), 2);
    } catch (const py::builtin_exception&) {
      throw;  // pybind11's own (TypeError ...): its translator
    } catch (const std::runtime_error& e) {
      raise(g_run_error, e.what(), 1);
    }
  });
}

std::function<void(const std::string&)> Messages::log() const {
  if (quiet_) return {};
  return [](const std::string& message) {
    py::gil_scoped_acquire gil;
    try {
      py::module_::import("sys").attr("stderr").attr("write")("weilgen: " + message + "\n");
    } catch (const py::error_already_set&) {
      // A closed or missing sys.stderr: the message is only informative.
    }
  };
}

std::function<void(const std::string&)> Messages::warn() {
  return [this](const std::string& w) {
    std::lock_guard<std::mutex> lock(mutex_);
    warnings_.push_back(w);
  };
}

void Messages::issue() {
  for (const std::string& w : warnings_)
    if (PyErr_WarnEx(g_warning, w.c_str(), 1) != 0) throw py::error_already_set();
  warnings_.clear();
}

}  // namespace weilgen::python

namespace weilgen::python {

nlohmann::json run_analysis(const std::function<nlohmann::json()>& f) {
  // Python runs signal handlers on the main thread only: elsewhere nothing can interrupt.
  const py::module_ threading = py::module_::import("threading");
  if (!threading.attr("main_thread")().is(threading.attr("current_thread")()))
    return without_gil(f);
  std::atomic<bool> cancel{false};
  nlohmann::json result;
  std::exception_ptr error;
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;
  PyObject *type = nullptr, *value = nullptr, *traceback = nullptr;  // the handler's exception
  {
    py::gil_scoped_release release;
    std::thread worker([&] {
      const CancelScope scope(&cancel);
      try {
        result = f();
      } catch (...) {
        error = std::current_exception();
      }
      const std::lock_guard<std::mutex> lock(mutex);
      done = true;
      finished.notify_one();
    });
    std::unique_lock<std::mutex> lock(mutex);
    while (!finished.wait_for(lock, std::chrono::milliseconds(20), [&] { return done; })) {
      if (type) continue;  // interrupted: waiting for the worker to stop
      lock.unlock();
      {
        py::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() != 0) {
          PyErr_Fetch(&type, &value, &traceback);
          cancel = true;
        }
      }
      lock.lock();
    }
    lock.unlock();
    worker.join();
  }
  if (type) {
    PyErr_Restore(type, value, traceback);
    throw py::error_already_set();
  }
  if (error) std::rethrow_exception(error);
  return result;
}

}  // namespace weilgen::python
