// The one translation of C++ exceptions into Python ones (errors.cc).
#pragma once

#include <exception>

#include <pybind11/pybind11.h>

namespace boxplus::python {

// Sets the Python error indicator from a C++ exception: boxplus::ParseError →
// ParseError (with .file, .line), boxplus::IndexError → BoxplusIndexError,
// boxplus::Error → BoxplusError (a ValueError), std::invalid_argument /
// domain_error → ValueError, std::out_of_range → IndexError, std::bad_alloc →
// MemoryError, anything else → RuntimeError. Messages are decoded as UTF-8
// with invalid bytes escaped (\xNN), never raising UnicodeDecodeError.
void SetPythonError(const std::exception& e);

// A Python str from bytes that may not be UTF-8 (bad bytes escaped).
pybind11::str SafeStr(const std::string& bytes);

}  // namespace boxplus::python
