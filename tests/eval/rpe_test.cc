#include "swarmlio/eval/rpe.h"

#include <gtest/gtest.h>

#include <vector>

#include "tests/eval/eval_test_util.h"

namespace swarmlio::eval {
namespace {

Trajectory AlongX(const std::vector<double>& x) {
  Trajectory trajectory;
  for (size_t i = 0; i < x.size(); ++i) {
    trajectory.stamps_s.push_back(static_cast<double>(i));
    trajectory.T_G_b.push_back(
        testing::MakePose(Eigen::Vector3d::Zero(), Eigen::Vector3d(x[i], 0.0, 0.0)));
  }
  return trajectory;
}

using Pairs = std::vector<IdPair>;

TEST(RpeIdPairs, FramesTakeEveryDthPose) {
  std::vector<IdPair> pairs;
  ASSERT_TRUE(RpeIdPairs(AlongX(std::vector<double>(10, 0.0)), 3, DeltaUnit::kFrames, &pairs).ok());
  EXPECT_EQ(pairs, (Pairs{{0, 3}, {3, 6}, {6, 9}}));
  ASSERT_TRUE(RpeIdPairs(AlongX(std::vector<double>(10, 0.0)), 4, DeltaUnit::kFrames, &pairs).ok());
  EXPECT_EQ(pairs, (Pairs{{0, 4}, {4, 8}}));
}

TEST(RpeIdPairs, MetresEmitWhenThePathReachesDeltaThenReset) {
  // Path increments (exact binary fractions): 0.5 0.25 0.25 | 0.5 0.5 | 0.125 1.375
  // The sum reaches 1 at index 3 and 5 and 1.5 at 7: ids 3, 5, 7 (not 0).
  const Trajectory poses = AlongX({0.0, 0.5, 0.75, 1.0, 1.5, 2.0, 2.125, 3.5});
  std::vector<IdPair> pairs;
  ASSERT_TRUE(RpeIdPairs(poses, 1.0, DeltaUnit::kMeters, &pairs).ok());
  EXPECT_EQ(pairs, (Pairs{{3, 5}, {5, 7}}));
  // The path is walked, not the straight distance: back and forth counts.
  ASSERT_TRUE(RpeIdPairs(AlongX({0.0, 0.5, 0.0, 0.5, 0.0}), 0.5, DeltaUnit::kMeters, &pairs).ok());
  EXPECT_EQ(pairs, (Pairs{{1, 2}, {2, 3}, {3, 4}}));
}

TEST(RpeIdPairs, Errors) {
  const Trajectory poses = AlongX({0.0, 1.0, 2.0});
  std::vector<IdPair> pairs;
  EXPECT_EQ(RpeIdPairs(poses, 1.5, DeltaUnit::kFrames, &pairs).code(),
            Status::Code::kInvalidArgument);
  EXPECT_EQ(RpeIdPairs(poses, 0.0, DeltaUnit::kMeters, &pairs).code(),
            Status::Code::kInvalidArgument);
  EXPECT_EQ(RpeIdPairs(poses, 3, DeltaUnit::kFrames, &pairs).code(),
            Status::Code::kFailedPrecondition);
  EXPECT_EQ(RpeIdPairs(poses, 1.5, DeltaUnit::kMeters, &pairs).code(),
            Status::Code::kFailedPrecondition);
}

TEST(Rpe, ScaledStepsGiveTheStepDifference) {
  const Trajectory reference = AlongX({0, 1, 2, 3, 4});
  const Trajectory estimate = AlongX({0, 1.25, 2.5, 3.75, 5.0});
  RpeResult result;
  ASSERT_TRUE(ComputeRpe(reference, estimate, {}, &result).ok());
  EXPECT_EQ(result.statistics.count, 4u);
  EXPECT_DOUBLE_EQ(result.statistics.min, 0.25);
  EXPECT_DOUBLE_EQ(result.statistics.max, 0.25);
  // Sim(3) alignment removes the scale, and so the error.
  RpeOptions options;
  options.alignment = Alignment::kSim3;
  Trajectory reference_3d = testing::Curve(30);
  Trajectory estimate_3d = reference_3d;
  for (Eigen::Isometry3d& T : estimate_3d.T_G_b) T.translation() *= 0.5;
  ASSERT_TRUE(ComputeRpe(reference_3d, estimate_3d, options, &result).ok());
  EXPECT_LT(result.statistics.max, 1e-12);
}

TEST(Rpe, InvariantToARigidChangeOfTheEstimateFrame) {
  const Trajectory reference = testing::Curve(50);
  Trajectory estimate = reference;
  const Eigen::Isometry3d T_other_G =
      testing::MakePose(Eigen::Vector3d(0.5, 1.0, -0.3), Eigen::Vector3d(10, -4, 2));
  for (Eigen::Isometry3d& T : estimate.T_G_b) T = T_other_G * T;
  for (const PoseRelation relation :
       {PoseRelation::kTranslation, PoseRelation::kFull, PoseRelation::kRotationAngleDeg}) {
    RpeOptions options;
    options.relation = relation;
    options.delta = 0.5;
    options.delta_unit = DeltaUnit::kMeters;
    RpeResult result;
    ASSERT_TRUE(ComputeRpe(reference, estimate, options, &result).ok());
    EXPECT_GT(result.statistics.count, 3u);
    EXPECT_LT(result.statistics.max, 1e-9) << PoseRelationName(relation);
  }
}

TEST(Rpe, DeltaUnitNames) {
  DeltaUnit unit;
  ASSERT_TRUE(DeltaUnitFromString("m", &unit));
  EXPECT_EQ(unit, DeltaUnit::kMeters);
  ASSERT_TRUE(DeltaUnitFromString("f", &unit));
  EXPECT_EQ(unit, DeltaUnit::kFrames);
  EXPECT_FALSE(DeltaUnitFromString("s", &unit));
}

}  // namespace
}  // namespace swarmlio::eval
