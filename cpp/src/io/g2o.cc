#include "boxplus/io/g2o.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "boxplus/errors.h"
#include "boxplus/factors/pose/unit_quaternion.h"

namespace boxplus::io {

int AmbientSize(VertexKind kind) {
  switch (kind) {
    case VertexKind::kSE2:
      return 3;
    case VertexKind::kSE3:
      return 7;
    case VertexKind::kPoint2:
      return 2;
    case VertexKind::kPoint3:
      return 3;
  }
  return 0;
}

int ErrorSize(EdgeKind kind) {
  switch (kind) {
    case EdgeKind::kSE2:
      return 3;
    case EdgeKind::kSE3:
      return 6;
    case EdgeKind::kSE2Point2:
      return 2;
    case EdgeKind::kSE3Point3:
      return 3;
    case EdgeKind::kSE2BearingRange:
      return 2;
  }
  return 0;
}

int MeasurementSize(EdgeKind kind) { return kind == EdgeKind::kSE3 ? 7 : ErrorSize(kind); }

int Graph::VertexIndex(int id) const {
  auto it = index_of.find(id);
  BOXPLUS_CHECK_INDEX(it != index_of.end(), "no vertex with id ", id);
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

void Graph::CheckVertex(const Vertex& v) const {
  BOXPLUS_CHECK(index_of.count(v.id) == 0, "vertex id ", v.id, " exists already");
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
  BOXPLUS_CHECK_INDEX(index_of.count(e.from) && index_of.count(e.to), "edge ", e.from, " → ", e.to,
                      ": no such vertex");
  BOXPLUS_CHECK(e.from != e.to, "edge ", e.from, " → ", e.to, ": an edge from a vertex to itself");
  const VertexKind a = vertices[index_of.at(e.from)].kind;
  const VertexKind b = vertices[index_of.at(e.to)].kind;
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
  if (e.kind == EdgeKind::kSE3) {
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

bool ConnectsKinds(EdgeKind e, VertexKind a, VertexKind b) {
  switch (e) {
    case EdgeKind::kSE2:
      return a == VertexKind::kSE2 && b == VertexKind::kSE2;
    case EdgeKind::kSE3:
      return a == VertexKind::kSE3 && b == VertexKind::kSE3;
    case EdgeKind::kSE2Point2:
    case EdgeKind::kSE2BearingRange:
      return a == VertexKind::kSE2 && b == VertexKind::kPoint2;
    case EdgeKind::kSE3Point3:
      return a == VertexKind::kSE3 && b == VertexKind::kPoint3;
  }
  return false;
}

int Graph::AddVertex(const Vertex& v) {
  CheckVertex(v);
  const int idx = static_cast<int>(vertices.size());
  vertices.push_back(v);
  index_of[v.id] = idx;
  order.push_back({RecordType::kVertex, idx});
  if (v.kind == VertexKind::kSE2 && dimension == 0) dimension = 2;
  if (v.kind == VertexKind::kSE3 && dimension == 0) dimension = 3;
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
  if (repaired_information > 0) {
    out << Escaped(path) << ": warning: replaced " << repaired_information
        << " information matrix(es) that were not positive definite by the "
           "nearest positive-definite matrix (first at line "
        << repaired_lines.front() << ")\n";
  }
  return out.str();
}

bool IsPositiveDefinite(const Eigen::MatrixXd& info) {
  if (!info.allFinite() || info.rows() != info.cols()) return false;
  Eigen::LLT<Eigen::MatrixXd> llt(info);
  if (llt.info() != Eigen::Success) return false;
  const Eigen::VectorXd d = llt.matrixLLT().diagonal();
  return d.minCoeff() > 0.0;
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
  // The field as it may be quoted in a message (bytes outside printable ASCII
  // escaped as \xNN: a message is text, the file may not be).
  std::string quoted(size_t i) const { return Escaped(str(i)); }
};

void Split(const char* begin, const char* end, Fields* out) {
  out->f.clear();
  const char* p = begin;
  while (p < end) {
    while (p < end && (*p == ' ' || *p == '\t' || *p == '\r')) ++p;
    if (p >= end || *p == '#') break;
    const char* s = p;
    while (p < end && *p != ' ' && *p != '\t' && *p != '\r') ++p;
    out->f.emplace_back(s, static_cast<size_t>(p - s));
  }
}

class LineParser {
 public:
  LineParser(const std::string& file, int line, const Fields& fields)
      : file_(file), line_(line), fields_(fields) {}

  [[noreturn]] void Fail(const std::string& what) const { throw ParseError(file_, line_, what); }
  void ExpectCount(size_t numbers, const char* layout) const {
    const size_t have = fields_.f.size() - 1;
    if (have < numbers) {
      Fail(fields_.quoted(0) + ": too few numbers (" + std::to_string(have) + ", expected " +
           std::to_string(numbers) + ": " + layout + ")");
    }
    if (have > numbers) {
      Fail(fields_.quoted(0) + ": too many numbers (" + std::to_string(have) + ", expected " +
           std::to_string(numbers) + ": " + layout + ")");
    }
  }
  double Number(size_t i) const {
    char buf[64];
    const auto& [s, n] = fields_.f[i];
    if (n == 0 || n >= sizeof(buf)) Bad(i);
    // Decimal only: strtod would also take C99 hex ("0x10"), which no other
    // g2o reader does.
    if (std::find_if(s, s + n, [](char c) { return c == 'x' || c == 'X'; }) != s + n) Bad(i);
    std::copy(s, s + n, buf);
    buf[n] = '\0';
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(buf, &end);
    if (end != buf + n || !std::isfinite(v)) Bad(i);
    return v;
  }
  int Id(size_t i) const {
    const double v = Number(i);
    if (v != std::floor(v) || std::abs(v) > 2e9) {
      Fail("field " + std::to_string(i + 1) + " ('" + fields_.quoted(i) +
           "') is not an integer id");
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
      Fail(fields_.quoted(0) + ": quaternion has zero norm");
    }
    return q;
  }

 private:
  [[noreturn]] void Bad(size_t i) const {
    Fail("field " + std::to_string(i + 1) + " ('" + fields_.quoted(i) +
         "') is not a finite number");
  }
  const std::string& file_;
  int line_;
  const Fields& fields_;
};

Eigen::Vector4d QuatFromEuler(double roll, double pitch, double yaw) {
  const Eigen::Quaterniond q = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  return q.coeffs();
}

// Inverse of QuatFromEuler. With R = Rz(y)·Ry(p)·Rx(r) (c·, s· of the angles):
//   R20 = −sp, R21 = cp·sr, R22 = cp·cr, R10 = sy·cp, R00 = cy·cp, and exactly
//   R01 − R12 = (1 + sp)·sin(r − y),  R11 + R02 = (1 + sp)·cos(r − y),
//   R01 + R12 = (sp − 1)·sin(r + y),  R11 − R02 = (1 − sp)·cos(r + y).
// Near pitch ±π/2 (gimbal lock) cp → 0 and yaw = atan2(R10, R00) is the
// angle of two rounding errors (0.2 rad off at ±π/2 exactly), so yaw comes
// from r ∓ y instead, which the other entries hold to full precision: any
// roll from atan2(R21, R22) (0 when cp = 0) then gives the same rotation.
Eigen::Vector3d EulerFromQuat(const Eigen::VectorXd& xyzw) {
  const Eigen::Matrix3d R =
      Eigen::Quaterniond(xyzw[3], xyzw[0], xyzw[1], xyzw[2]).toRotationMatrix();
  const double cp = std::hypot(R(2, 1), R(2, 2));
  const double pitch = std::atan2(-R(2, 0), cp);
  const double roll = cp > 0.0 ? std::atan2(R(2, 1), R(2, 2)) : 0.0;
  double yaw;
  if (cp > 0.1) {
    yaw = std::atan2(R(1, 0), R(0, 0));
  } else if (pitch > 0) {
    yaw = roll - std::atan2(R(0, 1) - R(1, 2), R(1, 1) + R(0, 2));
  } else {
    yaw = std::atan2(-(R(0, 1) + R(1, 2)), R(1, 1) - R(0, 2)) - roll;
  }
  return {roll, pitch, WrapAngleExact(yaw)};
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

Graph ParseG2o(const std::string& text, const std::string& name, const ReadOptions& options,
               ReadReport* report) {
  ReadReport local;
  ReadReport& rep = report ? *report : local;
  rep = ReadReport();
  Graph g;
  g.name = name;
  bool any_vertex_line = false;
  std::vector<int> fix_lines;
  Fields fields;
  const char* p = text.data();
  const char* end = p + text.size();
  int line = 0;
  while (p < end) {
    const char* eol = static_cast<const char*>(std::memchr(p, '\n', end - p));
    if (!eol) eol = end;
    ++line;
    Split(p, eol, &fields);
    p = eol + 1;
    if (fields.f.empty()) continue;
    LineParser lp(name, line, fields);
    const std::string tag = fields.str(0);

    auto add_vertex = [&](VertexKind kind, const Eigen::VectorXd& est, bool toro) {
      const int id = lp.Id(1);
      if (g.index_of.count(id)) {
        lp.Fail("vertex id " + std::to_string(id) + " appears twice (first at line " +
                std::to_string(g.vertices[g.index_of[id]].line) + ")");
      }
      Vertex v;
      v.id = id;
      v.kind = kind;
      v.estimate = est;
      v.toro = toro;
      v.line = line;
      const int pose_dim = kind == VertexKind::kSE2 ? 2 : kind == VertexKind::kSE3 ? 3 : 0;
      if (pose_dim && g.dimension && g.dimension != pose_dim) {
        lp.Fail("mixes 2D and 3D poses");
      }
      try {
        g.AddVertex(v);
      } catch (const Error& e) {
        lp.Fail(e.what());
      }
      any_vertex_line = true;
    };
    auto add_edge = [&](EdgeKind kind, int from, int to, Eigen::VectorXd z, Eigen::MatrixXd info,
                        bool toro, int param = 0) {
      if (from == to) lp.Fail(tag + ": an edge from vertex " + std::to_string(from) + " to itself");
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
      const int pose_dim = (kind == EdgeKind::kSE3 || kind == EdgeKind::kSE3Point3) ? 3 : 2;
      if (g.dimension && g.dimension != pose_dim) lp.Fail("mixes 2D and 3D poses");
      g.dimension = pose_dim;
    };

    if (tag == "VERTEX_SE2" || tag == "VERTEX2") {
      lp.ExpectCount(4, "id x y theta");
      add_vertex(VertexKind::kSE2,
                 Eigen::Vector3d(lp.Number(2), lp.Number(3), WrapAngleExact(lp.Number(4))),
                 tag == "VERTEX2");
    } else if (tag == "VERTEX_SE3:QUAT") {
      lp.ExpectCount(8, "id x y z qx qy qz qw");
      Eigen::VectorXd v(7);
      v << lp.Number(2), lp.Number(3), lp.Number(4), lp.Quaternion(5);
      add_vertex(VertexKind::kSE3, v, false);
    } else if (tag == "VERTEX3") {
      lp.ExpectCount(7, "id x y z roll pitch yaw");
      Eigen::VectorXd v(7);
      v << lp.Number(2), lp.Number(3), lp.Number(4),
          QuatFromEuler(lp.Number(5), lp.Number(6), lp.Number(7));
      add_vertex(VertexKind::kSE3, v, true);
    } else if (tag == "VERTEX_XY") {
      lp.ExpectCount(3, "id x y");
      add_vertex(VertexKind::kPoint2, Eigen::Vector2d(lp.Number(2), lp.Number(3)), false);
    } else if (tag == "VERTEX_TRACKXYZ") {
      lp.ExpectCount(4, "id x y z");
      add_vertex(VertexKind::kPoint3, Eigen::Vector3d(lp.Number(2), lp.Number(3), lp.Number(4)),
                 false);
    } else if (tag == "EDGE_SE2") {
      lp.ExpectCount(11, "i j dx dy dtheta I11 I12 I13 I22 I23 I33");
      // The measured angle wrapped exactly, as a vertex's: for |θ| ≫ 2π the
      // solver's wrap(θj − θi − θz) would lose every digit of it.
      add_edge(EdgeKind::kSE2, lp.Id(1), lp.Id(2),
               Eigen::Vector3d(lp.Number(3), lp.Number(4), WrapAngleExact(lp.Number(5))),
               lp.UpperTriangle(6, 3), false);
    } else if (tag == "EDGE2") {
      lp.ExpectCount(11, "i j dx dy dtheta I11 I12 I22 I33 I13 I23");
      add_edge(EdgeKind::kSE2, lp.Id(1), lp.Id(2),
               Eigen::Vector3d(lp.Number(3), lp.Number(4), WrapAngleExact(lp.Number(5))),
               ToroInfo2(lp, 6), true);
    } else if (tag == "EDGE_SE3:QUAT") {
      lp.ExpectCount(30, "i j dx dy dz qx qy qz qw I(21, upper triangle)");
      Eigen::VectorXd z(7);
      z << lp.Number(3), lp.Number(4), lp.Number(5), lp.Quaternion(6);
      add_edge(EdgeKind::kSE3, lp.Id(1), lp.Id(2), z, lp.UpperTriangle(10, 6), false);
    } else if (tag == "EDGE3") {
      lp.ExpectCount(29, "i j dx dy dz roll pitch yaw I(21, upper triangle)");
      Eigen::VectorXd z(7);
      z << lp.Number(3), lp.Number(4), lp.Number(5),
          QuatFromEuler(lp.Number(6), lp.Number(7), lp.Number(8));
      add_edge(EdgeKind::kSE3, lp.Id(1), lp.Id(2), z, lp.UpperTriangle(9, 6), true);
    } else if (tag == "EDGE_SE2_XY") {
      lp.ExpectCount(7, "i j x y I11 I12 I22");
      add_edge(EdgeKind::kSE2Point2, lp.Id(1), lp.Id(2),
               Eigen::Vector2d(lp.Number(3), lp.Number(4)), lp.UpperTriangle(5, 2), false);
    } else if (tag == "EDGE_SE3_TRACKXYZ") {
      lp.ExpectCount(12, "i j offset_id x y z I(6, upper triangle)");
      const int param = lp.Id(3);
      add_edge(EdgeKind::kSE3Point3, lp.Id(1), lp.Id(2),
               Eigen::Vector3d(lp.Number(4), lp.Number(5), lp.Number(6)), lp.UpperTriangle(7, 3),
               false, param);
    } else if (tag == "EDGE_SE2_BEARING_RANGE") {
      lp.ExpectCount(7, "i j bearing range Ibb Ibr Irr");
      add_edge(EdgeKind::kSE2BearingRange, lp.Id(1), lp.Id(2),
               Eigen::Vector2d(lp.Number(3), lp.Number(4)), lp.UpperTriangle(5, 2), false);
    } else if (tag == "FIX") {
      if (fields.f.size() < 2) lp.Fail("FIX: no vertex id");
      std::vector<int> ids;
      for (size_t i = 1; i < fields.f.size(); ++i) ids.push_back(lp.Id(i));
      g.fixed.push_back(ids);
      fix_lines.push_back(line);
      g.order.push_back({Graph::RecordType::kFix, static_cast<int>(g.fixed.size()) - 1});
    } else if (tag == "PARAMS_SE3OFFSET") {
      lp.ExpectCount(8, "id x y z qx qy qz qw");
      const Eigen::Vector4d q = lp.Quaternion(5);
      const double t = std::abs(lp.Number(2)) + std::abs(lp.Number(3)) + std::abs(lp.Number(4));
      if (t > 1e-12 || std::abs(std::abs(q[3]) - 1.0) > 1e-12) {
        lp.Fail("PARAMS_SE3OFFSET: only the identity offset is supported");
      }
      g.params.push_back(
          std::string(fields.f.front().first, fields.f.back().first + fields.f.back().second));
      g.order.push_back({Graph::RecordType::kParam, static_cast<int>(g.params.size()) - 1});
    } else if (options.skip_unknown_tags) {
      ++rep.unknown_skipped;
      ++rep.unknown_tags[Escaped(tag)];
    } else {
      lp.Fail("unknown tag '" + Escaped(tag) + "' (skip unknown tags explicitly to ignore it)");
    }
  }
  rep.lines = line;

  // Edges must name existing vertices, unless the file has no vertex at all.
  if (!any_vertex_line) {
    g.estimates_from_file = false;
    for (const Edge& e : g.edges) {
      const bool pose_pose = e.kind == EdgeKind::kSE2 || e.kind == EdgeKind::kSE3;
      for (int k = 0; k < 2; ++k) {
        const int id = k == 0 ? e.from : e.to;
        if (g.index_of.count(id)) continue;
        Vertex v;
        v.id = id;
        v.line = e.line;
        v.has_estimate = false;
        v.toro = e.toro;
        if (k == 0 || pose_pose) {
          v.kind = g.dimension == 3 ? VertexKind::kSE3 : VertexKind::kSE2;
        } else {
          v.kind = g.dimension == 3 ? VertexKind::kPoint3 : VertexKind::kPoint2;
        }
        v.estimate = Eigen::VectorXd::Zero(AmbientSize(v.kind));
        if (v.kind == VertexKind::kSE3) v.estimate[6] = 1.0;
        const int idx = static_cast<int>(g.vertices.size());
        g.vertices.push_back(v);
        g.index_of[id] = idx;
      }
    }
    // Created vertices are written before everything else, sorted by id.
    std::vector<Graph::Record> order;
    std::vector<int> idx(g.vertices.size());
    for (size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<int>(i);
    std::sort(idx.begin(), idx.end(),
              [&](int a, int b) { return g.vertices[a].id < g.vertices[b].id; });
    for (int i : idx) order.push_back({Graph::RecordType::kVertex, i});
    order.insert(order.end(), g.order.begin(), g.order.end());
    g.order = std::move(order);
  }
  for (const Edge& e : g.edges) {
    for (int id : {e.from, e.to}) {
      if (!g.index_of.count(id)) {
        throw ParseError(name, e.line, "edge to a missing vertex " + std::to_string(id));
      }
    }
    const VertexKind a = g.vertices[g.index_of[e.from]].kind;
    const VertexKind b = g.vertices[g.index_of[e.to]].kind;
    if (!ConnectsKinds(e.kind, a, b))
      throw ParseError(name, e.line, "edge connects vertices of the wrong types");
  }
  for (size_t f = 0; f < g.fixed.size(); ++f) {
    for (int id : g.fixed[f]) {
      if (!g.index_of.count(id)) {
        throw ParseError(name, fix_lines[f], "FIX of a missing vertex " + std::to_string(id));
      }
    }
  }
  return g;
}

Graph ReadG2o(const std::string& path, const ReadOptions& options, ReadReport* report) {
  std::error_code ec;
  BOXPLUS_CHECK(!std::filesystem::is_directory(path, ec), Escaped(path),
                ": is a directory, not a g2o file");
  std::ifstream in(path, std::ios::binary);
  BOXPLUS_CHECK(in.good(), Escaped(path), ": cannot open the file");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  BOXPLUS_CHECK(!in.bad(), Escaped(path), ": reading failed");
  return ParseG2o(text, path, options, report);
}

namespace {

void Num(std::string* out, double v) {
  char buf[40];
  const int n = std::snprintf(buf, sizeof(buf), " %.17g", v);
  out->append(buf, n);
}

void UpperTo(std::string* out, const Eigen::MatrixXd& m) {
  for (int r = 0; r < m.rows(); ++r) {
    for (int c = r; c < m.cols(); ++c) Num(out, m(r, c));
  }
}

}  // namespace

std::string FormatG2o(const Graph& g) {
  std::string out;
  out.reserve(g.edges.size() * 200 + g.vertices.size() * 80);
  for (const auto& rec : g.order) {
    switch (rec.type) {
      case Graph::RecordType::kVertex: {
        const Vertex& v = g.vertices[rec.index];
        const Eigen::VectorXd& x = v.estimate;
        switch (v.kind) {
          case VertexKind::kSE2:
            out += v.toro ? "VERTEX2 " : "VERTEX_SE2 ";
            break;
          case VertexKind::kSE3:
            out += v.toro ? "VERTEX3 " : "VERTEX_SE3:QUAT ";
            break;
          case VertexKind::kPoint2:
            out += "VERTEX_XY ";
            break;
          case VertexKind::kPoint3:
            out += "VERTEX_TRACKXYZ ";
            break;
        }
        out += std::to_string(v.id);
        if (v.kind == VertexKind::kSE3 && v.toro) {
          for (int i = 0; i < 3; ++i) Num(&out, x[i]);
          const Eigen::Vector3d rpy = EulerFromQuat(x.tail<4>());
          for (int i = 0; i < 3; ++i) Num(&out, rpy[i]);
        } else {
          for (int i = 0; i < x.size(); ++i) Num(&out, x[i]);
        }
        out += '\n';
        break;
      }
      case Graph::RecordType::kEdge: {
        const Edge& e = g.edges[rec.index];
        const Eigen::VectorXd& z = e.measurement;
        switch (e.kind) {
          case EdgeKind::kSE2:
            out += e.toro ? "EDGE2 " : "EDGE_SE2 ";
            break;
          case EdgeKind::kSE3:
            out += e.toro ? "EDGE3 " : "EDGE_SE3:QUAT ";
            break;
          case EdgeKind::kSE2Point2:
            out += "EDGE_SE2_XY ";
            break;
          case EdgeKind::kSE3Point3:
            out += "EDGE_SE3_TRACKXYZ ";
            break;
          case EdgeKind::kSE2BearingRange:
            out += "EDGE_SE2_BEARING_RANGE ";
            break;
        }
        out += std::to_string(e.from) + " " + std::to_string(e.to);
        if (e.kind == EdgeKind::kSE3Point3) out += " " + std::to_string(e.param);
        if (e.kind == EdgeKind::kSE3 && e.toro) {
          for (int i = 0; i < 3; ++i) Num(&out, z[i]);
          const Eigen::Vector3d rpy = EulerFromQuat(z.tail<4>());
          for (int i = 0; i < 3; ++i) Num(&out, rpy[i]);
        } else {
          for (int i = 0; i < z.size(); ++i) Num(&out, z[i]);
        }
        const Eigen::MatrixXd& I = e.information;
        if (e.kind == EdgeKind::kSE2 && e.toro) {
          for (double v : {I(0, 0), I(0, 1), I(1, 1), I(2, 2), I(0, 2), I(1, 2)}) Num(&out, v);
        } else {
          UpperTo(&out, I);
        }
        out += '\n';
        break;
      }
      case Graph::RecordType::kFix: {
        out += "FIX";
        for (int id : g.fixed[rec.index]) out += " " + std::to_string(id);
        out += '\n';
        break;
      }
      case Graph::RecordType::kParam:
        out += g.params[rec.index] + "\n";
        break;
    }
  }
  return out;
}

void WriteG2o(const std::string& path, const Graph& graph) {
  const std::string text = FormatG2o(graph);
  std::ofstream out(path, std::ios::binary);
  BOXPLUS_CHECK(out.good(), path, ": cannot open the file for writing");
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  BOXPLUS_CHECK(out.good(), path, ": writing failed");
}

}  // namespace boxplus::io
