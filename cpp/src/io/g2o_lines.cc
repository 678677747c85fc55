// The reader's first pass and the quoting of fields in messages (g2o_lines.h).
#include "g2o_lines.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <system_error>

#include "boxplus/io/g2o.h"

namespace boxplus::io::detail {
namespace {

// Field separators (space, tab, CR), by byte: one load per byte instead of
// three comparisons (splitting is a third of the time a big file takes).
struct Separators {
  bool is[256] = {};
  constexpr Separators() : is() {
    is[static_cast<unsigned char>(' ')] = is[static_cast<unsigned char>('\t')] =
        is[static_cast<unsigned char>('\r')] = true;
  }
};
constexpr Separators kSeparators;

// A plain decimal [±]digits[.digits] of at most 15 characters, as most
// numbers of a g2o file are ("0.000000", "-1.234567", "40000.0"): at most 15
// digits, so its value m / 10ᵏ has m < 2⁵³ and 10ᵏ (k ≤ 15) exact doubles, and
// the one IEEE division is correctly rounded: the double strtod returns
// (Clinger's fast path). False for anything else (exponents, longer
// numbers), which the full parser reads.
bool PlainDecimal(const char* s, const char* e, double* out) {
  static constexpr double kPow10[] = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};
  if (e - s > 15) return false;
  const bool negative = s < e && *s == '-';
  if (s < e && (*s == '-' || *s == '+')) ++s;
  int64_t m = 0;
  int digits = 0, fraction = -1;  // digits after the dot, −1 before it
  for (; s < e; ++s) {
    const unsigned d = static_cast<unsigned>(*s - '0');
    if (d <= 9) {
      m = 10 * m + d;
      ++digits;
      if (fraction >= 0) ++fraction;
    } else if (*s == '.' && fraction < 0) {
      fraction = 0;
    } else {
      return false;
    }
  }
  if (digits == 0) return false;
  const double v = static_cast<double>(m) / kPow10[fraction < 0 ? 0 : fraction];
  *out = negative ? -v : v;
  return true;
}

// The field's value if it is a finite decimal number; false otherwise.
// std::from_chars: correctly rounded like strtod, several times faster, decimal
// only (no C99 hex, which no other g2o reader takes either). strtod's leading
// '+' is kept; a number below the smallest double is read by strtod, which
// rounds it to 0 or a subnormal where from_chars reports a range error.
bool ToNumber(const char* s, size_t n, double* out) {
  if (n == 0 || n >= 64) return false;
  if (PlainDecimal(s, s + n, out)) return true;
  const char* b = s;
  if (*b == '+' && n > 1 && b[1] != '-' && b[1] != '+') ++b;
  double v = 0.0;
  const auto [end, ec] = std::from_chars(b, s + n, v, std::chars_format::general);
  if (end != s + n) return false;
  if (ec == std::errc::result_out_of_range) {
    char buf[64];
    std::copy(s, s + n, buf);
    buf[n] = '\0';
    v = std::strtod(buf, nullptr);
  } else if (ec != std::errc()) {
    return false;
  }
  if (!std::isfinite(v)) return false;
  *out = v;
  return true;
}

}  // namespace

void SplitFields(const char* begin, const char* end, Fields* out) {
  out->f.clear();
  const auto sep = [](const char* c) { return kSeparators.is[static_cast<unsigned char>(*c)]; };
  const char* p = begin;
  while (p < end) {
    while (p < end && sep(p)) ++p;
    if (p >= end || *p == '#') break;
    const char* s = p;
    while (p < end && !sep(p)) ++p;
    out->f.emplace_back(s, static_cast<size_t>(p - s));
  }
}

ConvertedBlock ConvertBlock(const char* begin, const char* end) {
  ConvertedBlock block;
  Fields fields;
  for (const char* p = begin; p < end;) {
    const char* eol = static_cast<const char*>(std::memchr(p, '\n', end - p));
    if (!eol) eol = end;
    SplitFields(p, eol, &fields);
    const size_t n = fields.f.size();
    block.lines.push_back({p, eol, n ? fields.f[0].first : p,
                           n ? static_cast<uint32_t>(fields.f[0].second) : 0u,
                           static_cast<uint32_t>(n), block.numbers.size()});
    for (size_t i = 1; i < n; ++i) {
      double v = std::numeric_limits<double>::quiet_NaN();
      ToNumber(fields.f[i].first, fields.f[i].second, &v);
      block.numbers.push_back(v);
    }
    p = eol + 1;
  }
  return block;
}

// Block boundaries: line starts about kBlockBytes apart, the first at the
// text's start and the last at its end.
std::vector<const char*> BlockCuts(const char* begin, const char* end) {
  constexpr size_t kBlockBytes = size_t{1} << 20;
  std::vector<const char*> cuts{begin};
  while (cuts.back() < end) {
    const char* c = cuts.back();
    if (static_cast<size_t>(end - c) <= kBlockBytes) {
      cuts.push_back(end);
      break;
    }
    const char* eol =
        static_cast<const char*>(std::memchr(c + kBlockBytes, '\n', end - c - kBlockBytes));
    cuts.push_back(eol ? eol + 1 : end);
  }
  return cuts;
}

// A field as a message quotes it: escaped, and at most 40 bytes of it (a
// 33-million-byte token once made a message of that size).
std::string Excerpt(const std::string& field) {
  constexpr size_t kMax = 40;
  if (field.size() <= kMax) return Escaped(field);
  return Escaped(field.substr(0, kMax)) + "... (" + std::to_string(field.size()) + " bytes)";
}

}  // namespace boxplus::io::detail
