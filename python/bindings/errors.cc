// C++ exceptions → Python, in one place: boxplus::Error → ValueError subclass
// BoxplusError, IndexError → IndexError subclass BoxplusIndexError,
// ParseError → ParseError(BoxplusError). Messages may echo bytes of a broken
// input file, so they are decoded with invalid bytes escaped.
#include "errors.h"

#include <new>
#include <stdexcept>
#include <string>

#include "bindings.h"
#include "boxplus/errors.h"

namespace py = pybind11;

namespace boxplus::python {
namespace {
// The exception classes, created once with the module (never freed: they
// live as long as the interpreter may raise them).
PyObject* boxplus_error = nullptr;
PyObject* index_error = nullptr;
PyObject* parse_error = nullptr;

void Raise(PyObject* type, const std::string& message) {
  PyErr_SetObject(type, SafeStr(message).ptr());
}
}  // namespace

py::str SafeStr(const std::string& bytes) {
  PyObject* s =
      PyUnicode_DecodeUTF8(bytes.data(), static_cast<Py_ssize_t>(bytes.size()), "backslashreplace");
  if (s == nullptr) throw py::error_already_set();
  return py::reinterpret_steal<py::str>(s);
}

void SetPythonError(const std::exception& e) {
  if (const auto* p = dynamic_cast<const ParseError*>(&e)) {
    py::object exc = py::reinterpret_borrow<py::object>(parse_error)(SafeStr(p->what()));
    exc.attr("file") = SafeStr(p->file());
    exc.attr("line") = p->line();
    PyErr_SetObject(parse_error, exc.ptr());
  } else if (dynamic_cast<const IndexError*>(&e)) {
    Raise(index_error, e.what());
  } else if (dynamic_cast<const Error*>(&e)) {
    Raise(boxplus_error, e.what());
  } else if (dynamic_cast<const std::bad_alloc*>(&e)) {
    PyErr_SetString(PyExc_MemoryError, "out of memory");
  } else if (dynamic_cast<const std::out_of_range*>(&e)) {
    Raise(PyExc_IndexError, e.what());
  } else if (dynamic_cast<const std::invalid_argument*>(&e) ||
             dynamic_cast<const std::domain_error*>(&e) ||
             dynamic_cast<const std::length_error*>(&e)) {
    Raise(PyExc_ValueError, e.what());
  } else {
    Raise(PyExc_RuntimeError, e.what());
  }
}

void RegisterErrors(py::module_& m) {
  auto make = [&](const char* name, PyObject* base, const char* doc) {
    PyObject* type = PyErr_NewExceptionWithDoc((std::string("boxplus._core.") + name).c_str(), doc,
                                               base, nullptr);
    if (type == nullptr) throw py::error_already_set();
    m.add_object(name, py::handle(type));
    return type;
  };
  boxplus_error = make("BoxplusError", PyExc_ValueError, "Bad input refused by boxplus.");
  index_error =
      make("BoxplusIndexError", PyExc_IndexError, "An id that names no variable or measurement.");
  parse_error =
      make("ParseError", boxplus_error, "A malformed input file; .file and .line name the place.");
  py::register_exception_translator([](std::exception_ptr p) {
    if (!p) return;
    try {
      std::rethrow_exception(p);
    } catch (const py::builtin_exception&) {
      throw;  // pybind11's own (value_error, index_error, ...) translate themselves
    } catch (const py::error_already_set&) {
      throw;
    } catch (const std::exception& e) {
      SetPythonError(e);
    }
  });
}

}  // namespace boxplus::python
