// Exceptions thrown by boxplus, and a CHECK that throws instead of aborting.
//
// Ceres' own CHECK macros abort the process; boxplus validates every input
// before it reaches Ceres so that no abort is reachable from Python or from a
// command-line tool. Errors carry the context a user needs to find the fault:
// the file and line of a parse error, the name of a measurement or variable.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace boxplus {

// Base class of every error boxplus raises on bad input.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An index or id that does not name an existing variable or measurement.
class IndexError : public Error {
 public:
  using Error::Error;
};

// A malformed input file; the message names the file and the 1-based line.
class ParseError : public Error {
 public:
  ParseError(const std::string& file, int line, const std::string& what)
      : Error(file + ":" + std::to_string(line) + ": " + what), file_(file), line_(line) {}
  const std::string& file() const { return file_; }
  int line() const { return line_; }

 private:
  std::string file_;
  int line_;
};

namespace internal {
// Streams all arguments into one string (used by BOXPLUS_CHECK messages).
template <typename... Args>
std::string Concat(const Args&... args) {
  std::ostringstream out;
  (out << ... << args);
  return out.str();
}
}  // namespace internal

}  // namespace boxplus

// Throws boxplus::Error (or the given subclass) with a message built from the
// remaining arguments when `cond` is false.
#define BOXPLUS_CHECK(cond, ...)                                        \
  do {                                                                  \
    if (!(cond)) {                                                      \
      throw ::boxplus::Error(::boxplus::internal::Concat(__VA_ARGS__)); \
    }                                                                   \
  } while (0)

#define BOXPLUS_CHECK_INDEX(cond, ...)                                       \
  do {                                                                       \
    if (!(cond)) {                                                           \
      throw ::boxplus::IndexError(::boxplus::internal::Concat(__VA_ARGS__)); \
    }                                                                        \
  } while (0)
