// The tables of the g2o/TORO record kinds: sizes, arity, which end is a pose,
// which vertex kinds an edge connects (io/g2o.h).
#include "boxplus/io/g2o.h"

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
    case EdgeKind::kSE2Offset:
    case EdgeKind::kSE2Prior:
      return 3;
    case EdgeKind::kSE3Offset:
    case EdgeKind::kSE3Prior:
      return 6;
    case EdgeKind::kSE2PositionPrior:
    case EdgeKind::kPoint2Prior:
    case EdgeKind::kPoint2Point2:
    case EdgeKind::kSE2Point2Offset:
      return 2;
    case EdgeKind::kSE3PositionPrior:
    case EdgeKind::kPoint3Prior:
    case EdgeKind::kPoint3Point3:
    case EdgeKind::kSE3Point3Offset:
      return 3;
    case EdgeKind::kSE2Bearing:
      return 1;
  }
  return 0;
}

int MeasurementSize(EdgeKind kind) {
  const bool se3 =
      kind == EdgeKind::kSE3 || kind == EdgeKind::kSE3Offset || kind == EdgeKind::kSE3Prior;
  return se3 ? 7 : ErrorSize(kind);
}

bool IsUnary(EdgeKind kind) {
  switch (kind) {
    case EdgeKind::kSE2Prior:
    case EdgeKind::kSE3Prior:
    case EdgeKind::kSE2PositionPrior:
    case EdgeKind::kSE3PositionPrior:
    case EdgeKind::kPoint2Prior:
    case EdgeKind::kPoint3Prior:
      return true;
    default:
      return false;
  }
}

bool EndIsPose(EdgeKind kind, int end) {
  switch (kind) {
    case EdgeKind::kPoint2Prior:
    case EdgeKind::kPoint3Prior:
    case EdgeKind::kPoint2Point2:
    case EdgeKind::kPoint3Point3:
      return false;
    case EdgeKind::kSE2Point2:
    case EdgeKind::kSE3Point3:
    case EdgeKind::kSE2BearingRange:
    case EdgeKind::kSE2Point2Offset:
    case EdgeKind::kSE3Point3Offset:
    case EdgeKind::kSE2Bearing:
      return end == 0;
    default:
      return true;
  }
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
    case EdgeKind::kSE3Point3Offset:
      return a == VertexKind::kSE3 && b == VertexKind::kPoint3;
    case EdgeKind::kSE2Offset:
      return a == VertexKind::kSE2 && b == VertexKind::kSE2;
    case EdgeKind::kSE3Offset:
      return a == VertexKind::kSE3 && b == VertexKind::kSE3;
    case EdgeKind::kSE2Prior:
    case EdgeKind::kSE2PositionPrior:
      return a == VertexKind::kSE2 && b == a;
    case EdgeKind::kSE3Prior:
    case EdgeKind::kSE3PositionPrior:
      return a == VertexKind::kSE3 && b == a;
    case EdgeKind::kPoint2Prior:
      return a == VertexKind::kPoint2 && b == a;
    case EdgeKind::kPoint3Prior:
      return a == VertexKind::kPoint3 && b == a;
    case EdgeKind::kPoint2Point2:
      return a == VertexKind::kPoint2 && b == a;
    case EdgeKind::kPoint3Point3:
      return a == VertexKind::kPoint3 && b == a;
    case EdgeKind::kSE2Point2Offset:
    case EdgeKind::kSE2Bearing:
      return a == VertexKind::kSE2 && b == VertexKind::kPoint2;
  }
  return false;
}

}  // namespace boxplus::io
