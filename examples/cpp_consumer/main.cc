// Averages noisy observations of a rigid transform with boxplus, from a
// project that found boxplus with find_package(boxplus). Exits non-zero if the
// estimate is not the closed-form mean (the position average).
#include <cstdio>
#include <random>

#include <boxplus/boxplus.h>

int main() {
  using namespace boxplus;
  const SE3 truth(SO3::Exp(Eigen::Vector3d(0.1, -0.4, 0.8)), Eigen::Vector3d(1, 2, 3));
  std::mt19937 rng(0);
  std::normal_distribution<double> noise(0.0, 0.05);

  Problem problem;
  const SE3 start;
  const int x = problem.AddVariable(MakeManifold("SE3"), start.data(), "cam_from_world");
  Eigen::Vector3d mean_pos = Eigen::Vector3d::Zero();
  const int n = 50;
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix<double, 6, 1> d;
    for (int k = 0; k < 6; ++k) d[k] = noise(rng);
    const SE3 z = truth.boxplus(d);
    mean_pos += z.pos() / n;
    problem.AddMeasurement(
        PriorFunctor<SE3Ops>::Create(z.ambient(), Eigen::Matrix<double, 6, 6>::Identity() / 0.05),
        {x});
  }
  const SolveSummary summary = problem.Solve();
  const SE3 est = SE3::FromAmbient(problem.value(x));
  std::printf("boxplus %s: %s after %d iterations, cost %.6g\n", BOXPLUS_VERSION_STRING,
              summary.termination.c_str(), summary.iterations, summary.final_cost);
  std::printf("position %.4f %.4f %.4f (mean of observations %.4f %.4f %.4f)\n", est.pos()[0],
              est.pos()[1], est.pos()[2], mean_pos[0], mean_pos[1], mean_pos[2]);
  std::printf("rotation error vs truth: %.4f rad\n",
              est.rotation().boxminus(truth.rotation()).norm());
  const double pos_error = (est.pos() - mean_pos).norm();
  std::printf("|position - mean of observations| = %.2e\n", pos_error);
  // LM damping leaves a tiny bias after the last accepted step.
  return pos_error < 1e-6 && summary.usable ? 0 : 1;
}
