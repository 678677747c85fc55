// The strict g2o/TORO reader's view of a file's lines (io/g2o.h): the first
// pass splits every line into fields and converts them to numbers, a block of
// lines at a time (on a second core while the second pass reads the block
// before); LineParser is the second pass's view of one line, for the tag
// parsers (g2o_tags.cc) and ParseText (g2o.cc).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "boxplus/errors.h"
#include "boxplus/factors/pose/unit_quaternion.h"

namespace boxplus::io::detail {

// A line split into whitespace-separated fields, without copies.
struct Fields {
  std::vector<std::pair<const char*, size_t>> f;
  std::string str(size_t i) const { return std::string(f[i].first, f[i].second); }
};

void SplitFields(const char* begin, const char* end, Fields* out);

// The reader's first pass, which needs no line but its own: each line's
// fields counted and every field after the tag converted to a number. It runs
// on a block of lines while the second pass (the file's meaning, in order:
// ids, offsets, checks, the graph) works on the block before, so a big file is
// read on two cores (converting numbers was half of the reading time). A
// field that is not a finite number is NaN here (no finite number is): the
// second pass reports it, in file order, with the message it always had.
struct LineView {
  const char* begin;  // the line, without its '\n'
  const char* end;
  const char* tag;  // the first field (none if fields == 0)
  uint32_t tag_size;
  uint32_t fields;  // before a comment, the tag included
  size_t numbers;   // index of field 1's value in the block's numbers
};

struct ConvertedBlock {
  std::vector<LineView> lines;
  std::vector<double> numbers;
};

ConvertedBlock ConvertBlock(const char* begin, const char* end);

// Block boundaries: line starts about a megabyte apart, the first at the
// text's start and the last at its end.
std::vector<const char*> BlockCuts(const char* begin, const char* end);

// A field as a message quotes it: escaped, and at most 40 bytes of it (a
// 33-million-byte token once made a message of that size).
std::string Excerpt(const std::string& field);

// The second pass's view of one line: its converted numbers, and its fields'
// text when a message quotes them (split again only then).
class LineParser {
 public:
  LineParser(const std::string& file, int line, const LineView& view, const double* numbers)
      : file_(file), line_(line), view_(view), numbers_(numbers) {}

  [[noreturn]] void Fail(const std::string& what) const { throw ParseError(file_, line_, what); }
  // Fields before a comment, the tag included.
  size_t size() const { return view_.fields; }
  std::string Tag() const { return std::string(view_.tag, view_.tag_size); }
  std::string_view TagView() const { return {view_.tag, view_.tag_size}; }
  // The field as it may be quoted in a message (bytes outside printable ASCII
  // escaped as \xNN: a message is text, the file may not be).
  std::string Quoted(size_t i) const { return Excerpt(Split().str(i)); }
  // The fields' text, from the tag to the last field before a comment.
  std::string Text() const {
    const Fields& f = Split();
    return std::string(f.f.front().first, f.f.back().first + f.f.back().second);
  }
  void ExpectCount(size_t numbers, const char* layout) const {
    const size_t have = size() - 1;
    if (have < numbers) {
      Fail(Quoted(0) + ": too few numbers (" + std::to_string(have) + ", expected " +
           std::to_string(numbers) + ": " + layout + ")");
    }
    if (have > numbers) {
      Fail(Quoted(0) + ": too many numbers (" + std::to_string(have) + ", expected " +
           std::to_string(numbers) + ": " + layout + ")");
    }
  }
  double Number(size_t i) const {
    const double v = numbers_[i - 1];
    if (std::isnan(v)) Bad(i);
    return v;
  }
  int Id(size_t i) const {
    const double v = Number(i);
    if (v != std::floor(v) || std::abs(v) > 2e9) {
      Fail("field " + std::to_string(i + 1) + " ('" + Quoted(i) + "') is not an integer id");
    }
    return static_cast<int>(v);
  }
  // Reads the upper triangle of an n×n matrix starting at field `first`.
  Eigen::MatrixXd UpperTriangle(size_t first, int n) const {
    Eigen::MatrixXd m(n, n);
    size_t k = first;
    for (int r = 0; r < n; ++r) {
      for (int c = r; c < n; ++c) {
        m(r, c) = m(c, r) = Number(k++);
      }
    }
    return m;
  }
  Eigen::Vector4d Quaternion(size_t first) const {
    Eigen::Vector4d q(Number(first), Number(first + 1), Number(first + 2), Number(first + 3));
    if (!NormalizeQuaternion(q.data(), q.data())) {
      Fail(Quoted(0) + ": quaternion has zero norm");
    }
    return q;
  }

 private:
  [[noreturn]] void Bad(size_t i) const {
    Fail("field " + std::to_string(i + 1) + " ('" + Quoted(i) + "') is not a finite number");
  }
  const Fields& Split() const {
    if (split_.f.empty()) SplitFields(view_.begin, view_.end, &split_);
    return split_;
  }
  const std::string& file_;
  int line_;
  const LineView& view_;
  const double* numbers_;
  mutable Fields split_;
};

}  // namespace boxplus::io::detail
