// Tests of the g2o/TORO reader and writer: every tag, strict errors with the
// file and line, explicit repair and skip switches, writing round trips.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "boxplus/errors.h"
#include "boxplus/io/g2o.h"

namespace boxplus::io {
namespace {

using ::testing::HasSubstr;

const std::string kData = std::string(BOXPLUS_SOURCE_DIR) + "/tests/data/";

// The message of the ParseError thrown by parsing `text`, or "" if none.
std::string ParseErrorOf(const std::string& text, ReadOptions o = {}) {
  try {
    ParseG2o(text, "test.g2o", o);
  } catch (const ParseError& e) {
    return e.what();
  }
  return "";
}

const char* kTwo = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\n";

TEST(G2oRead, AllTagsOfA3DFile) {
  const std::string text =
      "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\n"
      "VERTEX_SE3:QUAT 1 1 0 0 0 0 0 2\n"  // normalised when read
      "VERTEX_TRACKXYZ 5 1 2 3\n"
      "PARAMS_SE3OFFSET 0 0 0 0 0 0 0 1\n"
      "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 1 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1\n"
      "EDGE_SE3_TRACKXYZ 1 5 0 0 2 3 4 0 0 4 0 4\n"
      "FIX 0\n";
  Graph g = ParseG2o(text, "t.g2o");
  ASSERT_EQ(g.vertices.size(), 3u);
  ASSERT_EQ(g.edges.size(), 2u);
  EXPECT_EQ(g.dimension, 3);
  EXPECT_DOUBLE_EQ(g.vertices[1].estimate[6], 1.0);
  EXPECT_EQ(g.edges[1].kind, EdgeKind::kSE3Point3);
  EXPECT_DOUBLE_EQ(g.edges[1].information(2, 2), 4.0);
  EXPECT_EQ(g.FixedIds(), std::vector<int>{0});
}

TEST(G2oRead, UpperTriangleFillsTheSymmetricMatrix) {
  Graph g = ParseG2o(std::string(kTwo) + "EDGE_SE2 0 1 1 0 0 50 2 3 60 4 70\n", "t");
  Eigen::Matrix3d expected;
  expected << 50, 2, 3, 2, 60, 4, 3, 4, 70;
  EXPECT_TRUE((g.edges[0].information - expected).norm() == 0.0);
}

TEST(G2oRead, ToroEdge2InformationOrder) {
  // TORO: I11 I12 I22 I33 I13 I23.
  Graph g = ParseG2o("VERTEX2 0 0 0 0\nVERTEX2 1 1 0 0\nEDGE2 0 1 1 0 0 10 1 20 30 2 3\n", "t");
  const Eigen::MatrixXd& I = g.edges[0].information;
  EXPECT_EQ(I(0, 0), 10);
  EXPECT_EQ(I(0, 1), 1);
  EXPECT_EQ(I(1, 1), 20);
  EXPECT_EQ(I(2, 2), 30);
  EXPECT_EQ(I(0, 2), 2);
  EXPECT_EQ(I(1, 2), 3);
  // Written back in TORO order.
  EXPECT_THAT(FormatG2o(g), HasSubstr("EDGE2 0 1 1 0 0 10 1 20 30 2 3\n"));
}

TEST(G2oRead, Toro3DEulerAngles) {
  Graph g = ParseG2o("VERTEX3 0 0 0 0 0 0 0\nVERTEX3 1 1 2 3 0 0 1.5707963267948966\n", "t");
  const Eigen::VectorXd& x = g.vertices[1].estimate;
  EXPECT_NEAR(x[5], std::sqrt(0.5), 1e-12);  // qz of a yaw of 90°
  EXPECT_NEAR(x[6], std::sqrt(0.5), 1e-12);
  const Graph back = ParseG2o(FormatG2o(g), "t2");
  EXPECT_LT((back.vertices[1].estimate - x).norm(), 1e-15);
}

TEST(G2oErrors, NameTheFileAndLine) {
  EXPECT_EQ(ParseErrorOf(std::string(kTwo) + "FOO 1 2\n"),
            "test.g2o:3: unknown tag 'FOO' (skip unknown tags explicitly to ignore it)");
  EXPECT_THAT(ParseErrorOf(std::string(kTwo) + "EDGE_SE2 0 1 1 0 0 1 0 0 1 0\n"),
              HasSubstr("test.g2o:3: EDGE_SE2: too few numbers (10, expected 11"));
  EXPECT_THAT(ParseErrorOf(std::string(kTwo) + "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1 7\n"),
              HasSubstr("test.g2o:3: EDGE_SE2: too many numbers"));
  EXPECT_THAT(ParseErrorOf("VERTEX_SE2 0 0 abc 0\n"),
              HasSubstr("test.g2o:1: field 4 ('abc') is not a finite number"));
  EXPECT_THAT(ParseErrorOf("VERTEX_SE2 0.5 0 0 0\n"), HasSubstr("test.g2o:1: field 2"));
  EXPECT_THAT(ParseErrorOf(std::string(kTwo) + "\n# c\nEDGE_SE2 0 7 1 0 0 1 0 0 1 0 1\n"),
              HasSubstr("test.g2o:5: edge to a missing vertex 7"));
  EXPECT_THAT(ParseErrorOf(std::string(kTwo) + "EDGE_SE2 0 1 1 0 0 1 2 0 1 0 1\n"),
              HasSubstr("test.g2o:3: EDGE_SE2: information matrix is not positive definite"));
  EXPECT_THAT(ParseErrorOf("VERTEX_SE3:QUAT 0 0 0 0 0 0 0 0\n"),
              HasSubstr("test.g2o:1: VERTEX_SE3:QUAT: quaternion has zero norm"));
  EXPECT_THAT(ParseErrorOf("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 0 0 0 0\n"),
              HasSubstr("test.g2o:2: vertex id 0 appears twice (first at line 1)"));
  EXPECT_THAT(ParseErrorOf(std::string(kTwo) + "FIX 3\n"),
              HasSubstr("test.g2o:3: FIX of a missing vertex 3"));
  EXPECT_THAT(ParseErrorOf("VERTEX_SE2 0 0 0 inf\n"), HasSubstr("is not a finite number"));
}

TEST(G2oErrors, FilesOnDiskToo) {
  try {
    ReadG2o(kData + "bad_unknown_tag.g2o");
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_THAT(e.file(), HasSubstr("bad_unknown_tag.g2o"));
  }
  EXPECT_THROW(ReadG2o(kData + "does_not_exist.g2o"), Error);
}

TEST(G2oOptions, SkipUnknownTagsCountsThem) {
  ReadOptions o;
  o.skip_unknown_tags = true;
  ReadReport rep;
  Graph g = ReadG2o(kData + "bad_unknown_tag.g2o", o, &rep);
  EXPECT_EQ(g.edges.size(), 1u);
  EXPECT_EQ(rep.unknown_skipped, 1);
  EXPECT_EQ(rep.unknown_tags.at("EDGE_SE2_FOO"), 1);
  EXPECT_THAT(rep.Warnings("f"),
              HasSubstr("skipped 1 line(s) with unknown tags (EDGE_SE2_FOO ×1)"));
}

TEST(G2oOptions, RepairInformationCountsAndFixes) {
  ReadOptions o;
  o.repair_information = true;
  ReadReport rep;
  Graph g = ReadG2o(kData + "bad_indefinite_info.g2o", o, &rep);
  EXPECT_EQ(rep.repaired_information, 1);
  EXPECT_EQ(rep.repaired_lines, std::vector<int>{4});
  EXPECT_TRUE(IsPositiveDefinite(g.edges[1].information));
  EXPECT_TRUE(g.edges[0].information.isIdentity());  // PD ones untouched
  EXPECT_THAT(rep.Warnings("f"), HasSubstr("replaced 1 information matrix"));
}

TEST(G2oOptions, NearestPositiveDefiniteKeepsPDMatricesAndClampsOthers) {
  Eigen::MatrixXd A(2, 2);
  A << 2, 0, 0, -1;
  const Eigen::MatrixXd B = NearestPositiveDefinite(A);
  EXPECT_NEAR(B(0, 0), 2.0, 1e-12);
  EXPECT_GT(B(1, 1), 0.0);
  EXPECT_LT(B(1, 1), 1e-8);
  EXPECT_THROW(NearestPositiveDefinite(Eigen::MatrixXd::Zero(2, 2)), Error);
}

TEST(G2oWrite, RoundTripKeepsIdsOrderAndValues) {
  for (const char* f : {"tinyGrid3D.g2o", "landmarks2d.g2o", "CSAIL.g2o"}) {
    SCOPED_TRACE(f);
    const Graph a = ReadG2o(kData + f);
    const Graph b = ParseG2o(FormatG2o(a), "round-trip");
    ASSERT_EQ(a.vertices.size(), b.vertices.size());
    ASSERT_EQ(a.edges.size(), b.edges.size());
    ASSERT_EQ(a.order.size(), b.order.size());
    for (size_t i = 0; i < a.vertices.size(); ++i) {
      EXPECT_EQ(a.vertices[i].id, b.vertices[i].id);
      // Quaternions are normalised again when read: equal up to rounding.
      EXPECT_TRUE(a.vertices[i].estimate.isApprox(b.vertices[i].estimate, 1e-15));
    }
    for (size_t i = 0; i < a.edges.size(); ++i) {
      EXPECT_EQ(a.edges[i].from, b.edges[i].from);
      EXPECT_TRUE(a.edges[i].measurement.isApprox(b.edges[i].measurement, 1e-15));
      EXPECT_EQ(a.edges[i].information, b.edges[i].information);
    }
  }
}

TEST(G2oRead, FileWithoutVerticesCreatesThem) {
  ReadReport rep;
  const Graph g = ReadG2o(kData + "CSAIL.g2o", {}, &rep);
  EXPECT_FALSE(g.estimates_from_file);
  EXPECT_EQ(g.vertices.size(), 1045u);
  EXPECT_EQ(g.edges.size(), 1172u);
  EXPECT_FALSE(g.vertices[3].has_estimate);
  EXPECT_EQ(g.order.front().type, Graph::RecordType::kVertex);
}

// Issue 17, item 7: q / ‖q‖ must not overflow for huge components.
TEST(G2oRead, HugeQuaternionComponentsNormaliseToTheRotationTheyMean) {
  const Graph g = ParseG2o("VERTEX_SE3:QUAT 1 0 0 0 1e200 0 0 0\n", "test.g2o");
  EXPECT_DOUBLE_EQ(g.vertices[0].estimate[3], 1.0);
  EXPECT_DOUBLE_EQ(g.vertices[0].estimate.tail<4>().norm(), 1.0);
  const Graph h = ParseG2o("VERTEX_SE3:QUAT 1 0 0 0 1e-200 0 0 1e-200\n", "test.g2o");
  EXPECT_NEAR(h.vertices[0].estimate[6], std::sqrt(0.5), 1e-15);
}

// Issue 17, item 8: TORO Euler angles at pitch ±π/2 are written back as the
// same rotation (the gimbal lock made yaw the angle of two rounding errors).
TEST(G2oWrite, ToroEulerAnglesRoundTripAtTheGimbalLock) {
  for (const double pitch : {M_PI / 2, -M_PI / 2, M_PI / 2 - 1e-7, 0.3}) {
    char line[200];
    std::snprintf(line, sizeof line, "VERTEX3 0 1 2 3 0.3 %.17g 0.5\n", pitch);
    const Graph g = ParseG2o(line, "test.graph");
    const Graph h = ParseG2o(FormatG2o(g), "test.graph");
    const Eigen::Vector4d a = g.vertices[0].estimate.tail<4>();
    const Eigen::Vector4d b = h.vertices[0].estimate.tail<4>();
    EXPECT_NEAR(std::abs(a.dot(b)), 1.0, 1e-14) << "pitch " << pitch;
  }
}

// Issue 17, items 9, 10, 14.
TEST(G2oRead, MessagesEscapeBytesAndNameTheLine) {
  EXPECT_THAT(ParseErrorOf("VERTEX_SE2 0 \xff\xfe 0 0\n"),
              HasSubstr("test.g2o:1: field 3 ('\\xff\\xfe') is not a finite number"));
  EXPECT_THAT(ParseErrorOf("JUNK\xc3( 1\n"), HasSubstr("test.g2o:1: unknown tag 'JUNK\\xc3('"));
  ReadOptions skip;
  skip.skip_unknown_tags = true;
  ReadReport rep;
  ParseG2o("JUNK\xc3( 1\n", "test.g2o", skip, &rep);
  EXPECT_EQ(rep.unknown_tags.count("JUNK\\xc3("), 1u);
  ReadOptions repair;
  repair.repair_information = true;
  EXPECT_THAT(ParseErrorOf(std::string(kTwo) + "EDGE_SE2 0 1 1 0 0 0 0 0 0 0 0\n", repair),
              HasSubstr("test.g2o:3: EDGE_SE2: information matrix is zero or not finite"));
  EXPECT_THAT(ParseErrorOf("VERTEX_SE2 0 0 0 0\nVERTEX_XY 1 0 0\n"
                           "EDGE_SE2_BEARING_RANGE 0 1 0.5 -1 1 0 1\n"),
              HasSubstr("test.g2o:3: EDGE_SE2_BEARING_RANGE: negative range"));
  EXPECT_THAT(ParseErrorOf("VERTEX_SE2 0 0x10 0 0\n"), HasSubstr("is not a finite number"));
  const Graph g = ParseG2o("VERTEX_SE2 0 0 0 1e16\n", "test.g2o");
  EXPECT_GE(g.vertices[0].estimate[2], -M_PI);
  EXPECT_LT(g.vertices[0].estimate[2], M_PI);
  try {
    ReadG2o(kData);
    ADD_FAILURE() << "a directory was read";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("is a directory"));
  }
}

// Issue 17, item 3: a failed AddVertex/AddEdge leaves the graph unchanged.
TEST(G2oGraph, FailedAddsChangeNothing) {
  Graph g = ParseG2o(kTwo, "test.g2o");
  const std::string before = FormatG2o(g);
  Vertex v;
  v.id = 5;
  v.kind = VertexKind::kSE2;
  v.estimate = Eigen::Vector3d(0, NAN, 0);
  EXPECT_THROW(g.AddVertex(v), Error);
  v.kind = VertexKind::kSE3;
  v.estimate = (Eigen::VectorXd(7) << 0, 0, 0, 0, 0, 0, 1).finished();
  EXPECT_THROW(g.AddVertex(v), Error);  // a 3D pose in a 2D graph
  Edge e;
  e.kind = EdgeKind::kSE3;
  e.from = 0;
  e.to = 1;
  e.measurement = v.estimate;
  e.information = Eigen::MatrixXd::Identity(6, 6);
  EXPECT_THROW(g.AddEdge(e), Error);  // an SE3 edge between SE2 vertices
  e.kind = EdgeKind::kSE2;
  e.measurement = Eigen::Vector3d(1, 0, 0);
  e.information = -Eigen::MatrixXd::Identity(3, 3);
  EXPECT_THROW(g.AddEdge(e), Error);
  e.to = 9;
  e.information = Eigen::MatrixXd::Identity(3, 3);
  EXPECT_THROW(g.AddEdge(e), IndexError);
  EXPECT_EQ(FormatG2o(g), before);
  EXPECT_EQ(g.vertices.size(), 2u);
  EXPECT_EQ(g.order.size(), 2u);
}

TEST(G2oRead, ProgressIsReportedEveryNLinesWithTheBytesRead) {
  std::string text;
  for (int i = 0; i < 10; ++i) text += "VERTEX_SE2 " + std::to_string(i) + " 0 0 0\n";
  std::vector<ReadProgress> calls;
  ReadOptions o;
  o.progress_lines = 3;
  o.on_progress = [&](const ReadProgress& p) { calls.push_back(p); };
  ParseG2o(text, "t", o);
  ASSERT_EQ(calls.size(), 3u);
  for (size_t k = 0; k < calls.size(); ++k) {
    EXPECT_EQ(calls[k].lines, 3 * static_cast<long long>(k + 1));
    EXPECT_EQ(calls[k].bytes_total, text.size());
    // Every line of this text has the same length.
    EXPECT_EQ(calls[k].bytes, calls[k].lines * (text.size() / 10));
  }
}

TEST(G2oRead, OffsetEdgesKeepTheirParametersAndValues) {
  const Graph g = ReadG2o(kData + "g2o_tags/se3_offset.g2o");
  ASSERT_EQ(g.edges.size(), 3u);
  const Edge& e = g.edges[1];
  EXPECT_EQ(e.kind, EdgeKind::kSE3Offset);
  EXPECT_EQ(e.param, 1);
  EXPECT_EQ(e.param_to, 0);
  ASSERT_EQ(e.offset.size(), 7);
  EXPECT_DOUBLE_EQ(e.offset[0], 0.2);
  EXPECT_NEAR(e.offset.tail<4>().norm(), 1.0, 1e-15);
  // Written back with both ids, and the PARAMS lines verbatim.
  const std::string text = FormatG2o(g);
  EXPECT_THAT(text, HasSubstr("PARAMS_SE3OFFSET 1 0.2 0 0.1 0 0.0499792 0 0.9987503\n"));
  EXPECT_THAT(text, HasSubstr("EDGE_SE3_OFFSET 1 2 1 0 0.9"));
  EXPECT_EQ(FormatG2o(ParseG2o(text, "again")), text);
}

TEST(G2oRead, TrackXyzWithANonIdentityOffsetIsItsOwnKind) {
  const Graph g = ReadG2o(kData + "g2o_tags/se3_trackxyz_offset.g2o");
  EXPECT_EQ(g.edges[1].kind, EdgeKind::kSE3Point3Offset);
  EXPECT_EQ(g.edges[3].kind, EdgeKind::kSE3Point3);  // offset 0 is the identity
  EXPECT_THAT(FormatG2o(g), HasSubstr("EDGE_SE3_TRACKXYZ 0 9 1 1.1"));
}

TEST(G2oRead, PriorsNameOneVertex) {
  const Graph g = ReadG2o(kData + "g2o_tags/prior_se2.g2o");
  const Edge& e = g.edges[1];
  EXPECT_EQ(e.kind, EdgeKind::kSE2Prior);
  EXPECT_TRUE(IsUnary(e.kind));
  EXPECT_EQ(e.from, 0);
  EXPECT_EQ(e.to, 0);
  EXPECT_THAT(FormatG2o(g), HasSubstr("EDGE_PRIOR_SE2 0 0 0 0 1000"));
}

TEST(G2oRead, PosesAndLandmarksHaveTheirOwnIdRanges) {
  const Graph g = ReadG2o(kData + "g2o_tags/landmark_id_range.g2o");
  ASSERT_EQ(g.vertices.size(), 4u);
  EXPECT_EQ(g.VertexIndex(0), 0);  // the pose when both exist
  const Edge& seen = g.edges[3];   // EDGE_SE2_XY 1 1: pose 1 sees landmark 1
  EXPECT_EQ(g.vertices[g.EndIndex(seen, 0)].kind, VertexKind::kSE2);
  EXPECT_EQ(g.vertices[g.EndIndex(seen, 1)].kind, VertexKind::kPoint2);
  EXPECT_EQ(g.EndIndex(seen, 1), 3);
  // Within one range an id is still unique.
  EXPECT_THAT(ParseErrorOf("VERTEX_XY 0 0 0\nVERTEX_XY 0 1 1\n"),
              HasSubstr("test.g2o:2: vertex id 0 appears twice (first at line 1), both landmarks"));
}

TEST(G2oRead, EquivTakesTheEdgeBetweenItsVerticesOrientedElseTheIdentity) {
  const Graph g = ReadG2o(kData + "g2o_tags/toro_equiv.g2o");
  ASSERT_EQ(g.edges.size(), 7u);
  const Edge& q13 = g.edges[5];
  const Edge& q04 = g.edges[6];
  EXPECT_TRUE(q13.equiv && q04.equiv);
  EXPECT_EQ(q13.from, 1);
  EXPECT_EQ(q13.to, 3);
  // The file's edge is 3 → 1 with z = (0.05, 1.0, −3.1): EQUIV 1 3 holds z⁻¹.
  const double c = std::cos(-3.1), s = std::sin(-3.1);
  EXPECT_NEAR(q13.measurement[0], -(c * 0.05 + s * 1.0), 1e-15);
  EXPECT_NEAR(q13.measurement[1], s * 0.05 - c * 1.0, 1e-15);
  EXPECT_NEAR(q13.measurement[2], 3.1, 1e-15);
  EXPECT_EQ(q04.measurement, Eigen::Vector3d::Zero());
  EXPECT_EQ(q04.information, 1e6 * Eigen::MatrixXd::Identity(3, 3));
  // Written back as the EQUIV lines, where they were.
  EXPECT_THAT(FormatG2o(g), HasSubstr("\nEQUIV 1 3\nEQUIV 0 4\n"));
}

TEST(G2oRead, Edge3WithoutInformationIsTheIdentityAndCounted) {
  ReadReport report;
  const Graph g = ReadG2o(kData + "g2o_tags/edge3_no_information.g2o", {}, &report);
  EXPECT_EQ(report.identity_information, 2);
  EXPECT_EQ(report.first_identity_line, 5);
  EXPECT_EQ(g.edges[0].information, Eigen::MatrixXd::Identity(6, 6));
  EXPECT_TRUE(g.edges[0].identity_information);
  EXPECT_FALSE(g.edges[1].identity_information);
  EXPECT_THAT(report.Warnings("f.g2o"),
              HasSubstr("f.g2o: warning: 2 EDGE3 line(s) without an information matrix"));
}

// The number reader (a fast path for short plain decimals, std::from_chars
// for the rest) returns strtod's double, bit for bit, for every form a file
// may hold, and refuses what strtod would not read whole or read as infinite.
TEST(G2oRead, NumbersAreReadAsStrtodReadsThem) {
  for (const char* token : {"0",
                            "-0",
                            "0.0",
                            "-0.000000",
                            "1.",
                            ".5",
                            "+1.5",
                            "-1.234567",
                            "40000.0",
                            "0.1",
                            "123456789012345",
                            "1234567890123456",
                            "12345.678901234",
                            "399.99999999999994",
                            "-0.30000000000000004",
                            "1e5",
                            "1E-5",
                            "+2.5e-3",
                            "1e-400",
                            "4.9e-324",
                            "1.7976931348623157e308",
                            "0.000000000000001",
                            "999999999999999.9"}) {
    const Graph g = ParseG2o(std::string("VERTEX_SE2 0 ") + token + " 0 0\n", "n.g2o");
    const double expected = std::strtod(token, nullptr);
    const double got = g.vertices[0].estimate[0];
    EXPECT_EQ(std::memcmp(&got, &expected, sizeof(double)), 0)
        << token << ": " << got << " vs strtod " << expected;
  }
  for (const char* token : {"0x10", "1e400", "-1e999", "nan", "inf", "1.2.3", "--1", "+-1", "-",
                            "+", ".", "1e", "1,5", "٣"}) {
    EXPECT_THROW(ParseG2o(std::string("VERTEX_SE2 0 ") + token + " 0 0\n", "n.g2o"), ParseError)
        << token;
  }
}

// A text of several of the reader's blocks (it converts numbers a block ahead
// on another thread): lines, values and the first bad line are as if read
// line by line, wherever a block boundary falls.
TEST(G2oRead, BigTextsReadAsLineByLine) {
  const int n = 30000;  // about 2 MB, two blocks and more
  std::string text;
  for (int i = 0; i < n; ++i) {
    text += "VERTEX_SE2 " + std::to_string(i) + " " + std::to_string(i) + ".25 -1.5 0\n";
    if (i % 977 == 0) text += "# a comment\n\n";
  }
  for (int i = 0; i + 1 < n; ++i) {
    text += "EDGE_SE2 " + std::to_string(i) + " " + std::to_string(i + 1) + " 1 0 0.125 " +
            std::to_string(i + 1) + " 0 0 2 0 3\n";
  }
  ReadReport report;
  const Graph g = ParseG2o(text, "big.g2o", {}, &report);
  ASSERT_EQ(g.vertices.size(), static_cast<size_t>(n));
  ASSERT_EQ(g.edges.size(), static_cast<size_t>(n - 1));
  const int comment_lines = 2 * ((n - 1) / 977 + 1);
  EXPECT_EQ(report.lines, n + comment_lines + n - 1);
  for (int i : {0, 977, 17000, n - 1}) {
    EXPECT_EQ(g.vertices[i].id, i);
    EXPECT_EQ(g.vertices[i].estimate[0], i + 0.25);
    EXPECT_EQ(g.vertices[i].estimate[1], -1.5);
  }
  for (int k : {0, 12345, n - 2}) {
    EXPECT_EQ(g.edges[k].from, k);
    EXPECT_EQ(g.edges[k].information(0, 0), k + 1.0);
    EXPECT_EQ(g.edges[k].measurement[2], 0.125);
    EXPECT_EQ(g.edges[k].line, n + comment_lines + k + 1);
  }
  // Two bad lines far apart: the first in file order is reported.
  std::string bad = text;
  const std::string second = "EDGE_SE2 27000 27001 ";
  const std::string first = "EDGE_SE2 20000 20001 ";
  bad.replace(bad.find(second) + second.size(), 1, "x");
  bad.replace(bad.find(first) + first.size(), 1, "q");
  EXPECT_THAT(ParseErrorOf(bad), HasSubstr("test.g2o:" + std::to_string(n + comment_lines + 20001) +
                                           ": field 4 ('q') is not a finite number"));
}

}  // namespace
}  // namespace boxplus::io
