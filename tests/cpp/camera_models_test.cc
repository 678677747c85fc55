// The camera models of factors/camera/models.h against each other where they
// coincide, and Kannala–Brandt's optical-axis branch under ceres::Jet (its
// value and derivatives equal the limit of the general formula).
#include <gtest/gtest.h>

#include <ceres/jet.h>

#include "boxplus/factors/camera/models.h"

namespace boxplus {
namespace {

using camera::DoubleSphere;
using camera::KannalaBrandt;
using camera::OpenCV5;
using camera::Pinhole;
using camera::Rational;

const double kPoints[][3] = {{0.1, -0.2, 1.0}, {-0.4, 0.3, 0.8}, {0.7, 0.5, 1.5}, {0.0, 0.0, 2.0}};

TEST(CameraModels, RationalWithoutDenominatorIsOpenCV5) {
  const double k5[9] = {510, 505, 320, 240, -0.25, 0.05, 0.001, -0.002, 0.01};
  const double k8[12] = {510, 505, 320, 240, -0.25, 0.05, 0.001, -0.002, 0.01, 0, 0, 0};
  for (const auto& p : kPoints) {
    double a[2], b[2];
    OpenCV5::ProjectPoint(k5, p, a);
    Rational::ProjectPoint(k8, p, b);
    EXPECT_DOUBLE_EQ(a[0], b[0]);
    EXPECT_DOUBLE_EQ(a[1], b[1]);
  }
  // k4 divides like k1 multiplies: 1 / (1 + k4 r²) against the ratio's value
  const double k8b[12] = {510, 505, 320, 240, 0, 0, 0, 0, 0, 0.3, 0, 0};
  const double p[3] = {0.3, -0.4, 1.0};  // r² = 0.25
  double uv[2];
  Rational::ProjectPoint(k8b, p, uv);
  EXPECT_NEAR(uv[0], 510 * 0.3 / (1 + 0.3 * 0.25) + 320, 1e-12);
}

TEST(CameraModels, DoubleSphereWithZeroXiAlphaIsPinhole) {
  const double kp[4] = {510, 505, 320, 240};
  const double kd[6] = {510, 505, 320, 240, 0, 0};
  for (const auto& p : kPoints) {
    double a[2], b[2];
    Pinhole::ProjectPoint(kp, p, a);
    DoubleSphere::ProjectPoint(kd, p, b);
    EXPECT_NEAR(a[0], b[0], 1e-12);
    EXPECT_NEAR(a[1], b[1], 1e-12);
  }
}

TEST(CameraModels, KannalaBrandtAxisBranchUnderJets) {
  using J = ceres::Jet<double, 3>;
  const double k[8] = {300, 302, 321, 242, 0.02, -0.01, 0.004, -0.001};
  J kj[8];
  for (int i = 0; i < 8; ++i) kj[i] = J(k[i]);
  // derivatives w.r.t. the point at the axis and just off it agree
  for (const double off : {0.0, 1e-7}) {
    J p[3] = {J(off, 0), J(0.0, 1), J(2.0, 2)};
    J uv[2];
    KannalaBrandt::ProjectPoint(kj, p, uv);
    EXPECT_NEAR(uv[0].a, 321 + 300 * off / 2.0, 1e-9);
    EXPECT_NEAR(uv[0].v[0], 300 / 2.0, 1e-6) << off;  // ∂u/∂X = fx / Z on the axis
    EXPECT_NEAR(uv[1].v[1], 302 / 2.0, 1e-6) << off;
    EXPECT_NEAR(uv[0].v[2], 0.0, 1e-5) << off;  // ∂u/∂Z = −fx X / Z² = 0 at X = 0
  }
  // equidistant (k = 0): θ_d = θ, so a point 45° off the axis lands fx·π/4 away
  const double k0[8] = {300, 302, 321, 242, 0, 0, 0, 0};
  const double p45[3] = {1.0, 0.0, 1.0};
  double uv[2];
  KannalaBrandt::ProjectPoint(k0, p45, uv);
  EXPECT_NEAR(uv[0], 321 + 300 * kPi / 4, 1e-9);
}

}  // namespace
}  // namespace boxplus
