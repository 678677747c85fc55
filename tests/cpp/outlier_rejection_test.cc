// Wrong loop closures (slam/outlier_rejection.h): the χ² threshold, the GNC
// weights, and GNC on a generated two-lap trajectory against its truth and
// against the solve of the inliers alone.
#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/SparseCore>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "boxplus/slam/outlier_rejection.h"
#include "boxplus/slam/pose_graph.h"

namespace boxplus::slam {
namespace {

TEST(ChiSquaredQuantile, MatchesTables) {
  // Tabulated quantiles (e.g. scipy.stats.chi2.ppf) to the digits given.
  EXPECT_NEAR(ChiSquaredQuantile(1, 0.95), 3.841459, 1e-6);
  EXPECT_NEAR(ChiSquaredQuantile(3, 0.99), 11.344867, 1e-6);
  EXPECT_NEAR(ChiSquaredQuantile(6, 0.99), 16.811894, 1e-6);
  EXPECT_NEAR(ChiSquaredQuantile(2, 0.5), 2 * std::log(2.0), 1e-9);  // χ²(2) is exponential
  EXPECT_NEAR(ChiSquaredQuantile(6, 0.999), 22.457744, 1e-6);
  EXPECT_THROW(ChiSquaredQuantile(0, 0.9), Error);
  EXPECT_THROW(ChiSquaredQuantile(3, 1.0), Error);
}

TEST(GncWeights, TlsIsContinuousAndBinaryOutsideItsBand) {
  for (double mu : {1e-6, 0.01, 1.0, 40.0}) {
    const double lo = mu / (mu + 1), hi = (mu + 1) / mu;
    EXPECT_EQ(TlsWeight(0.5 * lo, mu), 1.0);
    EXPECT_NEAR(TlsWeight(lo * (1 + 1e-12), mu), 1.0, 1e-6) << mu;
    EXPECT_NEAR(TlsWeight(hi * (1 - 1e-12), mu), 0.0, 1e-5) << mu;
    EXPECT_EQ(TlsWeight(2 * hi, mu), 0.0);
    // Non-increasing in the residual.
    double last = 1.0;
    for (double s = 0; s < 3 * hi; s += hi / 50) {
      EXPECT_LE(TlsWeight(s, mu), last + 1e-15);
      last = TlsWeight(s, mu);
    }
  }
  EXPECT_EQ(TlsWeight(NAN, 1.0), 0.0);
  EXPECT_NEAR(GmWeight(1.0, 1.0), 0.25, 1e-15);
  EXPECT_NEAR(GmWeight(0.0, 3.0), 1.0, 1e-15);
  EXPECT_EQ(GmWeight(NAN, 1.0), 0.0);
}

TEST(OutlierMode, OneSpellingEach) {
  EXPECT_EQ(ParseOutlierMode("GNC"), OutlierMode::kTls);
  EXPECT_EQ(ParseOutlierMode("gnc_gm"), OutlierMode::kGm);
  EXPECT_EQ(ParseOutlierMode("none"), OutlierMode::kOff);
  EXPECT_EQ(OutlierModeName(OutlierMode::kAuto), "auto");
  EXPECT_THAT([] { ParseOutlierMode("dcs"); },
              ::testing::ThrowsMessage<Error>(::testing::HasSubstr("gnc-tls")));
}

// A linear least-squares problem of blocks (3 rows, 2 of 8 variables of 2
// columns each): the innovation χ² of a block outside the estimate is the
// rise of the minimum when it joins, and the deletion χ² of one in it the
// drop when it leaves, solved densely, on random draws.
TEST(InnovationChi2, IsTheRiseOfTheMinimumWhenTheBlockJoinsAndDeletionItsDrop) {
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  constexpr int kBlocks = 24, kVars = 8, kRows = 3, kCols = 2 * kVars;
  for (int draw = 0; draw < 20; ++draw) {
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(kBlocks * kRows, kCols);
    Eigen::VectorXd b(kBlocks * kRows);
    std::vector<int> offsets;
    for (int k = 0; k < kBlocks; ++k) {
      offsets.push_back(k * kRows);
      // A chain first (every variable determined), then random pairs.
      const int u = k < kVars ? std::max(k - 1, 0) : static_cast<int>(rng() % kVars);
      const int v = k < kVars ? k : static_cast<int>((u + 1 + rng() % (kVars - 1)) % kVars);
      for (int r = 0; r < kRows; ++r) {
        for (int c = 0; c < 2; ++c) {
          J(k * kRows + r, 2 * u + c) += normal(rng);
          J(k * kRows + r, 2 * v + c) += normal(rng);
        }
        b[k * kRows + r] = 3 * normal(rng);
      }
    }
    offsets.push_back(kBlocks * kRows);
    std::vector<char> in(kBlocks, 1);
    std::vector<int> tested;
    for (int k = kVars; k < kBlocks; k += 2) {
      in[k] = 0;
      tested.push_back(k);
    }
    auto rows_of = [&](const std::vector<char>& use) {
      Eigen::VectorXd w = Eigen::VectorXd::Zero(kBlocks * kRows);
      for (int k = 0; k < kBlocks; ++k) {
        if (use[k]) w.segment(k * kRows, kRows).setOnes();
      }
      return w;
    };
    // min Σ_{use} ‖J x − b‖², and its x.
    auto minimum = [&](const std::vector<char>& use, Eigen::VectorXd* x) {
      const Eigen::VectorXd w = rows_of(use);
      const Eigen::MatrixXd A = w.asDiagonal() * J;
      *x = (A.transpose() * A).ldlt().solve(A.transpose() * (w.asDiagonal() * b));
      return (w.asDiagonal() * (J * *x - b)).squaredNorm();
    };
    Eigen::VectorXd x;
    const double base = minimum(in, &x);
    const Eigen::VectorXd r = J * x - b;
    const std::vector<double> chi2 = InnovationChi2(J.sparseView(), r, offsets, in, tested);
    ASSERT_EQ(chi2.size(), tested.size());
    for (size_t i = 0; i < tested.size(); ++i) {
      std::vector<char> joined = in;
      joined[tested[i]] = 1;
      Eigen::VectorXd y;
      const double rise = minimum(joined, &y) - base;
      EXPECT_NEAR(chi2[i], rise, 1e-9 * std::max(1.0, rise)) << draw << " " << tested[i];
      EXPECT_LE(chi2[i], r.segment(tested[i] * kRows, kRows).squaredNorm() * (1 + 1e-12));
    }
    // A block in the estimate: the drop of the minimum when it leaves.
    std::vector<int> kept;
    for (int k = kVars; k < kBlocks; ++k) {
      if (in[k]) kept.push_back(k);
    }
    const std::vector<double> drop = DeletionChi2(J.sparseView(), r, offsets, in, kept);
    for (size_t i = 0; i < kept.size(); ++i) {
      std::vector<char> left = in;
      left[kept[i]] = 0;
      Eigen::VectorXd y;
      const double fall = base - minimum(left, &y);
      EXPECT_NEAR(drop[i], fall, 1e-9 * std::max(1.0, fall)) << draw << " " << kept[i];
      EXPECT_GE(drop[i], r.segment(kept[i] * kRows, kRows).squaredNorm() * (1 - 1e-12));
    }
  }
  // Blocks not outside the estimate, or offsets that do not fit, are refused.
  const Eigen::SparseMatrix<double> J = Eigen::MatrixXd::Identity(3, 3).sparseView();
  EXPECT_THROW(InnovationChi2(J, Eigen::VectorXd::Zero(3), {0, 3}, {1}, {0}), Error);
  EXPECT_THROW(InnovationChi2(J, Eigen::VectorXd::Zero(3), {0, 2}, {0}, {0}), Error);
  EXPECT_THROW(DeletionChi2(J, Eigen::VectorXd::Zero(3), {0, 3}, {0}, {0}), Error);
}

// A 3D chain of n poses (vertex 0 held by the gauge) with random closures,
// linearised away from any optimum: InnovationChi2Floor is a lower bound of
// the innovation χ² of every closure outside the estimate and
// DeletionChi2Ceiling an upper bound of the drop of every one in it; both
// are exact where the chain is all the estimate knows of the closure's ends,
// whichever two poses they are (the gauge's vertex need not be one).
TEST(PathBounds, BoundTheInnovationAndTheDropAndAreExactOnAChain) {
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  constexpr int n = 40;
  auto pose = [&](double spread) {
    Eigen::Matrix<double, 7, 1> x;
    const Eigen::Quaterniond q =
        Eigen::Quaterniond(Eigen::AngleAxisd(spread * normal(rng), Eigen::Vector3d::UnitX()) *
                           Eigen::AngleAxisd(spread * normal(rng), Eigen::Vector3d::UnitY()) *
                           Eigen::AngleAxisd(spread * normal(rng), Eigen::Vector3d::UnitZ()));
    x << spread * normal(rng), spread * normal(rng), spread * normal(rng), q.x(), q.y(), q.z(),
        q.w();
    return Eigen::VectorXd(x);
  };
  for (int draw = 0; draw < 4; ++draw) {
    io::Graph g;
    g.dimension = 3;
    for (int i = 0; i < n; ++i) {
      io::Vertex v;
      v.id = i;
      v.kind = io::VertexKind::kSE3;
      v.estimate = pose(1.0);
      g.AddVertex(v);
    }
    Eigen::Matrix<double, 6, 6> info = Eigen::Matrix<double, 6, 6>::Identity();
    info.diagonal() << 50, 80, 20, 400, 900, 300;
    info(0, 1) = info(1, 0) = 10;
    auto add = [&](int a, int b) {
      io::Edge e;
      e.kind = io::EdgeKind::kSE3;
      e.from = a;
      e.to = b;
      e.measurement = pose(0.5);
      e.information = info;
      g.AddEdge(e);
    };
    for (int i = 0; i + 1 < n; ++i) add(i, i + 1);
    // Closures between random poses; every other one joins the estimate.
    std::vector<char> in(n - 1, 1);
    std::vector<int> tested;
    for (int c = 0; c < 30; ++c) {
      const int a = static_cast<int>(rng() % n);
      const int b = static_cast<int>((a + 1 + rng() % (n - 1)) % n);
      add(a, b);
      in.push_back(c % 2 == 0);
      if (c % 2) tested.push_back(static_cast<int>(g.edges.size()) - 1);
    }
    PoseGraph graph(g);
    Problem& problem = graph.problem();
    const SparseJacobianEvaluation j = problem.EvaluateSparseJacobian();
    const int m = static_cast<int>(g.edges.size());
    std::vector<int> offsets(m + 1, 0);
    for (int k = 0; k < m; ++k) offsets[k + 1] = offsets[k] + problem.residual_size(k);
    std::vector<int> column(n, -1), tangent(n, 6);
    for (size_t q = 0; q < j.variables.size(); ++q) {
      for (int i = 0; i < n; ++i) {
        if (graph.variable_at(i) == j.variables[q]) column[i] = j.column_offsets[q];
      }
    }
    ASSERT_EQ(column[0], -1);  // the gauge
    const std::vector<double> exact = InnovationChi2(j.jacobian, j.residuals, offsets, in, tested);
    const std::vector<double> floor =
        InnovationChi2Floor(g, column, tangent, j.jacobian, j.residuals, offsets, in, tested);
    int bounded = 0;
    for (size_t i = 0; i < tested.size(); ++i) {
      ASSERT_TRUE(std::isfinite(exact[i]));
      if (std::isnan(floor[i])) continue;  // its path crosses the gauge's vertex
      EXPECT_LE(floor[i], exact[i] * (1 + 1e-9)) << draw << " " << tested[i];
      EXPECT_GT(floor[i], 0.0);
      ++bounded;
    }
    EXPECT_GE(bounded, 5) << draw;
    // The closures in the estimate: the ceiling bounds the drop when one leaves.
    std::vector<int> kept;
    for (int k = n - 1; k < m; ++k) {
      if (in[k]) kept.push_back(k);
    }
    const std::vector<double> drop = DeletionChi2(j.jacobian, j.residuals, offsets, in, kept);
    const std::vector<double> ceiling =
        DeletionChi2Ceiling(g, column, tangent, j.jacobian, j.residuals, offsets, in, kept);
    // Asked for no more than 0, each falls back on the ball of the path's
    // vertices and their neighbours: tighter, still a bound.
    const std::vector<double> ball =
        DeletionChi2Ceiling(g, column, tangent, j.jacobian, j.residuals, offsets, in, kept,
                            std::vector<double>(kept.size(), 0.0), n);
    int capped = 0, tighter = 0;
    for (size_t i = 0; i < kept.size(); ++i) {
      ASSERT_TRUE(std::isfinite(drop[i]));
      if (std::isnan(ceiling[i])) continue;
      EXPECT_GE(ceiling[i], drop[i] * (1 - 1e-9)) << draw << " " << kept[i];
      ASSERT_TRUE(std::isfinite(ball[i])) << draw << " " << kept[i];
      EXPECT_GE(ball[i], drop[i] * (1 - 1e-9)) << draw << " " << kept[i];
      EXPECT_LE(ball[i], ceiling[i] * (1 + 1e-9)) << draw << " " << kept[i];
      tighter += ball[i] < 0.9 * ceiling[i];
      ++capped;
    }
    EXPECT_GE(capped, 5) << draw;
    EXPECT_GE(tighter, 1) << draw;

    // The chain alone: exact, ends anywhere.
    std::vector<char> chain(m, 0);
    std::fill_n(chain.begin(), n - 1, 1);
    std::vector<int> all;
    for (int k = n - 1; k < m; ++k) all.push_back(k);
    const std::vector<double> alone = InnovationChi2(j.jacobian, j.residuals, offsets, chain, all);
    const std::vector<double> path =
        InnovationChi2Floor(g, column, tangent, j.jacobian, j.residuals, offsets, chain, all);
    for (size_t i = 0; i < all.size(); ++i) {
      const io::Edge& e = g.edges[all[i]];
      EXPECT_NEAR(path[i], alone[i], 1e-8 * alone[i]) << draw << " " << e.from << " " << e.to;
      // The chain and this closure: the ceiling of its drop is exact too.
      std::vector<char> with = chain;
      with[all[i]] = 1;
      const double exact_drop =
          DeletionChi2(j.jacobian, j.residuals, offsets, with, {all[i]}).front();
      const double ceiling_drop =
          DeletionChi2Ceiling(g, column, tangent, j.jacobian, j.residuals, offsets, with, {all[i]})
              .front();
      EXPECT_NEAR(ceiling_drop, exact_drop, 1e-8 * exact_drop) << draw << " " << e.from;
    }
  }
}

// Two laps of a circle of n poses (σ 2 cm, 0.5°), a loop closure from every
// pose of the second lap to the same place on the first, and `wrong` closures
// between random poses with random measurements (the model of
// boxplus.slam.generate). The file's estimate is the odometry composed.
struct TwoLaps {
  io::Graph graph;
  std::vector<Eigen::Vector3d> truth;
  std::set<std::pair<int, int>> wrong;
};

Eigen::Vector3d Between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double c = std::cos(a[2]), s = std::sin(a[2]);
  const Eigen::Vector2d d = b.head<2>() - a.head<2>();
  return {c * d[0] + s * d[1], -s * d[0] + c * d[1], std::remainder(b[2] - a[2], 2 * M_PI)};
}

Eigen::Vector3d Compose(const Eigen::Vector3d& a, const Eigen::Vector3d& z) {
  const double c = std::cos(a[2]), s = std::sin(a[2]);
  return {a[0] + c * z[0] - s * z[1], a[1] + s * z[0] + c * z[1],
          std::remainder(a[2] + z[2], 2 * M_PI)};
}

TwoLaps MakeTwoLaps(int n, int num_wrong, unsigned seed) {
  TwoLaps t;
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0, 1);
  const double sigma_t = 0.02, sigma_r = 0.01;
  for (int i = 0; i < 2 * n; ++i) {
    const double a = 2 * M_PI * i / n;
    t.truth.emplace_back(10 * std::cos(a), 10 * std::sin(a),
                         std::remainder(a + M_PI / 2, 2 * M_PI));
  }
  Eigen::Matrix3d info =
      Eigen::Vector3d(1 / (sigma_t * sigma_t), 1 / (sigma_t * sigma_t), 1 / (sigma_r * sigma_r))
          .asDiagonal();
  int line = 0;
  auto add_edge = [&](int a, int b, Eigen::Vector3d z) {
    io::Edge e;
    e.kind = io::EdgeKind::kSE2;
    e.from = a;
    e.to = b;
    e.measurement = z;
    e.information = info;
    e.line = ++line;
    t.graph.AddEdge(e);
  };
  auto noisy = [&](const Eigen::Vector3d& z) {
    return Eigen::Vector3d(z[0] + sigma_t * g(rng), z[1] + sigma_t * g(rng),
                           z[2] + sigma_r * g(rng));
  };
  std::vector<Eigen::Vector3d> odometry;
  for (int i = 0; i + 1 < 2 * n; ++i)
    odometry.push_back(noisy(Between(t.truth[i], t.truth[i + 1])));
  Eigen::Vector3d x = t.truth[0];
  for (int i = 0; i < 2 * n; ++i) {
    io::Vertex v;
    v.id = i;
    v.kind = io::VertexKind::kSE2;
    v.estimate = x;
    v.line = ++line;
    t.graph.AddVertex(v);
    if (i + 1 < 2 * n) x = Compose(x, odometry[i]);
  }
  for (int i = 0; i + 1 < 2 * n; ++i) add_edge(i, i + 1, odometry[i]);
  for (int i = n; i < 2 * n; i += 2) add_edge(i - n, i, noisy(Between(t.truth[i - n], t.truth[i])));
  std::uniform_int_distribution<int> pose(0, 2 * n - 1);
  std::uniform_real_distribution<double> u(-1, 1);
  while (static_cast<int>(t.wrong.size()) < num_wrong) {
    int a = pose(rng), b = pose(rng);
    if (a > b) std::swap(a, b);
    if (b - a < 2 || b - a == n || t.wrong.count({a, b})) continue;
    t.wrong.insert({a, b});
    add_edge(a, b, Eigen::Vector3d(5 * u(rng), 5 * u(rng), M_PI * u(rng)));
  }
  return t;
}

