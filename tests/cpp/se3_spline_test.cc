// The R³ × SO(3) spline (se3_spline.h) against closed forms and central
// differences, and the spline terms (spline_terms.h) at the truth.
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "boxplus/boxplus.h"
#include "boxplus/factors/imu/se3_spline.h"
#include "boxplus/factors/imu/spline_terms.h"

namespace boxplus {
namespace {

using Knot = Eigen::Matrix<double, 7, 1>;

Knot MakeKnot(const Eigen::Vector3d& p, const SO3& R) {
  Knot k;
  k.head<3>() = p;
  k.tail<4>() = R.ambient();
  return k;
}

struct Sample {
  Eigen::Vector3d p, v, a, w, alpha;
  SO3 R;
};

Sample Eval(const std::vector<Knot>& k, double u, double dt) {
  const double* knots[4] = {k[0].data(), k[1].data(), k[2].data(), k[3].data()};
  Sample s;
  double q[4];
  spline::Evaluate(knots, u, dt, s.p.data(), q, s.v.data(), s.a.data(), s.w.data(), s.alpha.data());
  s.R = SO3::FromAmbient(q);
  return s;
}

std::vector<Knot> RandomKnots(std::mt19937& rng) {
  std::normal_distribution<double> g;
  std::vector<Knot> k;
  for (int j = 0; j < 4; ++j) {
    k.push_back(MakeKnot(Eigen::Vector3d(g(rng), g(rng), g(rng)),
                         SO3::Exp(0.6 * Eigen::Vector3d(g(rng), g(rng), g(rng)))));
  }
  return k;
}

// v, a and ω are the derivatives of p and R: central differences in time.
// The Jacobian of a cost's residuals in its last block, a scalar, by autodiff and by a
// central difference of step h: (analytic, numeric).
template <int kRows>
std::pair<Eigen::Matrix<double, kRows, 1>, Eigen::Matrix<double, kRows, 1>> LastScalarJacobian(
    const ceres::CostFunction& f, std::vector<const double*> blocks, double h) {
  Eigen::Matrix<double, kRows, 1> J, r, r_plus, r_minus;
  std::vector<double*> jacobians(blocks.size(), nullptr);
  jacobians.back() = J.data();
  EXPECT_TRUE(f.Evaluate(blocks.data(), r.data(), jacobians.data()));
  const double x = *blocks.back(), plus = x + h, minus = x - h;
  blocks.back() = &plus;
  EXPECT_TRUE(f.Evaluate(blocks.data(), r_plus.data(), nullptr));
  blocks.back() = &minus;
  EXPECT_TRUE(f.Evaluate(blocks.data(), r_minus.data(), nullptr));
  return {J, (r_plus - r_minus) / (2 * h)};
}

TEST(Se3Spline, DerivativesMatchCentralDifferences) {
  std::mt19937 rng(5);
  const double dt = 0.1, h = 1e-5;
  for (int trial = 0; trial < 20; ++trial) {
    const std::vector<Knot> k = RandomKnots(rng);
    for (double u : {0.0, 0.3, 0.77, 1.0}) {
      const Sample s = Eval(k, u, dt), sp = Eval(k, u + h, dt), sm = Eval(k, u - h, dt);
      const Eigen::Vector3d v = (sp.p - sm.p) / (2 * h * dt);
      const Eigen::Vector3d a = (sp.v - sm.v) / (2 * h * dt);
      // body rate: Log(R(t)ᵀ R(t + τ)) / τ
      const Eigen::Vector3d w = (sm.R.inverse() * sp.R).Log() / (2 * h * dt);
      const Eigen::Vector3d alpha = (sp.w - sm.w) / (2 * h * dt);
      EXPECT_LT((alpha - s.alpha).norm(), 1e-5 * (1 + s.alpha.norm())) << trial << " u " << u;
      EXPECT_LT((v - s.v).norm(), 1e-6 * (1 + s.v.norm())) << trial << " u " << u;
      EXPECT_LT((a - s.a).norm(), 1e-5 * (1 + s.a.norm())) << trial << " u " << u;
      EXPECT_LT((w - s.w).norm(), 1e-6 * (1 + s.w.norm())) << trial << " u " << u;
      EXPECT_NEAR(s.R.ambient().norm(), 1.0, 1e-12);
    }
  }
}

// Control points on a constant-rate rotation and a quadratic path: the spline
// is the rotation R_i Exp((1 + u) d) at rate d/Δt and the parabola (i+1+u)² + 1/3
// per axis (B-splines reproduce polynomials up to degree 3 up to a constant
// for degree 2), with acceleration 2 c / Δt² exactly.
TEST(Se3Spline, ReproducesConstantRatesAndParabolas) {
  const double dt = 0.05;
  const Eigen::Vector3d d(0.1, -0.2, 0.15), c(0.3, -0.1, 0.2);
  const SO3 R0 = SO3::Exp(Eigen::Vector3d(0.4, 0.1, -0.3));
  for (int i : {0, 3}) {
    std::vector<Knot> k;
    for (int j = 0; j < 4; ++j) {
      const double n = i + j;
      k.push_back(MakeKnot(c * n * n, R0 * SO3::Exp(n * d)));
    }
    for (double u : {0.0, 0.25, 0.5, 0.9}) {
      const Sample s = Eval(k, u, dt);
      const double n = i + 1 + u;
      EXPECT_LT((s.p - c * (n * n + 1.0 / 3.0)).norm(), 1e-12);
      EXPECT_LT((s.v - c * 2 * n / dt).norm(), 1e-9);
      EXPECT_LT((s.a - c * 2 / (dt * dt)).norm(), 1e-8);
      EXPECT_LT((s.R.inverse() * (R0 * SO3::Exp(n * d))).Log().norm(), 1e-12);
      EXPECT_LT((s.w - d / dt).norm(), 1e-12);
      EXPECT_LT(s.alpha.norm(), 1e-9);  // a constant rate
    }
  }
}

// The three terms are zero at the truth they were built from.
TEST(Se3Spline, TermsVanishAtTheTruth) {
  std::mt19937 rng(9);
  const double dt = 0.1, u = 0.42;
  std::vector<Knot> k = RandomKnots(rng);
  const Sample s = Eval(k, u, dt);
  const Eigen::Vector3d bg(0.01, -0.02, 0.005), ba(0.1, 0.05, -0.2);
  const Eigen::Vector3d g_dir = Eigen::Vector3d(0.1, 0.2, -1.0).normalized();
  std::vector<const double*> blocks = {k[0].data(), k[1].data(), k[2].data(), k[3].data()};

  auto gyro = MakeSplineGyroFactor(u, dt, s.w + bg, NoiseModel::Isotropic(3, 0.01));
  std::vector<const double*> gb = blocks;
  gb.push_back(bg.data());
  Eigen::Vector3d r3;
  ASSERT_TRUE(gyro->Evaluate(gb.data(), r3.data(), nullptr));
  EXPECT_LT(r3.norm(), 1e-9);

  const Eigen::Vector3d f = s.R.inverse() * Eigen::Vector3d(s.a - 9.81 * g_dir);
  auto accel = MakeSplineAccelFactor(u, dt, f + ba, NoiseModel::Isotropic(3, 0.1));
  std::vector<const double*> ab = blocks;
  ab.push_back(ba.data());
  ab.push_back(g_dir.data());
  ASSERT_TRUE(accel->Evaluate(ab.data(), r3.data(), nullptr));
  EXPECT_LT(r3.norm(), 1e-9);

  // With the IMU's scale and misalignment M (lower triangular, [s_x, s_y, s_z, m_yx,
  // m_zx, m_zy]): the readings M ω + b_g and M f + b_a are matched at the truth.
  const Eigen::Matrix<double, 6, 1> m_vec =
      (Eigen::Matrix<double, 6, 1>() << 1.02, 0.97, 1.01, 0.004, -0.006, 0.003).finished();
  Eigen::Matrix3d M;
  M << m_vec[0], 0, 0, m_vec[3], m_vec[1], 0, m_vec[4], m_vec[5], m_vec[2];
  auto gyro_m = MakeSplineGyroFactor(u, dt, M * s.w + bg, NoiseModel::Isotropic(3, 0.01), true);
  gb.push_back(m_vec.data());
  ASSERT_TRUE(gyro_m->Evaluate(gb.data(), r3.data(), nullptr));
  EXPECT_LT(r3.norm(), 1e-9);
  auto accel_m =
      MakeSplineAccelFactor(u, dt, M * f + ba, NoiseModel::Isotropic(3, 0.1), 9.81, true);
  ab.push_back(m_vec.data());
  ASSERT_TRUE(accel_m->Evaluate(ab.data(), r3.data(), nullptr));
  EXPECT_LT(r3.norm(), 1e-9);
  // The size effect: the y and z sensing elements 1–2 cm from the x element each read
  // their own point's specific force (a second difference of its position), through M.
  const Eigen::Matrix<double, 6, 1> size =
      (Eigen::Matrix<double, 6, 1>() << 0.01, -0.005, 0.002, -0.004, 0.012, 0.02).finished();
  const double h = 1e-4;
  auto element_force = [&](const Eigen::Vector3d& arm) {
    auto where = [&](double uu) {
      const Sample e = Eval(k, uu, dt);
      return Eigen::Vector3d(e.p + e.R * arm);
    };
    const Eigen::Vector3d acc = (where(u + h) - 2 * where(u) + where(u - h)) / (h * h * dt * dt);
    return Eigen::Vector3d(s.R.inverse() * Eigen::Vector3d(acc - 9.81 * g_dir));
  };
  const Eigen::Vector3d f_sized(f.x(), element_force(size.head<3>()).y(),
                                element_force(size.tail<3>()).z());
  EXPECT_GT((f_sized - f).norm(), 0.05);  // the effect shows, far above the tolerance below
  auto accel_s = MakeSplineAccelFactor(u, dt, M * f_sized + ba, NoiseModel::Isotropic(3, 0.1), 9.81,
                                       true, true);
  ab.push_back(size.data());
  ASSERT_TRUE(accel_s->Evaluate(ab.data(), r3.data(), nullptr));
  EXPECT_LT(r3.norm(), 1e-3);  // the second difference's error (≈ 1e-6 m/s²) over σ = 0.1
  EXPECT_THROW(MakeSplineAccelFactor(u, dt, f, NoiseModel::Isotropic(3, 0.1), 9.81, false, true),
               Error);

  // with the identity M the prediction is the plain ω + b_g: r = W (ω − M ω), W = 1/0.01
  const Eigen::Matrix<double, 6, 1> identity =
      (Eigen::Matrix<double, 6, 1>() << 1, 1, 1, 0, 0, 0).finished();
  gb.back() = identity.data();
  ASSERT_TRUE(gyro_m->Evaluate(gb.data(), r3.data(), nullptr));
  EXPECT_LT((r3 - 100.0 * (s.w - M * s.w)).norm(), 1e-9);

  // A camera 3 cm from the IMU, a time offset of 4 ms: the pixel of a point seen
  // at camera time t_c is the projection at IMU time t_c + d.
  const SE3 imu_from_cam(SO3::Exp(Eigen::Vector3d(0.01, 0.02, 1.5)),
                         Eigen::Vector3d(0.03, 0, 0.01));
  const double d = 0.004;
  const Sample at = Eval(k, u + d / dt, dt);
  const SE3 world_from_cam = SE3(at.R, at.p) * imu_from_cam;
  const Eigen::Vector3d p_world = world_from_cam * Eigen::Vector3d(0.1, -0.05, 1.2);
  const Eigen::Vector4d K(500, 500, 320, 240);
  const Eigen::Vector3d pc = world_from_cam.inverse() * p_world;
  const Eigen::Vector2d uv(500 * pc.x() / pc.z() + 320, 500 * pc.y() / pc.z() + 240);
  auto proj = MakeSplineReprojectionFactor("pinhole", u * dt, dt, uv, NoiseModel::Isotropic(2, 0.5),
                                           p_world);
  std::vector<const double*> pb = blocks;
  const Knot ic = imu_from_cam.ambient();
  pb.push_back(ic.data());
  pb.push_back(&d);
  pb.push_back(K.data());
  Eigen::Vector2d r2;
  ASSERT_TRUE(proj->Evaluate(pb.data(), r2.data(), nullptr));
  EXPECT_LT(r2.norm(), 1e-7);

  // A rolling shutter with a line delay of 30 µs per row: the corner at row v was read
  // out at camera time t_c + ℓ v, so its pixel is the projection at t_c + d + ℓ v
  // (found by fixed-point iteration on the row, as a camera reading rows would).
  const double ell = 30e-6;
  Eigen::Vector2d uv_rs = uv;
  for (int it = 0; it < 60; ++it) {
    const Sample s_rs = Eval(k, u + (d + ell * uv_rs.y()) / dt, dt);
    const Eigen::Vector3d q = (SE3(s_rs.R, s_rs.p) * imu_from_cam).inverse() * p_world;
    uv_rs = Eigen::Vector2d(500 * q.x() / q.z() + 320, 500 * q.y() / q.z() + 240);
  }
  EXPECT_GT((uv_rs - uv).norm(), 0.05);  // the motion during the readout shows
  auto rs = MakeSplineReprojectionFactor("pinhole", u * dt, dt, uv_rs,
                                         NoiseModel::Isotropic(2, 0.5), p_world, true);
  std::vector<const double*> rb = pb;
  rb.push_back(&ell);
  ASSERT_TRUE(rs->Evaluate(rb.data(), r2.data(), nullptr));
  EXPECT_LT(r2.norm(), 1e-7);
  // its Jacobian in the line delay against a central difference
  const auto [J_ell, numeric_ell] = LastScalarJacobian<2>(*rs, rb, 1e-8);
  EXPECT_LT((J_ell - numeric_ell).norm(), 1e-4 * J_ell.norm() + 1e-6);
  EXPECT_GT(J_ell.norm(), 1.0);
}

// Another IMU 8 cm off the body's origin, turned: its gyroscope reads the body
// rate in its own axes, its accelerometer the second derivative of its own
// position (a central difference here) minus gravity, in its own axes.
TEST(Se3Spline, AnotherImuFeelsItsLeverArm) {
  std::mt19937 rng(13);
  const double dt = 0.1, u = 0.37, h = 1e-4;
  const std::vector<Knot> k = RandomKnots(rng);
  const SE3 body_from_imu(SO3::Exp(Eigen::Vector3d(0.3, -1.2, 0.5)),
                          Eigen::Vector3d(0.08, -0.03, 0.05));
  const Eigen::Vector3d g_dir = Eigen::Vector3d(0.1, 0.2, -1.0).normalized();
  auto where = [&](double uu) {
    const Sample s = Eval(k, uu, dt);
    return Eigen::Vector3d(s.p + s.R * body_from_imu.pos());
  };
  const Sample s = Eval(k, u, dt);
  const Eigen::Vector3d a_k = (where(u + h) - 2 * where(u) + where(u - h)) / (h * h * dt * dt);
  const Eigen::Matrix3d R_k = body_from_imu.rotation().matrix();
  const Eigen::Vector3d f_k =
      R_k.transpose() * (s.R.inverse() * Eigen::Vector3d(a_k - 9.81 * g_dir));
  const Eigen::Vector3d w_k = R_k.transpose() * s.w;
  // the lever arm matters here: without it the reading would differ by this much
  const Eigen::Vector3d body_f =
      R_k.transpose() * (s.R.inverse() * Eigen::Vector3d(s.a - 9.81 * g_dir));
  EXPECT_GT((f_k - body_f).norm(), 0.01);

  const Eigen::Vector3d bg(0.01, -0.02, 0.03), ba(0.1, 0.05, -0.2);
  const Knot pose = body_from_imu.ambient();
  std::vector<const double*> blocks = {k[0].data(), k[1].data(), k[2].data(), k[3].data(),
                                       pose.data()};
  auto gyro = MakeSplineOffsetGyroFactor(u, dt, w_k + bg, NoiseModel::Isotropic(3, 1.0));
  std::vector<const double*> gb = blocks;
  gb.push_back(bg.data());
  Eigen::Vector3d r;
  ASSERT_TRUE(gyro->Evaluate(gb.data(), r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-12);
  auto accel = MakeSplineOffsetAccelFactor(u, dt, f_k + ba, NoiseModel::Isotropic(3, 1.0));
  std::vector<const double*> ab = blocks;
  ab.push_back(ba.data());
  ab.push_back(g_dir.data());
  ASSERT_TRUE(accel->Evaluate(ab.data(), r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-4 * (1 + f_k.norm()));

  // Its clock 7 ms behind: the sample stamped at u − d/Δt on its own clock, read with the
  // time-offset block d (u computed with the guess d0 = 5 ms), is the same reading; the
  // Jacobian in d equals a central difference.
  const double d = 0.007, d0 = 0.005;
  const double u_own = u - d / dt;  // where its stamp alone would put it
  const double u0 = u_own + d0 / dt;
  for (const bool is_gyro : {true, false}) {
    auto f = is_gyro ? MakeSplineOffsetGyroFactor(u0, dt, w_k + bg, NoiseModel::Isotropic(3, 1.0),
                                                  true, d0)
                     : MakeSplineOffsetAccelFactor(u0, dt, f_k + ba, NoiseModel::Isotropic(3, 1.0),
                                                   9.81, true, d0);
    std::vector<const double*> db = is_gyro ? gb : ab;
    db.push_back(&d);
    ASSERT_TRUE(f->Evaluate(db.data(), r.data(), nullptr));
    EXPECT_LT(r.norm(), 1e-4 * (1 + f_k.norm())) << (is_gyro ? "gyro" : "accel");
    const auto [J_d, numeric_d] = LastScalarJacobian<3>(*f, db, 1e-7);
    EXPECT_LT((J_d - numeric_d).norm(), 1e-4 * J_d.norm() + 1e-6);
    EXPECT_GT(J_d.norm(), 0.1);
  }

  // Its own scale and misalignment M (the block after d): it reads M x + b in its own
  // axes, alone and with the time offset.
  const Eigen::Matrix<double, 6, 1> m =
      (Eigen::Matrix<double, 6, 1>() << 1.02, 0.97, 1.01, 0.004, -0.006, 0.003).finished();
  Eigen::Matrix3d M;
  M << m[0], 0, 0, m[3], m[1], 0, m[4], m[5], m[2];
  for (const bool with_offset : {false, true}) {
    for (const bool is_gyro : {true, false}) {
      const Eigen::Vector3d z =
          is_gyro ? Eigen::Vector3d(M * w_k + bg) : Eigen::Vector3d(M * f_k + ba);
      auto f =
          is_gyro ? MakeSplineOffsetGyroFactor(with_offset ? u0 : u, dt, z,
                                               NoiseModel::Isotropic(3, 1.0), with_offset, d0, true)
                  : MakeSplineOffsetAccelFactor(with_offset ? u0 : u, dt, z,
                                                NoiseModel::Isotropic(3, 1.0), 9.81, with_offset,
                                                d0, true);
      std::vector<const double*> mb = is_gyro ? gb : ab;
      if (with_offset) mb.push_back(&d);
      mb.push_back(m.data());
      ASSERT_EQ(f->parameter_block_sizes().back(), 6);
      ASSERT_TRUE(f->Evaluate(mb.data(), r.data(), nullptr));
      EXPECT_LT(r.norm(), 1e-4 * (1 + f_k.norm())) << is_gyro << with_offset;
      // without M the same reading is off by (M − I) x
      auto plain =
          is_gyro
              ? MakeSplineOffsetGyroFactor(with_offset ? u0 : u, dt, z,
                                           NoiseModel::Isotropic(3, 1.0), with_offset, d0)
              : MakeSplineOffsetAccelFactor(with_offset ? u0 : u, dt, z,
                                            NoiseModel::Isotropic(3, 1.0), 9.81, with_offset, d0);
      mb.pop_back();
      ASSERT_TRUE(plain->Evaluate(mb.data(), r.data(), nullptr));
      EXPECT_GT(r.norm(), 1e-3);
    }
  }
}

}  // namespace
}  // namespace boxplus
