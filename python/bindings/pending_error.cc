// The per-call slots of Python errors raised inside Ceres (pending_error.h).
#include "pending_error.h"

#include <string>

#include "boxplus/errors.h"
#include "errors.h"

namespace py = pybind11;

namespace boxplus::python {
namespace {
thread_local ErrorScope* current_scope = nullptr;
}  // namespace

void ErrorSlot::Store(py::error_already_set&& e) {
  if (!error_) error_ = std::make_unique<py::error_already_set>(std::move(e));
}

ErrorScope::ErrorScope() : previous_(current_scope) { current_scope = this; }
ErrorScope::~ErrorScope() { current_scope = previous_; }

ErrorSlot& CurrentErrorSlot() {
  if (current_scope) return current_scope->slot();
  thread_local ErrorSlot fallback;
  fallback.Take().reset();  // drop the previous scope-less error (GIL held)
  return fallback;
}

void StorePendingCppError(const std::exception& e) {
  SetPythonError(e);
  StorePendingError(py::error_already_set());
}

}  // namespace boxplus::python