io::Graph WithoutWrong(const TwoLaps& t) {
  io::Graph g = t.graph;
  g.edges.clear();
  for (const io::Edge& e : t.graph.edges) {
    if (!t.wrong.count({e.from, e.to})) g.edges.push_back(e);
  }
  return g;
}

std::set<std::pair<int, int>> Judged(const OutlierReport& r) {
  std::set<std::pair<int, int>> out;
  for (const EdgeVerdict& v : r.outliers) out.insert({v.from, v.to});
  return out;
}

double MaxDifference(PoseGraph& a, PoseGraph& b) {
  double worst = 0;
  for (int id : a.vertex_ids()) {
    const Eigen::Map<const Eigen::Vector3d> x(a.problem().value(a.variable(id)));
    const Eigen::Map<const Eigen::Vector3d> y(b.problem().value(b.variable(id)));
    worst = std::max(worst, (x - y).cwiseAbs().maxCoeff());
  }
  return worst;
}

// The default (auto) answers an implausible graph by GNC-TLS: it finds
// exactly the wrong closures here and returns the inliers' optimum.
TEST(Gnc, AutoFindsTheWrongClosuresAndReturnsTheInliersOptimum) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const TwoLaps t = MakeTwoLaps(120, 30, seed);  // 30 of 90 closures wrong
    PoseGraph pg(t.graph);
    pg.set_restart_when_implausible(true);  // what LoadPoseGraph sets for init "best"
    const SolveSummary s = pg.Solve();
    ASSERT_TRUE(s.usable) << s.message;
    const OutlierReport& r = pg.outlier_report();
    ASSERT_TRUE(r.ran) << s.message;
    EXPECT_EQ(r.method, "gnc-tls");
    EXPECT_EQ(r.candidates, 60 + 30);
    EXPECT_EQ(Judged(r), t.wrong) << "seed " << seed;
    EXPECT_THAT(s.message, ::testing::HasSubstr("30 of 90 loop closures judged wrong"));
    for (const EdgeVerdict& v : r.outliers) {
      EXPECT_EQ(t.graph.edges[v.edge].line, v.line);
      EXPECT_GT(v.chi2, r.threshold);
    }

    PoseGraph inliers(WithoutWrong(t));
    ASSERT_TRUE(inliers.Solve().usable);
    EXPECT_LT(MaxDifference(pg, inliers), 1e-6) << "seed " << seed;
    EXPECT_NEAR(2 * s.final_cost, inliers.Chi2(), 1e-6 * inliers.Chi2());
  }
}

