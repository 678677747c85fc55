// The Python exception raised inside a callback that Ceres called (a Python
// measurement function, a Python manifold's ⊞, the per-iteration callback).
// Ceres cannot carry it, so it is kept, the solve is stopped, and the binding
// that started Ceres re-raises it with its original traceback once Ceres has
// returned.
//
// The slot belongs to one call into the C++ problem (a solve, a cost or a
// residual evaluation), not to the process: an ErrorScope opened by that call
// is found through a thread-local pointer, because Ceres calls Python back on
// the thread that started it. Two threads solving two problems therefore
// never see each other's exceptions.
#pragma once

#include <memory>

#include <pybind11/pybind11.h>

namespace boxplus::python {

// One pending Python error; the first one is kept (later ones are usually
// its consequences). Store and Take must be used with the GIL held; Has only
// reads a pointer, so the thread that owns the slot may ask it without.
class ErrorSlot {
 public:
  void Store(pybind11::error_already_set&& e);
  bool Has() const { return error_ != nullptr; }
  std::unique_ptr<pybind11::error_already_set> Take() { return std::move(error_); }

 private:
  std::unique_ptr<pybind11::error_already_set> error_;
};

// Opens the slot of the current call on this thread (scopes nest: the
// innermost one receives the errors) and closes it on destruction.
class ErrorScope {
 public:
  ErrorScope();
  ~ErrorScope();
  ErrorScope(const ErrorScope&) = delete;
  ErrorScope& operator=(const ErrorScope&) = delete;
  ErrorSlot& slot() { return slot_; }

 private:
  ErrorSlot slot_;
  ErrorScope* previous_;
};

// The slot of the innermost ErrorScope on this thread, or a thread-local
// fallback when Python code runs outside any scope. Must be used with the GIL held.
ErrorSlot& CurrentErrorSlot();
inline void StorePendingError(pybind11::error_already_set&& e) {
  CurrentErrorSlot().Store(std::move(e));
}
inline bool HasPendingError() { return CurrentErrorSlot().Has(); }

// Stores the C++ exception `e` as a Python error of the same class as the
// module's translators would give it (used where a C++ exception must not
// unwind through Ceres).
void StorePendingCppError(const std::exception& e);

// Runs f inside an ErrorScope; if Python code failed inside it, raises that
// error (with its traceback) instead of the C++ one that followed.
template <class F>
auto RaisingPython(F f) {
  ErrorScope scope;
  try {
    return f();
  } catch (const std::exception&) {
    if (auto e = scope.slot().Take()) throw std::move(*e);
    throw;
  }
}

}  // namespace boxplus::python
