// One rule for every name↔value vocabulary (named_enum.h): case-insensitive,
// '-' equal to '_', aliases, and an error that lists the canonical names.
#include "boxplus/named_enum.h"

#include <gtest/gtest.h>

#include "boxplus/factors/pose/pose_error_convention.h"
#include "boxplus/loss.h"
#include "boxplus/slam/initialization.h"
#include "boxplus/solver_options.h"

namespace boxplus {
namespace {

TEST(NamedEnum, OneInputRuleForEveryVocabulary) {
  EXPECT_EQ(ParseMethod("GN-LS"), Method::kGaussNewtonLineSearch);
  EXPECT_EQ(ParseMethod("gn_ls"), Method::kGaussNewtonLineSearch);
  EXPECT_EQ(ParseMethod("Auto"), Method::kGaussNewtonFallback);
  EXPECT_EQ(ParseDamping("Levenberg"), Damping::kLevenberg);
  EXPECT_EQ(slam::ParseInitMethod("Spanning_Tree"), slam::InitMethod::kSpanningTree);
  EXPECT_EQ(slam::ParseInitMethod("odometry"), slam::InitMethod::kSpanningTree);
  EXPECT_EQ(ParsePoseErrorConvention("GTSAM"), PoseErrorConvention::kLog);
  EXPECT_EQ(ParsePoseErrorConvention("Chordal"), PoseErrorConvention::kSESync);
  EXPECT_EQ(CanonicalLossName("Soft-L1"), "soft_l1");
  EXPECT_EQ(CanonicalLossName(""), "none");
}

TEST(NamedEnum, NamesRoundTripAndUnknownNamesListTheChoices) {
  for (const std::string& n : MethodNames()) EXPECT_EQ(MethodName(ParseMethod(n)), n);
  EXPECT_STREQ(slam::InitMethodName(slam::ParseInitMethod("spanning-tree")), "spanning-tree");
  EXPECT_STREQ(ToString(ParsePoseErrorConvention("se3log")), "log");
  try {
    ParseMethod("newton");
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "unknown method 'newton' (expected one of lm, gn, gn_ls, dogleg, gn_lm)");
  }
  EXPECT_THROW(CanonicalLossName("geman"), Error);
}

TEST(SolverOptions, GivenFieldsOverrideAnOwnersDefaultsAndOnlyThey) {
  SolverOptions defaults;
  defaults.method = Method::kGaussNewtonFallback;
  defaults.damping = Damping::kLevenberg;
  SolverOptions mine;
  mine.method = Method::kLevenbergMarquardt;
  mine.max_iterations = 7;
  mine.given = std::set<std::string>{"method"};
  const SolverOptions o = WithDefaults(defaults, mine);
  EXPECT_EQ(o.method, Method::kLevenbergMarquardt);
  EXPECT_EQ(o.damping, Damping::kLevenberg);             // the owner's
  EXPECT_EQ(o.max_iterations, defaults.max_iterations);  // not given: the owner's
  mine.given.reset();                                    // nothing said: taken whole
  EXPECT_EQ(WithDefaults(defaults, mine).max_iterations, 7);
  mine.given = std::set<std::string>{"no_such_field"};
  EXPECT_THROW(WithDefaults(defaults, mine), Error);
  EXPECT_EQ(SolverOptionNames().front(), "method");
}

}  // namespace
}  // namespace boxplus