TEST(Gnc, GemanMcClureFindsThemToo) {
  const TwoLaps t = MakeTwoLaps(120, 30, 4);
  PoseGraph pg(t.graph);
  OutlierOptions o;
  o.mode = OutlierMode::kGm;
  pg.set_outlier_options(o);
  ASSERT_TRUE(pg.Solve().usable);
  EXPECT_EQ(pg.outlier_report().method, "gnc-gm");
  EXPECT_EQ(Judged(pg.outlier_report()), t.wrong);
}

// Without wrong closures the default path is the one solve it always was, and
// forced GNC keeps every closure and ends at the same optimum.
TEST(Gnc, APlausibleGraphIsLeftAlone) {
  const TwoLaps t = MakeTwoLaps(120, 0, 5);
  PoseGraph plain(t.graph);
  plain.set_restart_when_implausible(true);
  const SolveSummary a = plain.Solve();
  ASSERT_TRUE(a.usable);
  EXPECT_FALSE(plain.outlier_report().ran);
  EXPECT_LT(plain.Chi2PerDof(), kImplausibleChi2PerDof);

  OutlierOptions off;
  off.mode = OutlierMode::kOff;
  PoseGraph reference(t.graph);
  reference.set_outlier_options(off);
  reference.set_restart_when_implausible(true);
  const SolveSummary b = reference.Solve();
  EXPECT_EQ(a.final_cost, b.final_cost);
  EXPECT_EQ(a.iterations, b.iterations);

  PoseGraph forced(t.graph);
  OutlierOptions tls;
  tls.mode = OutlierMode::kTls;
  forced.set_outlier_options(tls);
  ASSERT_TRUE(forced.Solve().usable);
  EXPECT_TRUE(forced.outlier_report().ran);
  EXPECT_TRUE(forced.outlier_report().outliers.empty());
  EXPECT_NEAR(forced.Chi2(), plain.Chi2(), 1e-6 * plain.Chi2());
  EXPECT_LT(MaxDifference(forced, plain), 1e-6);
}

