// The pose-graph file in memory (Graph: its checks and additions) and the
// strict reader; the kind tables are g2o_kinds.cc, the writer g2o_write.cc.
#include "boxplus/io/g2o.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <memory>
#include <sstream>
#include <string_view>
#include <thread>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "boxplus/errors.h"
#include "boxplus/factors/pose/unit_quaternion.h"

namespace boxplus::io {

int Graph::VertexIndex(int id) const {
  auto it = index_of.find(id);
  if (it != index_of.end()) return it->second;
  auto lt = landmark_index_of.find(id);
  BOXPLUS_CHECK_INDEX(lt != landmark_index_of.end(), "no vertex with id ", id);
  return lt->second;
}

int Graph::EndIndex(const Edge& e, int end) const {
  const int id = end == 0 ? e.from : e.to;
  const auto& map = EndIsPose(e.kind, end) ? index_of : landmark_index_of;
  auto it = map.find(id);
  BOXPLUS_CHECK_INDEX(it != map.end(), "no ", EndIsPose(e.kind, end) ? "pose" : "landmark",
                      " vertex with id ", id);
  return it->second;
}

std::vector<int> Graph::FixedIds() const {
  std::vector<int> out;
  for (const auto& f : fixed) out.insert(out.end(), f.begin(), f.end());
  return out;
}

namespace {

int PoseDimension(VertexKind k) {
  return k == VertexKind::kSE2 ? 2 : k == VertexKind::kSE3 ? 3 : 0;
}

bool IsPoseKind(VertexKind k) { return PoseDimension(k) != 0; }

// The id range a vertex of this kind is numbered in.
const std::unordered_map<int, int>& RangeOf(const Graph& g, VertexKind k) {
  return IsPoseKind(k) ? g.index_of : g.landmark_index_of;
}

}  // namespace

std::string Escaped(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (unsigned char c : text) {
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    }
  }
  return out;
}

// A field as a message quotes it: escaped, and at most 40 bytes of it (a
// 33-million-byte token once made a message of that size).
std::string Excerpt(const std::string& field) {
  constexpr size_t kMax = 40;
  if (field.size() <= kMax) return Escaped(field);
  return Escaped(field.substr(0, kMax)) + "... (" + std::to_string(field.size()) + " bytes)";
}

void Graph::CheckVertex(const Vertex& v) const {
  BOXPLUS_CHECK(RangeOf(*this, v.kind).count(v.id) == 0, "vertex id ", v.id, " exists already (",
                IsPoseKind(v.kind) ? "a pose" : "a landmark", ")");
  BOXPLUS_CHECK(v.estimate.size() == AmbientSize(v.kind), "vertex ", v.id, ": estimate needs ",
                AmbientSize(v.kind), " numbers, got ", v.estimate.size());
  BOXPLUS_CHECK(v.estimate.allFinite(), "vertex ", v.id, ": estimate is not finite");
  if (v.kind == VertexKind::kSE3) {
    const double n = v.estimate.tail<4>().norm();
    BOXPLUS_CHECK(std::abs(n - 1.0) < 1e-9, "vertex ", v.id, ": quaternion is not unit (norm ", n,
                  "); normalise it first");
  }
  const int d = PoseDimension(v.kind);
  BOXPLUS_CHECK(!d || !dimension || d == dimension, "vertex ", v.id, ": a ", d, "D pose in a ",
                dimension, "D graph");
}

void Graph::CheckEdge(const Edge& e) const {
  const int ia = EndIndex(e, 0), ib = EndIndex(e, 1);
  BOXPLUS_CHECK(IsUnary(e.kind) ? e.from == e.to : ia != ib, "edge ", e.from, " → ", e.to,
                IsUnary(e.kind) ? ": a prior names one vertex (to == from)"
                                : ": an edge from a vertex to itself");
  const VertexKind a = vertices[ia].kind;
  const VertexKind b = vertices[ib].kind;
  BOXPLUS_CHECK(ConnectsKinds(e.kind, a, b), "edge ", e.from, " → ", e.to,
                ": connects vertices of the wrong types");
  const int n = ErrorSize(e.kind);
  BOXPLUS_CHECK(e.measurement.size() == MeasurementSize(e.kind) && e.information.rows() == n &&
                    e.information.cols() == n,
                "edge ", e.from, " → ", e.to, ": measurement needs ", MeasurementSize(e.kind),
                " numbers and information ", n, "×", n, ", got ", e.measurement.size(), " and ",
                e.information.rows(), "×", e.information.cols());
  BOXPLUS_CHECK(e.measurement.allFinite(), "edge ", e.from, " → ", e.to,
                ": measurement is not finite");
  if (MeasurementSize(e.kind) == 7) {
    const double q = e.measurement.tail<4>().norm();
    BOXPLUS_CHECK(std::abs(q - 1.0) < 1e-9, "edge ", e.from, " → ", e.to,
                  ": quaternion is not unit (norm ", q, "); normalise it first");
  }
  if (e.kind == EdgeKind::kSE2BearingRange) {
    BOXPLUS_CHECK(e.measurement[1] >= 0.0, "edge ", e.from, " → ", e.to, ": negative range ",
                  e.measurement[1]);
  }
  BOXPLUS_CHECK(IsPositiveDefinite(e.information), "edge ", e.from, " → ", e.to,
                ": information matrix is not positive definite");
}

