// C++ exceptions → Python: boxplus::Error → ValueError subclass BoxplusError,
// IndexError → IndexError subclass, ParseError → ParseError(BoxplusError).
#include "boxplus/errors.h"

#include "bindings.h"

namespace py = pybind11;

namespace boxplus::python {

void RegisterErrors(py::module_& m) {
  // pybind11 tries translators newest first: register the base class first.
  auto base = py::register_exception<Error>(m, "BoxplusError", PyExc_ValueError);
  py::register_exception<IndexError>(m, "BoxplusIndexError", PyExc_IndexError);
  py::register_exception<ParseError>(m, "ParseError", base.ptr());
}

}  // namespace boxplus::python