TEST(Gnc, OffKeepsTheLowestLeastSquaresMinimum) {
  const TwoLaps t = MakeTwoLaps(120, 30, 6);
  OutlierOptions off;
  off.mode = OutlierMode::kOff;
  PoseGraph pg(t.graph);
  pg.set_outlier_options(off);
  pg.set_restart_when_implausible(true);
  const SolveSummary s = pg.Solve();
  EXPECT_FALSE(pg.outlier_report().ran);
  EXPECT_THAT(s.message, ::testing::HasSubstr("kept the lowest"));
}

TEST(Gnc, RefusesWhatItCannotJudge) {
  const TwoLaps t = MakeTwoLaps(60, 5, 7);
  OutlierOptions tls;
  tls.mode = OutlierMode::kTls;
  PoseGraphOptions cauchy;
  cauchy.robust = "cauchy";
  PoseGraph kernel(t.graph, cauchy);
  kernel.set_outlier_options(tls);
  EXPECT_THAT([&] { kernel.Solve(); },
              ::testing::ThrowsMessage<Error>(::testing::HasSubstr("robust kernel")));
  OutlierOptions bad;
  bad.inlier_probability = 1.0;
  EXPECT_THROW(kernel.set_outlier_options(bad), Error);
}

TEST(Gnc, TheOutlierFileNamesLinesAndIds) {
  OutlierReport r;
  r.ran = true;
  r.method = "gnc-tls";
  r.threshold = 11.34;
  r.candidates = 4;
  r.outliers.push_back({3, 17, 2, 9, 0.0, 1234.5});
  const std::string text = FormatOutliers(r, "graph.g2o");
  EXPECT_THAT(text, ::testing::HasSubstr("graph.g2o"));
  EXPECT_THAT(text, ::testing::HasSubstr("1 of 4 loop closures"));
  EXPECT_THAT(text, ::testing::EndsWith("\n17 2 9 1234.5 0\n"));
  EXPECT_THAT(text, ::testing::Not(::testing::HasSubstr("under-confident")));
  r.information_scale = 2.5e-4;  // GNC judged again in the inliers' units
  EXPECT_THAT(FormatOutliers(r, "graph.g2o"),
              ::testing::HasSubstr("under-confident: thresholds x 0.00025"));
  EXPECT_THAT(FormatOutliers(OutlierReport{}, "g"), ::testing::HasSubstr("did not run"));
}

}  // namespace
}  // namespace boxplus::slam