int Graph::AddVertex(Vertex v) {
  CheckVertex(v);
  const int idx = static_cast<int>(vertices.size());
  const VertexKind kind = v.kind;
  const int id = v.id;
  vertices.push_back(std::move(v));
  (IsPoseKind(kind) ? index_of : landmark_index_of)[id] = idx;
  order.push_back({RecordType::kVertex, idx});
  if (kind == VertexKind::kSE2 && dimension == 0) dimension = 2;
  if (kind == VertexKind::kSE3 && dimension == 0) dimension = 3;
  return idx;
}

int Graph::AddEdge(const Edge& e) {
  CheckEdge(e);
  const int idx = static_cast<int>(edges.size());
  edges.push_back(e);
  order.push_back({RecordType::kEdge, idx});
  return idx;
}

std::string ReadReport::Warnings(const std::string& path) const {
  std::ostringstream out;
  if (unknown_skipped > 0) {
    out << Escaped(path) << ": warning: skipped " << unknown_skipped
        << " line(s) with unknown tags (";
    bool first = true;
    for (const auto& [tag, n] : unknown_tags) {
      out << (first ? "" : ", ") << tag << " ×" << n;
      first = false;
    }
    out << ")\n";
  }
  if (identity_information > 0) {
    out << Escaped(path) << ": warning: " << identity_information
        << " EDGE3 line(s) without an information matrix: the identity is used, as GTSAM's "
           "loader does (first at line "
        << first_identity_line << ")\n";
  }
  if (repaired_information > 0) {
    out << Escaped(path) << ": warning: replaced " << repaired_information
        << " information matrix(es) that were not positive definite by the "
           "nearest positive-definite matrix (first at line "
        << repaired_lines.front() << ")\n";
  }
  return out.str();
}

namespace {

template <class Matrix>
bool CholeskySucceeds(const Eigen::MatrixXd& info) {
  const Eigen::LLT<Matrix> llt{Matrix(info)};
  return llt.info() == Eigen::Success && llt.matrixLLT().diagonal().minCoeff() > 0.0;
}

}  // namespace

bool IsPositiveDefinite(const Eigen::MatrixXd& info) {
  if (!info.allFinite() || info.rows() != info.cols()) return false;
  // The sizes of g2o's edges on the stack, unrolled: one check per edge of a big file.
  switch (info.rows()) {
    case 2:
      return CholeskySucceeds<Eigen::Matrix2d>(info);
    case 3:
      return CholeskySucceeds<Eigen::Matrix3d>(info);
    case 6:
      return CholeskySucceeds<Eigen::Matrix<double, 6, 6>>(info);
    default:
      return info.rows() > 0 && CholeskySucceeds<Eigen::MatrixXd>(info);
  }
}

bool CanRepair(const Eigen::MatrixXd& info) {
  return info.allFinite() && info.rows() == info.cols() && info.cwiseAbs().maxCoeff() > 0.0;
}

