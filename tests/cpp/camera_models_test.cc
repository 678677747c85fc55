// The camera models of factors/camera/models.h against each other where they
// coincide, and Kannala–Brandt's optical-axis branch under ceres::Jet (its
// value and derivatives equal the limit of the general formula).
#include <gtest/gtest.h>

#include <ceres/jet.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "boxplus/errors.h"
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

// Every model's Unproject inverts its ProjectPoint: the ray of a projected point
// projects back to the same pixel (1e-7 px) and points the same way, on lenses like
// the ones calibrated in the tests (OpenCV's sample, a 180° fisheye, a double sphere
// of ξ = −0.18), out to 80° off axis for the wide models; names and numbers agree.
TEST(CameraModels, UnprojectInvertsProjectForEveryModel) {
  const std::map<std::string, std::vector<double>> lenses = {
      {"simple_radial", {500, 320, 240, -0.2}},
      {"pinhole", {500, 505, 320, 240}},
      {"radial1", {500, 505, 320, 240, -0.2}},
      {"radial2", {500, 505, 320, 240, -0.25, 0.08}},
      {"opencv5", {533, 533, 342, 235, -0.287, 0.081, 0.0011, -0.0001, 0.032}},
      {"rational", {533, 533, 342, 235, -0.2, 0.05, 0.001, -0.002, 0.01, 0.1, 0.01, 0.0}},
      {"kannala_brandt", {300, 300, 320, 240, 0.05, -0.01, 0.002, -0.0005}},
      {"double_sphere", {300, 300, 320, 240, -0.18, 0.59}}};
  ASSERT_EQ(lenses.size(), std::size(camera::kCameraModelNames));
  for (const auto& [name, k] : lenses) {
    const bool wide = name == "kannala_brandt" || name == "double_sphere";
    const int index = camera::CameraModelIndex(name);
    EXPECT_STREQ(camera::kCameraModelNames[index], name.c_str());
    EXPECT_EQ(CameraModelSize(name), static_cast<int>(k.size())) << name;
    for (double angle : {0.0, 0.2, 0.5, wide ? 1.4 : 0.6}) {
      for (double az : {0.3, 2.0, -2.5}) {
        const double p[3] = {std::sin(angle) * std::cos(az), std::sin(angle) * std::sin(az),
                             std::cos(angle)};
        double uv[2], ray[3], back[2];
        camera::WithCameraModelIndex(index, [&](auto m) {
          decltype(m)::ProjectPoint(k.data(), p, uv);
          decltype(m)::Unproject(k.data(), uv, ray);
          decltype(m)::ProjectPoint(k.data(), ray, back);
        });
        EXPECT_NEAR(back[0], uv[0], 1e-7) << name << " at " << angle;
        EXPECT_NEAR(back[1], uv[1], 1e-7) << name << " at " << angle;
        const double n = std::sqrt(ray[0] * ray[0] + ray[1] * ray[1] + ray[2] * ray[2]);
        EXPECT_NEAR(ray[2] / n, p[2], 1e-9) << name << " at " << angle;
      }
    }
  }
  EXPECT_THROW(camera::CameraModelIndex("fisheye"), Error);
  EXPECT_THROW(camera::WithCameraModelIndex(8, [](auto m) { return decltype(m)::kSize; }), Error);
}

}  // namespace
}  // namespace boxplus
