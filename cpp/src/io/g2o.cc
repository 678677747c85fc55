// The pose-graph file in memory (Graph: its checks and additions) and the
// strict reader's driver: the first pass is g2o_lines.cc, the records' parsers
// and the tag table g2o_tags.cc, the kind tables g2o_kinds.cc, the writer
// g2o_write.cc.
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
#include "g2o_lines.h"
#include "g2o_tags.h"

namespace boxplus::io {

using detail::IsPoseKind;
using detail::PoseDimension;
using detail::RangeOf;

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

using detail::GraphBuilder;
using detail::LineParser;

// Whether the initialisation of a file without VERTEX lines can place the
// ends of this edge (pose-pose edges and the landmark observations it knows).
bool InitialisableWithoutVertices(EdgeKind k) {
  return k == EdgeKind::kSE2 || k == EdgeKind::kSE3 || k == EdgeKind::kSE2Point2 ||
         k == EdgeKind::kSE3Point3 || k == EdgeKind::kSE2BearingRange;
}

// Tight information of an EQUIV constraint (σ = 1e-3 per coordinate).
constexpr double kEquivInformation = 1e6;

// EQUIV i j → a tight edge i → j with the measurement of the (first) edge
// between them, oriented i → j, else the identity.
void ResolveEquivs(GraphBuilder& b, const std::string& name) {
  Graph& g = b.graph;
  for (const GraphBuilder::Equiv& q : b.equivs) {
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
}

// A file without VERTEX lines: the ends of its edges become vertices without
// an estimate (the initialisation places them), written first, sorted by id.
// Otherwise edges must name existing vertices (CheckReferences).
void CreateMissingVertices(GraphBuilder& b, const std::string& name) {
  Graph& g = b.graph;
  if (!b.any_vertex_line) {
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
}

// Every edge names vertices of its kinds, every FIX an existing vertex.
void CheckReferences(GraphBuilder& b, const std::string& name) {
  Graph& g = b.graph;
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
        throw ParseError(name, b.fix_lines[f], "FIX of a missing vertex " + std::to_string(id));
      }
    }
  }
}

Graph ParseText(std::string_view text, const std::string& name, const ReadOptions& options,
                ReadReport* report) {
  ReadReport local;
  ReadReport& rep = report ? *report : local;
  rep = ReadReport();
  GraphBuilder b(name, options, &rep);
  Graph& g = b.graph;
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
  int& line = b.line;
  const int progress_every = std::max(1, options.progress_lines);
  const std::vector<const char*> cuts = detail::BlockCuts(begin, end);
  const size_t num_blocks = cuts.size() - 1;
  // One block converted ahead on another thread, when there is one (a
  // deferred launch converts it on this thread at get(); with both flags a
  // thread that cannot be started falls back to that).
  const auto policy = num_blocks > 1 && std::thread::hardware_concurrency() > 1
                          ? std::launch::async | std::launch::deferred
                          : std::launch::deferred;
  const auto convert = [&](size_t k) {
    return std::async(policy, detail::ConvertBlock, cuts[k], cuts[k + 1]);
  };
  std::future<detail::ConvertedBlock> ahead;
  if (num_blocks > 0) ahead = convert(0);
  for (size_t block_index = 0; block_index < num_blocks; ++block_index) {
    const detail::ConvertedBlock block = ahead.get();
    if (block_index + 1 < num_blocks) ahead = convert(block_index + 1);
    for (const detail::LineView& view : block.lines) {
      ++line;
      if (options.on_progress && line % progress_every == 0) {
        options.on_progress(
            {line, static_cast<size_t>(std::min(view.end + 1, end) - begin), text.size()});
      }
      if (view.fields == 0) continue;
      const LineParser lp(name, line, view, block.numbers.data() + view.numbers);
      if (detail::ReadRecord(b, lp)) continue;
      const std::string tag = Escaped(lp.Tag());
      if (!options.skip_unknown_tags) {
        lp.Fail("unknown tag '" + tag + "' (skip unknown tags explicitly to ignore it)");
      }
      ++rep.unknown_skipped;
      ++rep.unknown_tags[tag];
    }
  }
  rep.lines = line;
  ResolveEquivs(b, name);
  CreateMissingVertices(b, name);
  CheckReferences(b, name);
  return std::move(b.graph);
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