Eigen::MatrixXd NearestPositiveDefinite(const Eigen::MatrixXd& info) {
  // Decomposed at unit scale, so entries near the largest double (1e300)
  // cannot overflow the eigenvalues; the repair is scale-invariant.
  const double scale = info.cwiseAbs().maxCoeff();
  BOXPLUS_CHECK(scale > 0 && std::isfinite(scale),
                "information matrix is zero or not finite: cannot be repaired");
  const Eigen::MatrixXd sym = 0.5 * (info / scale + (info / scale).transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(sym);
  const double max_abs = es.eigenvalues().cwiseAbs().maxCoeff();
  BOXPLUS_CHECK(max_abs > 0 && std::isfinite(max_abs),
                "information matrix is zero or not finite: cannot be repaired");
  const Eigen::VectorXd lambda = es.eigenvalues().cwiseMax(1e-9 * max_abs);
  return scale * (es.eigenvectors() * lambda.asDiagonal() * es.eigenvectors().transpose());
}

namespace {

// A line split into whitespace-separated fields, without copies.
struct Fields {
  std::vector<std::pair<const char*, size_t>> f;
  std::string str(size_t i) const { return std::string(f[i].first, f[i].second); }
};

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

Eigen::Vector4d QuatFromEuler(double roll, double pitch, double yaw) {
  const Eigen::Quaterniond q = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  return q.coeffs();
}

// TORO EDGE2 stores I11 I12 I22 I33 I13 I23.
Eigen::MatrixXd ToroInfo2(const LineParser& p, size_t first) {
  Eigen::MatrixXd m(3, 3);
  const double i11 = p.Number(first), i12 = p.Number(first + 1), i22 = p.Number(first + 2),
               i33 = p.Number(first + 3), i13 = p.Number(first + 4), i23 = p.Number(first + 5);
  m << i11, i12, i13, i12, i22, i23, i13, i23, i33;
  return m;
}

}  // namespace

namespace {

// The value of an offset parameter for an edge: identity (empty) when the id
// has no PARAMS line and `lenient` (EDGE_SE3_TRACKXYZ, as before), else the
// line must exist and be of the edge's dimension.
Eigen::VectorXd OffsetFor(const Graph& g, const LineParser& lp, const std::string& tag, int id,
                          int dimension, bool lenient) {
  auto it = g.offsets.find(id);
  const char* params = dimension == 2 ? "PARAMS_SE2OFFSET" : "PARAMS_SE3OFFSET";
  if (it == g.offsets.end()) {
    if (lenient) return Eigen::VectorXd();
    lp.Fail(tag + ": offset parameter " + std::to_string(id) + " has no " + params +
            " line before it");
  }
  if (it->second.size() != (dimension == 2 ? 3 : 7)) {
    lp.Fail(tag + ": offset parameter " + std::to_string(id) + " is not a " + params);
  }
  return it->second;
}

bool IsIdentityOffset(const Eigen::VectorXd& o) {
  if (o.size() == 0) return true;
  if (o.size() == 3) return o.cwiseAbs().maxCoeff() == 0.0;
  return o.head<3>().cwiseAbs().maxCoeff() == 0.0 && std::abs(o[6]) == 1.0;
}

// Whether the initialisation of a file without VERTEX lines can place the
// ends of this edge (pose-pose edges and the landmark observations it knows).
bool InitialisableWithoutVertices(EdgeKind k) {
  return k == EdgeKind::kSE2 || k == EdgeKind::kSE3 || k == EdgeKind::kSE2Point2 ||
         k == EdgeKind::kSE3Point3 || k == EdgeKind::kSE2BearingRange;
}

// Tight information of an EQUIV constraint (σ = 1e-3 per coordinate).
constexpr double kEquivInformation = 1e6;

}  // namespace

namespace {

Graph ParseText(std::string_view text, const std::string& name, const ReadOptions& options,
                ReadReport* report) {
  ReadReport local;
  ReadReport& rep = report ? *report : local;
  rep = ReadReport();
  Graph g;
  g.name = name;
  bool any_vertex_line = false;
  std::vector<int> fix_lines;
  struct Equiv {
    int a, b, line;
    size_t record;
  };
  std::vector<Equiv> equivs;
  const char* const begin = text.data();
  const char* const end = begin + text.size();
  {  // the edges' and records' storage at once (no regrowth: its copies raise the peak memory)
    size_t lines = 0, edges = 0, vertices = 0;
    for (const char* q = begin; q < end; ++lines) {
      if (*q == 'E') ++edges;  // EDGE…, EQUIV
      if (*q == 'V') ++vertices;
      const char* eol = static_cast<const char*>(std::memchr(q, '\n', end - q));
      q = eol ? eol + 1 : end;
    }
    g.edges.reserve(edges);
    g.vertices.reserve(vertices);
    g.index_of.reserve(vertices);  // rehashing a million ids cost a tenth of the reading
    g.order.reserve(lines);
  }
  int line = 0;
  const int progress_every = std::max(1, options.progress_lines);
  const std::vector<const char*> cuts = BlockCuts(begin, end);
  const size_t num_blocks = cuts.size() - 1;
  // One block converted ahead on another thread, when there is one (a
  // deferred launch converts it on this thread at get(); with both flags a
  // thread that cannot be started falls back to that).
  const auto policy = num_blocks > 1 && std::thread::hardware_concurrency() > 1
                          ? std::launch::async | std::launch::deferred
                          : std::launch::deferred;
  const auto convert = [&](size_t k) {
    return std::async(policy, ConvertBlock, cuts[k], cuts[k + 1]);
  };
  std::future<ConvertedBlock> ahead;
  if (num_blocks > 0) ahead = convert(0);
  for (size_t block_index = 0; block_index < num_blocks; ++block_index) {
    const ConvertedBlock block = ahead.get();
    if (block_index + 1 < num_blocks) ahead = convert(block_index + 1);
    for (const LineView& view : block.lines) {
      ++line;
      if (options.on_progress && line % progress_every == 0) {
        options.on_progress(
            {line, static_cast<size_t>(std::min(view.end + 1, end) - begin), text.size()});
      }
      if (view.fields == 0) continue;
      LineParser lp(name, line, view, block.numbers.data() + view.numbers);
      const std::string tag = lp.Tag();

      auto add_vertex = [&](VertexKind kind, Eigen::VectorXd est, bool toro) {
        const int id = lp.Id(1);
        const auto& range = RangeOf(g, kind);
        if (range.count(id)) {
          lp.Fail("vertex id " + std::to_string(id) + " appears twice (first at line " +
                  std::to_string(g.vertices[range.at(id)].line) + "), both " +
                  (IsPoseKind(kind) ? "poses" : "landmarks"));
        }
        Vertex v;
        v.id = id;
        v.kind = kind;
        v.estimate = std::move(est);
        v.toro = toro;
        v.line = line;
        const int pose_dim = PoseDimension(kind);
        if (pose_dim && g.dimension && g.dimension != pose_dim) {
          lp.Fail("mixes 2D and 3D poses");
        }
        try {
          g.AddVertex(std::move(v));
        } catch (const Error& e) {
          lp.Fail(e.what());
        }
        any_vertex_line = true;
      };
      // Fills the edge's common fields, checks and repairs its information and
      // appends it; returns it for the caller's extra fields.
      auto add_edge = [&](EdgeKind kind, int from, int to, Eigen::VectorXd z, Eigen::MatrixXd info,
                          bool toro, int param = 0) -> Edge& {
        if (!IsUnary(kind) && from == to && EndIsPose(kind, 0) == EndIsPose(kind, 1)) {
          lp.Fail(tag + ": an edge from vertex " + std::to_string(from) + " to itself");
        }
        if (kind == EdgeKind::kSE2BearingRange && !(z[1] >= 0.0)) {
          lp.Fail(tag + ": negative range " + std::to_string(z[1]));
        }
        if (!IsPositiveDefinite(info)) {
          if (!options.repair_information) {
            lp.Fail(tag +
                    ": information matrix is not positive definite (use the repair "
                    "option to replace it by the nearest positive-definite matrix)");
          }
          if (!CanRepair(info)) {
            lp.Fail(tag + ": information matrix is zero or not finite: cannot be repaired");
          }
          try {
            info = NearestPositiveDefinite(info);
          } catch (const Error& e) {
            lp.Fail(tag + ": " + e.what());
          }
          ++rep.repaired_information;
          rep.repaired_lines.push_back(line);
        }
        const bool three_d = MeasurementSize(kind) == 7 || kind == EdgeKind::kSE3Point3 ||
                             kind == EdgeKind::kSE3Point3Offset ||
                             kind == EdgeKind::kSE3PositionPrior ||
                             kind == EdgeKind::kPoint3Prior || kind == EdgeKind::kPoint3Point3;
        const int pose_dim = three_d ? 3 : 2;
        if (g.dimension && g.dimension != pose_dim) lp.Fail("mixes 2D and 3D poses");
        g.dimension = pose_dim;
        Edge e;
        e.kind = kind;
        e.from = from;
        e.to = to;
        e.measurement = std::move(z);
        e.information = std::move(info);
        e.toro = toro;
        e.param = param;
        e.line = line;
        g.edges.push_back(std::move(e));
        g.order.push_back({Graph::RecordType::kEdge, static_cast<int>(g.edges.size()) - 1});
        return g.edges.back();
      };
      auto se2 = [&](size_t first) {
        return Eigen::Vector3d(lp.Number(first), lp.Number(first + 1),
                               WrapAngleExact(lp.Number(first + 2)));
      };
      auto se3 = [&](size_t first) {
        Eigen::VectorXd z(7);
        z << lp.Number(first), lp.Number(first + 1), lp.Number(first + 2), lp.Quaternion(first + 3);
        return z;
      };
      auto vec = [&](size_t first, int n) {
        Eigen::VectorXd v(n);
        for (int k = 0; k < n; ++k) v[k] = lp.Number(first + k);
        return v;
      };
      auto keep_param_line = [&]() {
        g.params.push_back(lp.Text());
        g.order.push_back({Graph::RecordType::kParam, static_cast<int>(g.params.size()) - 1});
      };
      auto define_offset = [&](int id, Eigen::VectorXd value) {
        if (g.offsets.count(id)) {
          lp.Fail(tag + ": parameter id " + std::to_string(id) + " is defined twice");
        }
        g.offsets[id] = std::move(value);
        keep_param_line();
      };

      if (tag == "VERTEX_SE2" || tag == "VERTEX2" || tag == "VERTEX") {
        lp.ExpectCount(4, "id x y theta");
        add_vertex(VertexKind::kSE2, se2(2), tag != "VERTEX_SE2");
      } else if (tag == "VERTEX_SE3:QUAT") {
        lp.ExpectCount(8, "id x y z qx qy qz qw");
        add_vertex(VertexKind::kSE3, se3(2), false);
      } else if (tag == "VERTEX3") {
        lp.ExpectCount(7, "id x y z roll pitch yaw");
        Eigen::VectorXd v(7);
        v << lp.Number(2), lp.Number(3), lp.Number(4),
            QuatFromEuler(lp.Number(5), lp.Number(6), lp.Number(7));
        add_vertex(VertexKind::kSE3, std::move(v), true);
      } else if (tag == "VERTEX_XY") {
        lp.ExpectCount(3, "id x y");
        add_vertex(VertexKind::kPoint2, vec(2, 2), false);
      } else if (tag == "VERTEX_TRACKXYZ") {
        lp.ExpectCount(4, "id x y z");
        add_vertex(VertexKind::kPoint3, vec(2, 3), false);
      } else if (tag == "EDGE_SE2") {
        lp.ExpectCount(11, "i j dx dy dtheta I11 I12 I13 I22 I23 I33");
        // The measured angle wrapped exactly, as a vertex's: for |θ| ≫ 2π the
        // solver's wrap(θj − θi − θz) would lose every digit of it.
        add_edge(EdgeKind::kSE2, lp.Id(1), lp.Id(2), se2(3), lp.UpperTriangle(6, 3), false);
      } else if (tag == "EDGE2" || tag == "EDGE") {
        lp.ExpectCount(11, "i j dx dy dtheta I11 I12 I22 I33 I13 I23");
        add_edge(EdgeKind::kSE2, lp.Id(1), lp.Id(2), se2(3), ToroInfo2(lp, 6), true);
      } else if (tag == "EDGE_SE3:QUAT") {
        lp.ExpectCount(30, "i j dx dy dz qx qy qz qw I(21, upper triangle)");
        add_edge(EdgeKind::kSE3, lp.Id(1), lp.Id(2), se3(3), lp.UpperTriangle(10, 6), false);
      } else if (tag == "EDGE3") {
        // GTSAM's loader reads EDGE3 without I(21) as the identity information.
        const bool without_info = lp.size() == 9;
        if (!without_info) {
          lp.ExpectCount(29, "i j dx dy dz roll pitch yaw [I(21, upper triangle)]");
        }
        Eigen::VectorXd z(7);
        z << lp.Number(3), lp.Number(4), lp.Number(5),
            QuatFromEuler(lp.Number(6), lp.Number(7), lp.Number(8));
        const Eigen::MatrixXd info =
            without_info ? Eigen::MatrixXd::Identity(6, 6) : lp.UpperTriangle(9, 6);
        Edge& e = add_edge(EdgeKind::kSE3, lp.Id(1), lp.Id(2), z, info, true);
        if (without_info) {
          e.identity_information = true;
          if (rep.identity_information++ == 0) rep.first_identity_line = line;
        }
      } else if (tag == "EDGE_SE2_XY" || tag == "LANDMARK2") {
        // LANDMARK2 (GTSAM's example data: cityTrees, victoriaPark): the same
        // line as EDGE_SE2_XY, pose id, landmark id, the point in the pose's
        // frame and its information; written back as LANDMARK2.
        lp.ExpectCount(7, "i j x y I11 I12 I22");
        add_edge(EdgeKind::kSE2Point2, lp.Id(1), lp.Id(2), vec(3, 2), lp.UpperTriangle(5, 2),
                 tag == "LANDMARK2");
      } else if (tag == "EDGE_SE3_TRACKXYZ") {
        lp.ExpectCount(12, "i j offset_id x y z I(6, upper triangle)");
        const int param = lp.Id(3);
        Eigen::VectorXd offset = OffsetFor(g, lp, tag, param, 3, true);
        const bool identity = IsIdentityOffset(offset);
        Edge& e = add_edge(identity ? EdgeKind::kSE3Point3 : EdgeKind::kSE3Point3Offset, lp.Id(1),
                           lp.Id(2), vec(4, 3), lp.UpperTriangle(7, 3), false, param);
        if (!identity) e.offset = std::move(offset);
      } else if (tag == "EDGE_SE2_BEARING_RANGE") {
        lp.ExpectCount(7, "i j bearing range Ibb Ibr Irr");
        add_edge(EdgeKind::kSE2BearingRange, lp.Id(1), lp.Id(2), vec(3, 2), lp.UpperTriangle(5, 2),
                 false);
      } else if (tag == "EDGE_SE2_OFFSET" || tag == "EDGE_SE3_OFFSET") {
        const bool three = tag == "EDGE_SE3_OFFSET";
        if (three) {
          lp.ExpectCount(32, "i j p_from p_to dx dy dz qx qy qz qw I(21, upper triangle)");
        } else {
          lp.ExpectCount(13, "i j p_from p_to dx dy dtheta I(6, upper triangle)");
        }
        const int pa = lp.Id(3), pb = lp.Id(4);
        Eigen::VectorXd oa = OffsetFor(g, lp, tag, pa, three ? 3 : 2, false);
        Eigen::VectorXd ob = OffsetFor(g, lp, tag, pb, three ? 3 : 2, false);
        Edge& e = add_edge(three ? EdgeKind::kSE3Offset : EdgeKind::kSE2Offset, lp.Id(1), lp.Id(2),
                           three ? se3(5) : Eigen::VectorXd(se2(5)),
                           lp.UpperTriangle(three ? 12 : 8, three ? 6 : 3), false, pa);
        e.param_to = pb;
        e.offset = std::move(oa);
        e.offset_to = std::move(ob);
      } else if (tag == "EDGE_PRIOR_SE2") {
        lp.ExpectCount(10, "i x y theta I(6, upper triangle)");
        const int i = lp.Id(1);
        add_edge(EdgeKind::kSE2Prior, i, i, se2(2), lp.UpperTriangle(5, 3), false);
      } else if (tag == "EDGE_SE3_PRIOR") {
        lp.ExpectCount(30, "i p x y z qx qy qz qw I(21, upper triangle)");
        const int i = lp.Id(1), param = lp.Id(2);
        Eigen::VectorXd offset = OffsetFor(g, lp, tag, param, 3, false);
        Edge& e =
            add_edge(EdgeKind::kSE3Prior, i, i, se3(3), lp.UpperTriangle(10, 6), false, param);
        e.offset = std::move(offset);
      } else if (tag == "EDGE_PRIOR_SE2_XY" || tag == "EDGE_PRIOR_XY") {
        lp.ExpectCount(6, "i x y I11 I12 I22");
        const int i = lp.Id(1);
        add_edge(tag == "EDGE_PRIOR_XY" ? EdgeKind::kPoint2Prior : EdgeKind::kSE2PositionPrior, i,
                 i, vec(2, 2), lp.UpperTriangle(4, 2), false);
      } else if (tag == "EDGE_SE3_XYZ_PRIOR") {
        lp.ExpectCount(11, "i p x y z I(6, upper triangle)");
        const int i = lp.Id(1), param = lp.Id(2);
        // g2o's computeError ignores the offset; it must still exist.
        OffsetFor(g, lp, tag, param, 3, false);
        add_edge(EdgeKind::kSE3PositionPrior, i, i, vec(3, 3), lp.UpperTriangle(6, 3), false,
                 param);
      } else if (tag == "EDGE_POINTXYZ_PRIOR") {
        lp.ExpectCount(10, "i x y z I(6, upper triangle)");
        const int i = lp.Id(1);
        add_edge(EdgeKind::kPoint3Prior, i, i, vec(2, 3), lp.UpperTriangle(5, 3), false);
      } else if (tag == "EDGE_POINTXY") {
        lp.ExpectCount(7, "i j dx dy I11 I12 I22");
        add_edge(EdgeKind::kPoint2Point2, lp.Id(1), lp.Id(2), vec(3, 2), lp.UpperTriangle(5, 2),
                 false);
      } else if (tag == "EDGE_POINTXYZ") {
        lp.ExpectCount(11, "i j dx dy dz I(6, upper triangle)");
        add_edge(EdgeKind::kPoint3Point3, lp.Id(1), lp.Id(2), vec(3, 3), lp.UpperTriangle(6, 3),
                 false);
      } else if (tag == "EDGE_SE2_POINTXY_OFFSET") {
        lp.ExpectCount(8, "i j p x y I11 I12 I22");
        const int param = lp.Id(3);
        Eigen::VectorXd offset = OffsetFor(g, lp, tag, param, 2, false);
        Edge& e = add_edge(EdgeKind::kSE2Point2Offset, lp.Id(1), lp.Id(2), vec(4, 2),
                           lp.UpperTriangle(6, 2), false, param);
        e.offset = std::move(offset);
      } else if (tag == "EDGE_BEARING_SE2_XY") {
        lp.ExpectCount(4, "i j bearing I");
        Eigen::VectorXd z(1);
        z << WrapAngleExact(lp.Number(3));
        add_edge(EdgeKind::kSE2Bearing, lp.Id(1), lp.Id(2), z, lp.UpperTriangle(4, 1), false);
      } else if (tag == "FIX") {
        if (lp.size() < 2) lp.Fail("FIX: no vertex id");
        std::vector<int> ids;
        for (size_t i = 1; i < lp.size(); ++i) ids.push_back(lp.Id(i));
        g.fixed.push_back(ids);
        fix_lines.push_back(line);
        g.order.push_back({Graph::RecordType::kFix, static_cast<int>(g.fixed.size()) - 1});
      } else if (tag == "EQUIV") {
        lp.ExpectCount(2, "i j");
        const int a = lp.Id(1), b = lp.Id(2);
        if (a == b) lp.Fail("EQUIV: a vertex with itself");
        // Resolved once every edge is read (the edge between them may follow).
        equivs.push_back({a, b, line, g.order.size()});
        g.order.push_back({Graph::RecordType::kEdge, -1});
        ++rep.equiv;
      } else if (tag == "PARAMS_SE3OFFSET") {
        lp.ExpectCount(8, "id x y z qx qy qz qw");
        define_offset(lp.Id(1), se3(2));
      } else if (tag == "PARAMS_SE2OFFSET") {
        lp.ExpectCount(4, "id x y theta");
        define_offset(lp.Id(1), se2(2));
      } else if (options.skip_unknown_tags) {
        ++rep.unknown_skipped;
        ++rep.unknown_tags[Escaped(tag)];
      } else {
        lp.Fail("unknown tag '" + Escaped(tag) + "' (skip unknown tags explicitly to ignore it)");
      }
    }
  }
  rep.lines = line;

  // EQUIV i j → a tight edge i → j with the measurement of the (first) edge
  // between them, oriented i → j, else the identity.
  for (const Equiv& q : equivs) {
    if (g.dimension == 0) throw ParseError(name, q.line, "EQUIV in a file without poses");
    const bool three = g.dimension == 3;
    Edge e;
    e.kind = three ? EdgeKind::kSE3 : EdgeKind::kSE2;
    e.from = q.a;
    e.to = q.b;
    e.measurement = Eigen::VectorXd::Zero(three ? 7 : 3);
    if (three) e.measurement[6] = 1.0;
    for (const Edge& other : g.edges) {
      if (other.equiv || other.kind != e.kind) continue;
      if (other.from == q.a && other.to == q.b) {
        e.measurement = other.measurement;
        break;
      }
      if (other.from == q.b && other.to == q.a) {
        if (three) {
          Eigen::Quaterniond r(other.measurement[6], other.measurement[3], other.measurement[4],
                               other.measurement[5]);
          const Eigen::Vector3d t = -(r.conjugate() * other.measurement.head<3>());
          e.measurement << t, r.conjugate().coeffs();
        } else {
          const double c = std::cos(other.measurement[2]), s = std::sin(other.measurement[2]);
          const double x = other.measurement[0], y = other.measurement[1];
          e.measurement << -(c * x + s * y), s * x - c * y, -other.measurement[2];
        }
        break;
      }
    }
    e.information = kEquivInformation * Eigen::MatrixXd::Identity(three ? 6 : 3, three ? 6 : 3);
    e.equiv = true;
    e.toro = true;
    e.line = q.line;
    g.order[q.record].index = static_cast<int>(g.edges.size());
    g.edges.push_back(std::move(e));
  }

  // Edges must name existing vertices, unless the file has no vertex at all.
  if (!any_vertex_line) {
    g.estimates_from_file = false;
    for (const Edge& e : g.edges) {
      if (!InitialisableWithoutVertices(e.kind)) {
        throw ParseError(name, e.line,
                         "this edge needs VERTEX lines: a file without vertices is initialised "
                         "from its pose-pose edges and landmark observations only");
      }
      for (int k = 0; k < 2; ++k) {
        const int id = k == 0 ? e.from : e.to;
        const bool pose = EndIsPose(e.kind, k);
        auto& range = pose ? g.index_of : g.landmark_index_of;
        if (range.count(id)) continue;
        Vertex v;
        v.id = id;
        v.line = e.line;
        v.has_estimate = false;
        v.toro = e.toro;
        if (pose) {
          v.kind = g.dimension == 3 ? VertexKind::kSE3 : VertexKind::kSE2;
        } else {
          v.kind = g.dimension == 3 ? VertexKind::kPoint3 : VertexKind::kPoint2;
        }
        v.estimate = Eigen::VectorXd::Zero(AmbientSize(v.kind));
        if (v.kind == VertexKind::kSE3) v.estimate[6] = 1.0;
        const int idx = static_cast<int>(g.vertices.size());
        g.vertices.push_back(v);
        range[id] = idx;
      }
    }
    // Created vertices are written before everything else, sorted by id.
    std::vector<Graph::Record> order;
    std::vector<int> idx(g.vertices.size());
    for (size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<int>(i);
    std::sort(idx.begin(), idx.end(), [&](int a, int b) {
      const bool pa = IsPoseKind(g.vertices[a].kind), pb = IsPoseKind(g.vertices[b].kind);
      if (pa != pb) return pa;
      return g.vertices[a].id < g.vertices[b].id;
    });
    for (int i : idx) order.push_back({Graph::RecordType::kVertex, i});
    order.insert(order.end(), g.order.begin(), g.order.end());
    g.order = std::move(order);
  }
  for (const Edge& e : g.edges) {
    VertexKind ends[2];
    for (int k = 0; k < 2; ++k) {
      const int id = k == 0 ? e.from : e.to;
      const bool pose = EndIsPose(e.kind, k);
      const auto& range = pose ? g.index_of : g.landmark_index_of;
      const auto it = range.find(id);
      if (it == range.end()) {
        throw ParseError(name, e.line,
                         "edge to a missing vertex " + std::to_string(id) +
                             (pose ? " (a pose)" : " (a landmark)"));
      }
      ends[k] = g.vertices[it->second].kind;
    }
    if (!ConnectsKinds(e.kind, ends[0], ends[1]))
      throw ParseError(name, e.line, "edge connects vertices of the wrong types");
  }
  for (size_t f = 0; f < g.fixed.size(); ++f) {
    for (int id : g.fixed[f]) {
      if (!g.index_of.count(id) && !g.landmark_index_of.count(id)) {
        throw ParseError(name, fix_lines[f], "FIX of a missing vertex " + std::to_string(id));
      }
    }
  }
  return g;
}

}  // namespace

Graph ParseG2o(const std::string& text, const std::string& name, const ReadOptions& options,
               ReadReport* report) {
  return ParseText(text, name, options, report);
}

// Checks text as it arrives, before it is kept: a NUL byte (binary data, not a
// g2o/TORO text) or a line longer than kMaxLineBytes (no record comes near:
// EDGE_SE3:QUAT with its 21 information entries is under 1 kB) ends the read at
// once, naming the line, so that /dev/zero, /dev/urandom or a large binary file
// cost a few kilobytes and no time instead of all the memory there is.
class TextCheck {
 public:
  explicit TextCheck(const std::string& name) : name_(name) {}
  void operator()(const char* data, size_t n) {
    for (size_t i = 0; i < n; ++i) {
      const char c = data[i];
      if (c == '\n') {
        ++line_;
        length_ = 0;
        continue;
      }
      if (c == '\0') {
        throw ParseError(name_, line_, "binary data (a NUL byte): not a g2o or TORO text file");
      }
      if (++length_ > kMaxLineBytes) {
        throw ParseError(name_, line_,
                         "a line longer than " + std::to_string(kMaxLineBytes) +
                             " bytes: not a g2o or TORO text file");
      }
    }
  }

 private:
  std::string name_;
  int line_ = 1;
  size_t length_ = 0;
};

std::string ReadTextStream(std::istream& in, const std::string& name) {
  TextCheck check(name);
  std::string text;
  char chunk[1 << 16];
  while (in.read(chunk, sizeof(chunk)) || in.gcount() > 0) {
    check(chunk, static_cast<size_t>(in.gcount()));
    text.append(chunk, static_cast<size_t>(in.gcount()));
  }
  BOXPLUS_CHECK(!in.bad(), Escaped(name), ": reading failed");
  return text;
}

Graph ReadG2o(const std::string& path, const ReadOptions& options, ReadReport* report) {
  std::error_code ec;
  BOXPLUS_CHECK(!std::filesystem::is_directory(path, ec), Escaped(path),
                ": is a directory, not a g2o file");
  std::ifstream in(path, std::ios::binary);
  BOXPLUS_CHECK(in.good(), Escaped(path), ": cannot open the file");
  // One read into a buffer of the file's size (an istreambuf_iterator copies
  // byte by byte: a tenth of the reading time of a 140 MB file; a read through
  // a chunk copies the file twice). The buffer is not zero-filled first (a
  // std::string's resize is: a pass over a 300 MB file for nothing). Its first
  // megabyte is checked (TextCheck) before the rest is read: binary input fails
  // there. A file whose size is unknown (a pipe, a device) or that grows while
  // read is read in checked chunks.
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && std::filesystem::is_regular_file(path, ec) && size > 0) {
    std::unique_ptr<char[]> buffer(new char[size]);
    const size_t head = std::min<size_t>(size, 2 * kMaxLineBytes);
    in.read(buffer.get(), static_cast<std::streamsize>(head));
    size_t got = static_cast<size_t>(in.gcount());
    TextCheck{path}(buffer.get(), got);
    if (got == head && head < size) {
      in.read(buffer.get() + head, static_cast<std::streamsize>(size - head));
      got += static_cast<size_t>(in.gcount());
    }
    BOXPLUS_CHECK(!in.bad(), Escaped(path), ": reading failed");
    if (!in.good() || in.peek() == std::char_traits<char>::eof()) {
      return ParseText(std::string_view(buffer.get(), got), path, options, report);
    }
    std::string text(buffer.get(), got);  // the file grew while read: the rest in chunks
    buffer.reset();
    text += ReadTextStream(in, path);
    return ParseText(text, path, options, report);
  }
  return ParseText(ReadTextStream(in, path), path, options, report);
}

}  // namespace boxplus::io
