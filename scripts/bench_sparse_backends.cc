// What leaving SuiteSparse's GPL modules out of a binary wheel would cost:
// a 3D pose graph solved by Ceres' Levenberg–Marquardt with
// SPARSE_NORMAL_CHOLESKY on SuiteSparse (CHOLMOD, supernodal where it pays)
// and on Eigen (simplicial LDLᵀ, MPL-2.0), the fallback of a wheel without
// CHOLMOD's Supernodal module. Same problem, same start, same iterations.
//
//   g++ -O2 -std=c++17 -I/usr/include/eigen3 scripts/bench_sparse_backends.cc \
//       -lceres -lglog -o build/bench_sparse_backends
//   OPENBLAS_NUM_THREADS=1 build/bench_sparse_backends FILE.g2o
//
// FILE: a 3D g2o file (VERTEX_SE3:QUAT / EDGE_SE3:QUAT), e.g. one written by
// `python -m boxplus.slam.generate --family sphere -n 2500 -o sphere.g2o`.
// Residual: g2o's [t(Δ), 2·vec(q(Δ))] whitened by the edge's √Ω, Δ = z⁻¹ xᵢ⁻¹ xⱼ.
#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct Pose {
  double p[3];
  double q[4];  // x, y, z, w (Eigen's coeffs(), EigenQuaternionManifold)
};

struct Edge {
  int a, b;
  Eigen::Vector3d t;
  Eigen::Quaterniond q;
  Eigen::Matrix<double, 6, 6> sqrt_info;
};

struct RelativePose {
  Edge e;
  template <class T>
  bool operator()(const T* pa, const T* qa, const T* pb, const T* qb, T* r) const {
    Eigen::Map<const Eigen::Matrix<T, 3, 1>> ta(pa), tb(pb);
    Eigen::Map<const Eigen::Quaternion<T>> Ra(qa), Rb(qb);
    const Eigen::Quaternion<T> Rab = Ra.conjugate() * Rb;
    const Eigen::Matrix<T, 3, 1> tab = Ra.conjugate() * (tb - ta);
    const Eigen::Quaternion<T> zinv = e.q.template cast<T>().conjugate();
    Eigen::Quaternion<T> dq = zinv * Rab;
    const Eigen::Matrix<T, 3, 1> dt = zinv * (tab - e.t.template cast<T>());
    if (dq.w() < T(0)) dq.coeffs() = -dq.coeffs();
    Eigen::Matrix<T, 6, 1> err;
    err << dt, T(2) * dq.vec();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> residual(r);
    residual = e.sqrt_info.template cast<T>() * err;
    return true;
  }
};

bool Read(const std::string& path, std::map<int, Pose>* poses, std::vector<Edge>* edges) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "VERTEX_SE3:QUAT") {
      int id;
      Pose p;
      s >> id >> p.p[0] >> p.p[1] >> p.p[2] >> p.q[0] >> p.q[1] >> p.q[2] >> p.q[3];
      (*poses)[id] = p;
    } else if (tag == "EDGE_SE3:QUAT") {
      Edge e;
      double q[4];
      s >> e.a >> e.b >> e.t[0] >> e.t[1] >> e.t[2] >> q[0] >> q[1] >> q[2] >> q[3];
      e.q = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized();
      Eigen::Matrix<double, 6, 6> info;
      for (int i = 0; i < 6; ++i)
        for (int j = i; j < 6; ++j) {
          s >> info(i, j);
          info(j, i) = info(i, j);
        }
      e.sqrt_info = info.llt().matrixL().transpose();
      edges->push_back(e);
    }
  }
  return !poses->empty() && !edges->empty();
}

double Solve(std::map<int, Pose> poses, const std::vector<Edge>& edges,
             ceres::SparseLinearAlgebraLibraryType library, ceres::Solver::Summary* summary) {
  ceres::Problem problem;
  auto* quaternion = new ceres::EigenQuaternionManifold;
  for (const Edge& e : edges) {
    auto* cost = new ceres::AutoDiffCostFunction<RelativePose, 6, 3, 4, 3, 4>(new RelativePose{e});
    problem.AddResidualBlock(cost, nullptr, poses[e.a].p, poses[e.a].q, poses[e.b].p, poses[e.b].q);
  }
  for (auto& [id, p] : poses) {
    if (problem.HasParameterBlock(p.q)) problem.SetManifold(p.q, quaternion);
  }
  Pose& gauge = poses.begin()->second;
  problem.SetParameterBlockConstant(gauge.p);
  problem.SetParameterBlockConstant(gauge.q);
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  o.sparse_linear_algebra_library_type = library;
  o.max_num_iterations = 100;
  o.num_threads = 1;
  ceres::Solve(o, &problem, summary);
  return summary->total_time_in_seconds;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s FILE.g2o (3D)\n", argv[0]);
    return 2;
  }
  std::map<int, Pose> poses;
  std::vector<Edge> edges;
  if (!Read(argv[1], &poses, &edges)) {
    std::fprintf(stderr, "%s: no VERTEX_SE3:QUAT / EDGE_SE3:QUAT lines\n", argv[1]);
    return 1;
  }
  std::printf("%s: %zu poses, %zu edges\n", argv[1], poses.size(), edges.size());
  for (auto lib : {ceres::SUITE_SPARSE, ceres::EIGEN_SPARSE}) {
    ceres::Solver::Summary s;
    Solve(poses, edges, lib, &s);
    std::printf("%-13s chi2 %.10g -> %.10g, %d iterations, linear solver %.3f s, total %.3f s\n",
                lib == ceres::SUITE_SPARSE ? "SUITE_SPARSE" : "EIGEN_SPARSE", 2 * s.initial_cost,
                2 * s.final_cost, static_cast<int>(s.iterations.size()) - 1,
                s.linear_solver_time_in_seconds, s.total_time_in_seconds);
  }
  return 0;
}
