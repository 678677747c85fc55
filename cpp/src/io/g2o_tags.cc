// One table of the record tags: for each tag its format, its numbers, its
// parser, and the record kinds the writer writes under it (g2o_tags.h). The
// reader dispatches through it, FormatG2o takes its tags from it
// (WrittenTag), and boxplus-g2o --list-types and the fuzzer list it
// (RecordTags): a new tag is one parser and one row.
#include "g2o_tags.h"

#include <cmath>
#include <cstdint>
#include <string_view>
#include <utility>

#include <Eigen/Geometry>

#include "boxplus/errors.h"

namespace boxplus::io {
namespace detail {

void GraphBuilder::AddVertex(const LineParser& lp, VertexKind kind, Eigen::VectorXd estimate,
                             bool toro) {
  const int id = lp.Id(1);
  const auto& range = RangeOf(graph, kind);
  if (range.count(id)) {
    lp.Fail("vertex id " + std::to_string(id) + " appears twice (first at line " +
            std::to_string(graph.vertices[range.at(id)].line) + "), both " +
            (IsPoseKind(kind) ? "poses" : "landmarks"));
  }
  Vertex v;
  v.id = id;
  v.kind = kind;
  v.estimate = std::move(estimate);
  v.toro = toro;
  v.line = line;
  const int pose_dim = PoseDimension(kind);
  if (pose_dim && graph.dimension && graph.dimension != pose_dim) lp.Fail("mixes 2D and 3D poses");
  try {
    graph.AddVertex(std::move(v));
  } catch (const Error& e) {
    lp.Fail(e.what());
  }
  any_vertex_line = true;
}

Edge& GraphBuilder::AddEdge(const LineParser& lp, EdgeKind kind, int from, int to,
                            Eigen::VectorXd z, Eigen::MatrixXd info, bool toro, int param) {
  if (!IsUnary(kind) && from == to && EndIsPose(kind, 0) == EndIsPose(kind, 1)) {
    lp.Fail(lp.Tag() + ": an edge from vertex " + std::to_string(from) + " to itself");
  }
  if (kind == EdgeKind::kSE2BearingRange && !(z[1] >= 0.0)) {
    lp.Fail(lp.Tag() + ": negative range " + std::to_string(z[1]));
  }
  if (!IsPositiveDefinite(info)) {
    if (!options.repair_information) {
      lp.Fail(lp.Tag() +
              ": information matrix is not positive definite (use the repair "
              "option to replace it by the nearest positive-definite matrix)");
    }
    if (!CanRepair(info)) {
      lp.Fail(lp.Tag() + ": information matrix is zero or not finite: cannot be repaired");
    }
    try {
      info = NearestPositiveDefinite(info);
    } catch (const Error& e) {
      lp.Fail(lp.Tag() + ": " + e.what());
    }
    ++report.repaired_information;
    report.repaired_lines.push_back(line);
  }
  const bool three_d = MeasurementSize(kind) == 7 || kind == EdgeKind::kSE3Point3 ||
                       kind == EdgeKind::kSE3Point3Offset || kind == EdgeKind::kSE3PositionPrior ||
                       kind == EdgeKind::kPoint3Prior || kind == EdgeKind::kPoint3Point3;
  const int pose_dim = three_d ? 3 : 2;
  if (graph.dimension && graph.dimension != pose_dim) lp.Fail("mixes 2D and 3D poses");
  graph.dimension = pose_dim;
  Edge e;
  e.kind = kind;
  e.from = from;
  e.to = to;
  e.measurement = std::move(z);
  e.information = std::move(info);
  e.toro = toro;
  e.param = param;
  e.line = line;
  graph.edges.push_back(std::move(e));
  graph.order.push_back({Graph::RecordType::kEdge, static_cast<int>(graph.edges.size()) - 1});
  return graph.edges.back();
}

void GraphBuilder::DefineOffset(const LineParser& lp, int id, Eigen::VectorXd value) {
  if (graph.offsets.count(id)) {
    lp.Fail(lp.Tag() + ": parameter id " + std::to_string(id) + " is defined twice");
  }
  graph.offsets[id] = std::move(value);
  graph.params.push_back(lp.Text());
  graph.order.push_back({Graph::RecordType::kParam, static_cast<int>(graph.params.size()) - 1});
}

Eigen::VectorXd GraphBuilder::OffsetFor(const LineParser& lp, int id, int dimension,
                                        bool lenient) const {
  auto it = graph.offsets.find(id);
  const char* params = dimension == 2 ? "PARAMS_SE2OFFSET" : "PARAMS_SE3OFFSET";
  if (it == graph.offsets.end()) {
    if (lenient) return Eigen::VectorXd();
    lp.Fail(lp.Tag() + ": offset parameter " + std::to_string(id) + " has no " + params +
            " line before it");
  }
  if (it->second.size() != (dimension == 2 ? 3 : 7)) {
    lp.Fail(lp.Tag() + ": offset parameter " + std::to_string(id) + " is not a " + params);
  }
  return it->second;
}

namespace {

struct TagRow;
using TagParser = void (*)(GraphBuilder&, const LineParser&, const TagRow&);

// kVariableCount: the parser checks the count itself (optional or repeated fields).
constexpr int kVariableCount = -1;

struct TagRow {
  const char* tag;
  TagFamily family;
  int numbers;         // after the tag
  const char* fields;  // their names, as a wrong count's message gives them
  TagParser parse;
  // The record kinds the writer writes under this tag (bit k: kind k), and
  // whether for records read from TORO/GTSAM lines (Vertex/Edge::toro).
  uint32_t writes_vertices = 0;
  uint32_t writes_edges = 0;
  bool toro = false;
};

constexpr uint32_t Bit(VertexKind k) { return 1u << static_cast<int>(k); }
constexpr uint32_t Bit(EdgeKind k) { return 1u << static_cast<int>(k); }

bool IsToro(const TagRow& row) { return row.family != TagFamily::kG2o; }

Eigen::Vector3d SE2At(const LineParser& lp, size_t first) {
  return {lp.Number(first), lp.Number(first + 1), WrapAngleExact(lp.Number(first + 2))};
}

Eigen::VectorXd SE3At(const LineParser& lp, size_t first) {
  Eigen::VectorXd z(7);
  z << lp.Number(first), lp.Number(first + 1), lp.Number(first + 2), lp.Quaternion(first + 3);
  return z;
}

Eigen::VectorXd VectorAt(const LineParser& lp, size_t first, int n) {
  Eigen::VectorXd v(n);
  for (int k = 0; k < n; ++k) v[k] = lp.Number(first + k);
  return v;
}

Eigen::Vector4d QuatFromEuler(double roll, double pitch, double yaw) {
  const Eigen::Quaterniond q = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  return q.coeffs();
}

// TORO 3D poses: x y z roll pitch yaw.
Eigen::VectorXd EulerPoseAt(const LineParser& lp, size_t first) {
  Eigen::VectorXd v(7);
  v << lp.Number(first), lp.Number(first + 1), lp.Number(first + 2),
      QuatFromEuler(lp.Number(first + 3), lp.Number(first + 4), lp.Number(first + 5));
  return v;
}

// TORO EDGE2 stores I11 I12 I22 I33 I13 I23.
Eigen::MatrixXd ToroInfo2(const LineParser& p, size_t first) {
  Eigen::MatrixXd m(3, 3);
  const double i11 = p.Number(first), i12 = p.Number(first + 1), i22 = p.Number(first + 2),
               i33 = p.Number(first + 3), i13 = p.Number(first + 4), i23 = p.Number(first + 5);
  m << i11, i12, i13, i12, i22, i23, i13, i23, i33;
  return m;
}

bool IsIdentityOffset(const Eigen::VectorXd& o) {
  if (o.size() == 0) return true;
  if (o.size() == 3) return o.cwiseAbs().maxCoeff() == 0.0;
  return o.head<3>().cwiseAbs().maxCoeff() == 0.0 && std::abs(o[6]) == 1.0;
}

// ---- one parser per record --------------------------------------------------

void VertexSE2(GraphBuilder& b, const LineParser& lp, const TagRow& row) {
  b.AddVertex(lp, VertexKind::kSE2, SE2At(lp, 2), IsToro(row));
}

void VertexSE3(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  b.AddVertex(lp, VertexKind::kSE3, SE3At(lp, 2), false);
}

void VertexSE3Euler(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  b.AddVertex(lp, VertexKind::kSE3, EulerPoseAt(lp, 2), true);
}

void VertexPoint2(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  b.AddVertex(lp, VertexKind::kPoint2, VectorAt(lp, 2, 2), false);
}

void VertexPoint3(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  b.AddVertex(lp, VertexKind::kPoint3, VectorAt(lp, 2, 3), false);
}

void EdgeSE2(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  // The measured angle wrapped exactly, as a vertex's: for |θ| ≫ 2π the
  // solver's wrap(θj − θi − θz) would lose every digit of it.
  b.AddEdge(lp, EdgeKind::kSE2, lp.Id(1), lp.Id(2), SE2At(lp, 3), lp.UpperTriangle(6, 3), false);
}

void EdgeSE2Toro(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  b.AddEdge(lp, EdgeKind::kSE2, lp.Id(1), lp.Id(2), SE2At(lp, 3), ToroInfo2(lp, 6), true);
}

void EdgeSE3(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  b.AddEdge(lp, EdgeKind::kSE3, lp.Id(1), lp.Id(2), SE3At(lp, 3), lp.UpperTriangle(10, 6), false);
}

void EdgeSE3Toro(GraphBuilder& b, const LineParser& lp, const TagRow& row) {
  // GTSAM's loader reads EDGE3 without I(21) as the identity information.
  const bool without_info = lp.size() == 9;
  if (!without_info) lp.ExpectCount(29, row.fields);
  const Eigen::MatrixXd info =
      without_info ? Eigen::MatrixXd::Identity(6, 6) : lp.UpperTriangle(9, 6);
  Edge& e = b.AddEdge(lp, EdgeKind::kSE3, lp.Id(1), lp.Id(2), EulerPoseAt(lp, 3), info, true);
  if (without_info) {
    e.identity_information = true;
    if (b.report.identity_information++ == 0) b.report.first_identity_line = b.line;
  }
}

// EDGE_SE2_XY, and LANDMARK2 of GTSAM's example data (cityTrees,
// victoriaPark): the same line, pose id, landmark id, the point in the pose's
// frame and its information; each written back under its own tag.
void EdgeSE2Point2(GraphBuilder& b, const LineParser& lp, const TagRow& row) {
  b.AddEdge(lp, EdgeKind::kSE2Point2, lp.Id(1), lp.Id(2), VectorAt(lp, 3, 2),
            lp.UpperTriangle(5, 2), IsToro(row));
}

void EdgeSE3Point3(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  const int param = lp.Id(3);
  Eigen::VectorXd offset = b.OffsetFor(lp, param, 3, true);
  const bool identity = IsIdentityOffset(offset);
  Edge& e = b.AddEdge(lp, identity ? EdgeKind::kSE3Point3 : EdgeKind::kSE3Point3Offset, lp.Id(1),
                      lp.Id(2), VectorAt(lp, 4, 3), lp.UpperTriangle(7, 3), false, param);
  if (!identity) e.offset = std::move(offset);
}

void EdgeSE2BearingRange(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  b.AddEdge(lp, EdgeKind::kSE2BearingRange, lp.Id(1), lp.Id(2), VectorAt(lp, 3, 2),
            lp.UpperTriangle(5, 2), false);
}

template <int D>
void EdgeOffset(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  const int pa = lp.Id(3), pb = lp.Id(4);
  Eigen::VectorXd oa = b.OffsetFor(lp, pa, D, false);
  Eigen::VectorXd ob = b.OffsetFor(lp, pb, D, false);
  Edge& e = b.AddEdge(lp, D == 3 ? EdgeKind::kSE3Offset : EdgeKind::kSE2Offset, lp.Id(1), lp.Id(2),
                      D == 3 ? SE3At(lp, 5) : Eigen::VectorXd(SE2At(lp, 5)),
                      lp.UpperTriangle(D == 3 ? 12 : 8, D == 3 ? 6 : 3), false, pa);
  e.param_to = pb;
  e.offset = std::move(oa);
  e.offset_to = std::move(ob);
}

void PriorSE2(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  const int i = lp.Id(1);
  b.AddEdge(lp, EdgeKind::kSE2Prior, i, i, SE2At(lp, 2), lp.UpperTriangle(5, 3), false);
}

void PriorSE3(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  const int i = lp.Id(1), param = lp.Id(2);
  Eigen::VectorXd offset = b.OffsetFor(lp, param, 3, false);
  Edge& e =
      b.AddEdge(lp, EdgeKind::kSE3Prior, i, i, SE3At(lp, 3), lp.UpperTriangle(10, 6), false, param);
  e.offset = std::move(offset);
}

template <EdgeKind K>
void PriorPoint2(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  const int i = lp.Id(1);
  b.AddEdge(lp, K, i, i, VectorAt(lp, 2, 2), lp.UpperTriangle(4, 2), false);
}

void PriorSE3Position(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  const int i = lp.Id(1), param = lp.Id(2);
  // g2o's computeError ignores the offset; it must still exist.
  b.OffsetFor(lp, param, 3, false);
  b.AddEdge(lp, EdgeKind::kSE3PositionPrior, i, i, VectorAt(lp, 3, 3), lp.UpperTriangle(6, 3),
            false, param);
}

void PriorPoint3(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  const int i = lp.Id(1);
  b.AddEdge(lp, EdgeKind::kPoint3Prior, i, i, VectorAt(lp, 2, 3), lp.UpperTriangle(5, 3), false);
}

void EdgePoint2Point2(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  b.AddEdge(lp, EdgeKind::kPoint2Point2, lp.Id(1), lp.Id(2), VectorAt(lp, 3, 2),
            lp.UpperTriangle(5, 2), false);
}

void EdgePoint3Point3(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  b.AddEdge(lp, EdgeKind::kPoint3Point3, lp.Id(1), lp.Id(2), VectorAt(lp, 3, 3),
            lp.UpperTriangle(6, 3), false);
}

void EdgeSE2Point2Offset(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  const int param = lp.Id(3);
  Eigen::VectorXd offset = b.OffsetFor(lp, param, 2, false);
  Edge& e = b.AddEdge(lp, EdgeKind::kSE2Point2Offset, lp.Id(1), lp.Id(2), VectorAt(lp, 4, 2),
                      lp.UpperTriangle(6, 2), false, param);
  e.offset = std::move(offset);
}

void EdgeSE2Bearing(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  Eigen::VectorXd z(1);
  z << WrapAngleExact(lp.Number(3));
  b.AddEdge(lp, EdgeKind::kSE2Bearing, lp.Id(1), lp.Id(2), z, lp.UpperTriangle(4, 1), false);
}

void Fix(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  if (lp.size() < 2) lp.Fail("FIX: no vertex id");
  std::vector<int> ids;
  for (size_t i = 1; i < lp.size(); ++i) ids.push_back(lp.Id(i));
  b.graph.fixed.push_back(ids);
  b.fix_lines.push_back(b.line);
  b.graph.order.push_back({Graph::RecordType::kFix, static_cast<int>(b.graph.fixed.size()) - 1});
}

void Equiv(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  const int a = lp.Id(1), c = lp.Id(2);
  if (a == c) lp.Fail("EQUIV: a vertex with itself");
  // Resolved once every edge is read (the edge between them may follow).
  b.equivs.push_back({a, c, b.line, b.graph.order.size()});
  b.graph.order.push_back({Graph::RecordType::kEdge, -1});
  ++b.report.equiv;
}

void ParamsSE3Offset(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  b.DefineOffset(lp, lp.Id(1), SE3At(lp, 2));
}

void ParamsSE2Offset(GraphBuilder& b, const LineParser& lp, const TagRow&) {
  b.DefineOffset(lp, lp.Id(1), SE2At(lp, 2));
}

// ---- the table ----------------------------------------------------------------

using F = TagFamily;
using V = VertexKind;
using E = EdgeKind;

// In the order --list-types prints them; the first row writing a kind (with
// its toro flag) is the writer's tag for it.
const TagRow kTags[] = {
    {"VERTEX_SE2", F::kG2o, 4, "id x y theta", VertexSE2, Bit(V::kSE2)},
    {"VERTEX_XY", F::kG2o, 3, "id x y", VertexPoint2, Bit(V::kPoint2)},
    {"VERTEX_SE3:QUAT", F::kG2o, 8, "id x y z qx qy qz qw", VertexSE3, Bit(V::kSE3)},
    {"VERTEX_TRACKXYZ", F::kG2o, 4, "id x y z", VertexPoint3, Bit(V::kPoint3)},
    {"PARAMS_SE2OFFSET", F::kG2o, 4, "id x y theta", ParamsSE2Offset},
    {"PARAMS_SE3OFFSET", F::kG2o, 8, "id x y z qx qy qz qw", ParamsSE3Offset},
    {"EDGE_SE2", F::kG2o, 11, "i j dx dy dtheta I11 I12 I13 I22 I23 I33", EdgeSE2, 0, Bit(E::kSE2)},
    {"EDGE_SE2_XY", F::kG2o, 7, "i j x y I11 I12 I22", EdgeSE2Point2, 0, Bit(E::kSE2Point2)},
    {"EDGE_SE2_OFFSET", F::kG2o, 13, "i j p_from p_to dx dy dtheta I(6, upper triangle)",
     EdgeOffset<2>, 0, Bit(E::kSE2Offset)},
    {"EDGE_SE2_POINTXY_OFFSET", F::kG2o, 8, "i j p x y I11 I12 I22", EdgeSE2Point2Offset, 0,
     Bit(E::kSE2Point2Offset)},
    {"EDGE_PRIOR_SE2", F::kG2o, 10, "i x y theta I(6, upper triangle)", PriorSE2, 0,
     Bit(E::kSE2Prior)},
    {"EDGE_PRIOR_SE2_XY", F::kG2o, 6, "i x y I11 I12 I22", PriorPoint2<E::kSE2PositionPrior>, 0,
     Bit(E::kSE2PositionPrior)},
    {"EDGE_PRIOR_XY", F::kG2o, 6, "i x y I11 I12 I22", PriorPoint2<E::kPoint2Prior>, 0,
     Bit(E::kPoint2Prior)},
    {"EDGE_POINTXY", F::kG2o, 7, "i j dx dy I11 I12 I22", EdgePoint2Point2, 0,
     Bit(E::kPoint2Point2)},
    {"EDGE_BEARING_SE2_XY", F::kG2o, 4, "i j bearing I", EdgeSE2Bearing, 0, Bit(E::kSE2Bearing)},
    {"EDGE_SE3:QUAT", F::kG2o, 30, "i j dx dy dz qx qy qz qw I(21, upper triangle)", EdgeSE3, 0,
     Bit(E::kSE3)},
    {"EDGE_SE3_TRACKXYZ", F::kG2o, 12, "i j offset_id x y z I(6, upper triangle)", EdgeSE3Point3, 0,
     Bit(E::kSE3Point3) | Bit(E::kSE3Point3Offset)},
    {"EDGE_SE3_OFFSET", F::kG2o, 32, "i j p_from p_to dx dy dz qx qy qz qw I(21, upper triangle)",
     EdgeOffset<3>, 0, Bit(E::kSE3Offset)},
    {"EDGE_SE3_PRIOR", F::kG2o, 30, "i p x y z qx qy qz qw I(21, upper triangle)", PriorSE3, 0,
     Bit(E::kSE3Prior)},
    {"EDGE_SE3_XYZ_PRIOR", F::kG2o, 11, "i p x y z I(6, upper triangle)", PriorSE3Position, 0,
     Bit(E::kSE3PositionPrior)},
    {"EDGE_POINTXYZ", F::kG2o, 11, "i j dx dy dz I(6, upper triangle)", EdgePoint3Point3, 0,
     Bit(E::kPoint3Point3)},
    {"EDGE_POINTXYZ_PRIOR", F::kG2o, 10, "i x y z I(6, upper triangle)", PriorPoint3, 0,
     Bit(E::kPoint3Prior)},
    {"FIX", F::kG2o, kVariableCount, "id [id ...]", Fix},
    {"EDGE_SE2_BEARING_RANGE", F::kBoxplus, 7, "i j bearing range Ibb Ibr Irr", EdgeSE2BearingRange,
     0, Bit(E::kSE2BearingRange)},
    {"VERTEX2", F::kToro, 4, "id x y theta", VertexSE2, Bit(V::kSE2), 0, true},
    {"VERTEX", F::kToro, 4, "id x y theta", VertexSE2},
    {"EDGE2", F::kToro, 11, "i j dx dy dtheta I11 I12 I22 I33 I13 I23", EdgeSE2Toro, 0,
     Bit(E::kSE2), true},
    {"EDGE", F::kToro, 11, "i j dx dy dtheta I11 I12 I22 I33 I13 I23", EdgeSE2Toro},
    {"VERTEX3", F::kToro, 7, "id x y z roll pitch yaw", VertexSE3Euler, Bit(V::kSE3), 0, true},
    {"EDGE3", F::kToro, kVariableCount, "i j dx dy dz roll pitch yaw [I(21, upper triangle)]",
     EdgeSE3Toro, 0, Bit(E::kSE3), true},
    {"EQUIV", F::kToro, 2, "i j", Equiv},
    {"LANDMARK2", F::kGtsam, 7, "i j x y I11 I12 I22", EdgeSE2Point2, 0, Bit(E::kSE2Point2), true},
};

const TagRow* FindTag(std::string_view tag) {
  static const std::unordered_map<std::string_view, const TagRow*> by_tag = [] {
    std::unordered_map<std::string_view, const TagRow*> m;
    for (const TagRow& row : kTags) m.emplace(row.tag, &row);
    return m;
  }();
  const auto it = by_tag.find(tag);
  return it == by_tag.end() ? nullptr : it->second;
}

// The writer's tag: the first row writing the kind from lines of the record's
// own family (toro), else the first writing it at all.
template <typename Kind>
const char* WrittenTagOf(Kind kind, bool toro, uint32_t TagRow::*writes) {
  const TagRow* any = nullptr;
  for (const TagRow& row : kTags) {
    if (!(row.*writes & Bit(kind))) continue;
    if (row.toro == toro) return row.tag;
    if (!any) any = &row;
  }
  BOXPLUS_CHECK(any != nullptr, "no tag writes record kind ", static_cast<int>(kind));
  return any->tag;
}

}  // namespace

bool ReadRecord(GraphBuilder& builder, const LineParser& lp) {
  const TagRow* row = FindTag(lp.TagView());
  if (row == nullptr) return false;
  if (row->numbers != kVariableCount) lp.ExpectCount(row->numbers, row->fields);
  row->parse(builder, lp, *row);
  return true;
}

}  // namespace detail

std::vector<TagInfo> RecordTags() {
  std::vector<TagInfo> tags;
  for (const detail::TagRow& row : detail::kTags) tags.push_back({row.tag, row.family, row.fields});
  return tags;
}

const char* ToString(TagFamily family) {
  switch (family) {
    case TagFamily::kG2o:
      return "g2o";
    case TagFamily::kBoxplus:
      return "boxplus";
    case TagFamily::kToro:
      return "TORO";
    case TagFamily::kGtsam:
      return "GTSAM's example data";
  }
  return "?";
}

const char* WrittenTag(VertexKind kind, bool toro) {
  return detail::WrittenTagOf(kind, toro, &detail::TagRow::writes_vertices);
}

const char* WrittenTag(EdgeKind kind, bool toro) {
  return detail::WrittenTagOf(kind, toro, &detail::TagRow::writes_edges);
}

}  // namespace boxplus::io
