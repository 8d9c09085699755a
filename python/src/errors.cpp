// The module's exceptions (python/src/errors.hpp).
#include "errors.hpp"

#include "hoist/io/error.hpp"
#include "hoist/io/estimator_config.hpp"
#include "hoist/io/sim_run.hpp"
#include "hoist/params.hpp"
#include "run.hpp"

namespace py = pybind11;

namespace hoist::python {

namespace {
// Owned by the module for the interpreter's life (never released: classes).
PyObject* g_input = nullptr;
PyObject* g_config = nullptr;
PyObject* g_profile = nullptr;
PyObject* g_measurement = nullptr;
PyObject* g_run = nullptr;

PyObject* newClass(py::module_& m, const char* name, PyObject* base, const char* doc) {
  const std::string full = "hoist." + std::string(name);
  PyObject* c = PyErr_NewExceptionWithDoc(full.c_str(), doc, base, nullptr);
  if (!c) throw py::error_already_set();
  m.add_object(name, py::reinterpret_borrow<py::object>(c));
  return c;
}

[[noreturn]] void setError(PyObject* type, const std::string& message, const io::InputError* in, long index) {
  py::object exc = py::reinterpret_borrow<py::object>(type)(message);
  if (in) {
    exc.attr("source") = in->source();
    exc.attr("line") = in->line();
    exc.attr("key") = in->key();
  }
  exc.attr("index") = index >= 0 ? py::object(py::int_(index)) : py::object(py::none());
  PyErr_SetObject(type, exc.ptr());
  throw py::error_already_set();
}
}  // namespace

void raise(std::exception_ptr e, const std::string& prefix, long index) {
  try {
    std::rethrow_exception(e);
  } catch (const py::error_already_set&) {
    throw;
  } catch (const io::ConfigError& x) {
    setError(g_config, prefix + x.what(), &x, index);
  } catch (const io::ProfileError& x) {
    setError(g_profile, prefix + x.what(), &x, index);
  } catch (const io::MeasurementError& x) {
    setError(g_measurement, prefix + x.what(), &x, index);
  } catch (const io::InputError& x) {
    setError(g_input, prefix + x.what(), &x, index);
  } catch (const io::OptionError& x) {
    setError(PyExc_ValueError, prefix + x.what(), nullptr, index);
  } catch (const ParamError& x) {
    setError(PyExc_ValueError, prefix + x.what(), nullptr, index);
  } catch (const RunError& x) {
    setError(g_run, prefix + x.what(), nullptr, index);
  } catch (const std::bad_alloc&) {
    setError(PyExc_MemoryError, prefix + "out of memory", nullptr, index);
  } catch (const std::exception& x) {
    setError(g_run, prefix + x.what(), nullptr, index);
  } catch (...) {
    setError(g_run, prefix + "unexpected failure (not a std::exception)", nullptr, index);
  }
}

void bindErrors(py::module_& m) {
  g_input = newClass(m, "InputError", PyExc_ValueError,
                     "Bad input (configuration, profile, measurements): .source (file), .line (1-based, 0 if "
                     "unknown), .key (TOML key or CSV column); the message is the programs' own.");
  g_config = newClass(m, "ConfigError", g_input, "An error in a shaft configuration (TOML or Config.set).");
  g_profile = newClass(m, "ProfileError", g_input, "An error in a hoist profile (CSV, SPEC or arrays).");
  g_measurement = newClass(m, "MeasurementError", g_input, "An error in the estimator's measurements.");
  g_run = newClass(m, "RunError", PyExc_RuntimeError,
                   "The run failed: the state became non-finite or implausible, or left the model's domain.");
  py::register_exception_translator([](std::exception_ptr p) {
    if (!p) return;
    try {
      std::rethrow_exception(p);
    } catch (const io::InputError&) {
      raise(p);
    } catch (const io::OptionError&) {
      raise(p);
    } catch (const ParamError&) {
      raise(p);
    } catch (const RunError&) {
      raise(p);
    }
  });
}

}  // namespace hoist::python
