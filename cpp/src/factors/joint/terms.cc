#include "boxplus/factors/joint/terms.h"

#include <cmath>
#include <iterator>

#include "boxplus/errors.h"

namespace boxplus {

namespace joint {

namespace {

// Stride of the dynamic autodiff: derivatives of 8 parameters per pass.
constexpr int kStride = 8;

struct Checker {
  const std::vector<int>& sizes;
  const std::string& what;

  void Block(int block, int size, const char* role) const {
    BOXPLUS_CHECK(block >= 0 && block < static_cast<int>(sizes.size()), what, ": ", role,
                  " block index ", block, " out of range (", sizes.size(), " blocks)");
    BOXPLUS_CHECK(sizes[block] == size, what, ": ", role, " must have ", size,
                  " numbers, its variable has ", sizes[block]);
  }
  void OptionalBlock(int block, int size, const char* role) const {
    if (block != kNoBlock) Block(block, size, role);
  }
  void Camera(int model, int block) const {
    BOXPLUS_CHECK(model >= 0 && model < static_cast<int>(std::size(camera::kCameraModelNames)),
                  what, ": camera model index ", model, " out of range");
    Block(block, CameraModelSize(camera::kCameraModelNames[model]), "camera intrinsics");
  }
  void Chain(const ChainSpec& c) const {
    const auto n = c.nominal.rows();
    BOXPLUS_CHECK(n >= 1 && n <= kMaxJoints && c.nominal.cols() == 4, what,
                  ": a DH table must be n × 4 with 1 ≤ n ≤ ", kMaxJoints, ", got ", n, " × ",
                  c.nominal.cols());
    BOXPLUS_CHECK(c.joints.size() == n, what, ": ", c.joints.size(), " joint readings for ", n,
                  " joints");
    BOXPLUS_CHECK(c.nominal.allFinite() && c.joints.allFinite() && c.base_from_chain.allFinite() &&
                      c.mount_value.allFinite(),
                  what, ": non-finite DH table, readings or chain ends");
    std::vector<int> seen(4 * n, 0);
    for (int u : c.unknown) {
      BOXPLUS_CHECK(u >= 0 && u < 4 * n && !seen[u]++, what, ": unknown DH entry ", u,
                    " out of range or repeated");
    }
    if (c.unknown.empty()) {
      BOXPLUS_CHECK(c.dh == kNoBlock, what, ": a dh block without unknown entries");
    } else {
      Block(c.dh, static_cast<int>(c.unknown.size()), "dh");
    }
    OptionalBlock(c.encoder, static_cast<int>(n), "encoder errors");
    OptionalBlock(c.mount, 7, "mount (SE3)");
  }
  void Point(const PointSpec& p) const {
    BOXPLUS_CHECK(p.c.allFinite() && p.uv.allFinite() && std::isfinite(p.beta), what,
                  ": non-finite datum");
    OptionalBlock(p.pose, 7, "root_from_system (SE3)");
    switch (p.kind) {
      case PointKind::kConstant:
        return;
      case PointKind::kVariable:
        return Block(p.block, 3, "point (R3)");
      case PointKind::kChain:
        return Chain(p.chain);
      case PointKind::kSheet:
        Camera(p.model, p.camera);
        return Block(p.sheet, 4, "light sheet (Plane)");
      case PointKind::kBeam:
        Camera(p.model, p.camera);
        return Block(p.sheet, 7, "cam_from_laser (SE3)");
    }
  }
  void Surface(const SurfaceSpec& s) const {
    OptionalBlock(s.pose, 7, "root_from_owner (SE3)");
    switch (s.kind) {
      case SurfaceKind::kPlane:
        return Block(s.block, 4, "plane");
      case SurfaceKind::kLine:
        return Block(s.block, 6, "line");
      case SurfaceKind::kChainPlane:
        return Chain(s.chain);
    }
  }
};

}  // namespace

int TermResidualSize(TermKind kind) {
  switch (kind) {
    case TermKind::kLink:
    case TermKind::kLine:
      return 3;
    case TermKind::kProjection:
    case TermKind::kTargetProjection:
      return 2;
    default:
      return 1;
  }
}

std::shared_ptr<ceres::CostFunction> MakeJointTerm(const TermSpec& spec,
                                                   const std::vector<int>& block_sizes,
                                                   const std::string& what) {
  const Checker check{block_sizes, what};
  BOXPLUS_CHECK(!block_sizes.empty(), what, ": a term needs at least one variable");
  const int m = TermResidualSize(spec.kind);
  BOXPLUS_CHECK(spec.W.rows() == m && spec.W.cols() == m && spec.W.allFinite(), what,
                ": noise of dimension ", spec.W.rows(), " for an error of ", m);
  switch (spec.kind) {
    case TermKind::kLink:
    case TermKind::kDistance:
      check.Point(spec.a);
      check.Point(spec.b);
      break;
    case TermKind::kPlane:
      check.Point(spec.a);
      BOXPLUS_CHECK(spec.surface.kind != SurfaceKind::kLine, what, ": a plane term needs a plane");
      check.Surface(spec.surface);
      break;
    case TermKind::kLine:
      check.Point(spec.a);
      BOXPLUS_CHECK(spec.surface.kind == SurfaceKind::kLine, what, ": a line term needs a line");
      check.Surface(spec.surface);
      break;
    case TermKind::kLineAnchor:
      check.Block(spec.surface.block, 6, "line");
      break;
    case TermKind::kTargetProjection:
      BOXPLUS_CHECK(spec.a.kind == PointKind::kChain, what, ": target projections need a chain");
      BOXPLUS_CHECK(
          spec.targets.rows() >= 1 && spec.targets.cols() == 3 && spec.targets.allFinite(), what,
          ": targets must be M × 3 finite points with M ≥ 1, got ", spec.targets.rows(), " × ",
          spec.targets.cols());
      [[fallthrough]];
    case TermKind::kProjection:
      check.Point(spec.a);
      check.Camera(spec.camera.model, spec.camera.intrinsics);
      check.OptionalBlock(spec.camera.cam_from_system, 7, "cam_from_system (SE3)");
      check.OptionalBlock(spec.camera.pose, 7, "root_from_system (SE3)");
      break;
  }
  const int nz = spec.kind == TermKind::kDistance     ? 1
                 : spec.kind == TermKind::kProjection ? 2
                 : spec.kind == TermKind::kTargetProjection
                     ? 2 * static_cast<int>(spec.targets.rows())
                     : 0;
  BOXPLUS_CHECK(spec.z.size() == nz && spec.z.allFinite(), what, ": the measurement must be ", nz,
                " finite numbers, got ", spec.z.size());
  auto* cost =
      new ceres::DynamicAutoDiffCostFunction<JointTermFunctor, kStride>(new JointTermFunctor(spec));
  for (int size : block_sizes) cost->AddParameterBlock(size);
  cost->SetNumResiduals(spec.kind == TermKind::kTargetProjection ? nz : m);
  return std::shared_ptr<ceres::CostFunction>(cost);
}

}  // namespace joint

}  // namespace boxplus
