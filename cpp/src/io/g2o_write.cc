// Writing a pose-graph file: every record in its original order, ids and tag
// family (io/g2o.h); the tags from the one tag table (g2o_tags.cc).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include <Eigen/Geometry>

#include "boxplus/errors.h"
#include "boxplus/factors/pose/unit_quaternion.h"
#include "boxplus/io/g2o.h"

#include "boxplus/io/atomic_file.h"

namespace boxplus::io {
namespace {

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
        out += WrittenTag(v.kind, v.toro);
        out += ' ';
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
        if (e.equiv) {
          out += "EQUIV " + std::to_string(e.from) + " " + std::to_string(e.to) + "\n";
          break;
        }
        out += WrittenTag(e.kind, e.toro);
        out += ' ';
        out += std::to_string(e.from);
        if (!IsUnary(e.kind)) out += " " + std::to_string(e.to);
        switch (e.kind) {
          case EdgeKind::kSE3Point3:
          case EdgeKind::kSE3Point3Offset:
          case EdgeKind::kSE3Prior:
          case EdgeKind::kSE3PositionPrior:
          case EdgeKind::kSE2Point2Offset:
            out += " " + std::to_string(e.param);
            break;
          case EdgeKind::kSE2Offset:
          case EdgeKind::kSE3Offset:
            out += " " + std::to_string(e.param) + " " + std::to_string(e.param_to);
            break;
          default:
            break;
        }
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
        } else if (e.identity_information) {
          // EDGE3 as read: without its (identity) information.
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
  WriteFileAtomically(path, FormatG2o(graph));
}

}  // namespace boxplus::io
