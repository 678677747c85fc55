// The Python exception raised inside a callback that Ceres called (a Python
// measurement function, a Python manifold's ⊞). Ceres cannot carry it, so it
// is kept here, the solve is stopped, and Problem.solve re-raises it with its
// original traceback once Ceres has returned. One slot suffices: the GIL
// serialises Python callbacks.
#pragma once

#include <memory>

#include <pybind11/pybind11.h>

namespace boxplus::python {

// Must be called with the GIL held.
void StorePendingError(pybind11::error_already_set&& e);
bool HasPendingError();
// Removes and returns the pending error (nullptr if none).
std::unique_ptr<pybind11::error_already_set> TakePendingError();

}  // namespace boxplus::python
