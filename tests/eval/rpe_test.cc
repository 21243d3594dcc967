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

TEST(RpeAllIdPairs, FramesPairEveryPoseWithTheOneDAhead) {
  std::vector<IdPair> pairs;
  ASSERT_TRUE(
      RpeAllIdPairs(AlongX(std::vector<double>(6, 0.0)), 3, DeltaUnit::kFrames, 0.1, &pairs).ok());
  EXPECT_EQ(pairs, (Pairs{{0, 3}, {1, 4}, {2, 5}}));
}

TEST(RpeAllIdPairs, MetresTakeTheNearestPathLengthWithinTheTolerance) {
  // Path lengths from pose 0 (exact binary fractions): 0 0.5 1 1.5 2.25 3 3 3 4.
  const Trajectory poses = AlongX({0.0, 0.5, 1.0, 1.5, 2.25, 3.0, 3.0, 3.0, 4.0});
  std::vector<IdPair> pairs;
  // Tolerance 0.1 m: only the starts with a pose exactly 1 m further on.
  ASSERT_TRUE(RpeAllIdPairs(poses, 1.0, DeltaUnit::kMeters, 0.1, &pairs).ok());
  EXPECT_EQ(pairs, (Pairs{{0, 2}, {1, 3}, {5, 8}, {6, 8}, {7, 8}}));
  // Tolerance 0.3 m: 2 -> 4 (2.25 beats 1.5), 3 -> 4 (the 0.25 m short one
  // beats the 0.5 m long one), 4 -> 5 (the first pose of the stretch at 3 m).
  ASSERT_TRUE(RpeAllIdPairs(poses, 1.0, DeltaUnit::kMeters, 0.3, &pairs).ok());
  EXPECT_EQ(pairs,
            (Pairs{{0, 2}, {1, 3}, {2, 4}, {3, 4}, {4, 5}, {5, 8}, {6, 8}, {7, 8}}));
  // A tie (0.75 and 1.25 m from pose 0) goes to the nearer pose.
  ASSERT_TRUE(RpeAllIdPairs(AlongX({0.0, 0.75, 1.25}), 1.0, DeltaUnit::kMeters, 0.3, &pairs).ok());
  EXPECT_EQ(pairs, (Pairs{{0, 1}}));
}

TEST(RpeAllIdPairs, Errors) {
  const Trajectory poses = AlongX({0.0, 1.0, 2.0});
  std::vector<IdPair> pairs;
  EXPECT_EQ(RpeAllIdPairs(poses, 1.0, DeltaUnit::kMeters, 1.0, &pairs).code(),
            Status::Code::kInvalidArgument);
  EXPECT_EQ(RpeAllIdPairs(poses, 1.0, DeltaUnit::kMeters, -0.1, &pairs).code(),
            Status::Code::kInvalidArgument);
  EXPECT_EQ(RpeAllIdPairs(poses, 1.5, DeltaUnit::kFrames, 0.1, &pairs).code(),
            Status::Code::kInvalidArgument);
  EXPECT_EQ(RpeAllIdPairs(poses, 3, DeltaUnit::kFrames, 0.1, &pairs).code(),
            Status::Code::kFailedPrecondition);
  EXPECT_EQ(RpeAllIdPairs(poses, 5.0, DeltaUnit::kMeters, 0.1, &pairs).code(),
            Status::Code::kFailedPrecondition);
}

TEST(Rpe, AllPairsInMetresMeasureTheDriftPerDistance) {
  // The estimate runs 1 % long: 0.101 m steps against 0.1 m. Pairs of 2 m of
  // estimated path are 20 steps (2.02 m, the nearest to 2 m), whose error is
  // 2.02 - 2.00 = 0.02 m: 1 % of the delta, from every start pose that has
  // 20 steps ahead (a tolerance of 2 %, 0.04 m, keeps out the last starts'
  // 19-step pairs, 1.919 m; the default 10 % would take them).
  std::vector<double> x_reference;
  std::vector<double> x_estimate;
  for (int i = 0; i <= 100; ++i) {
    x_reference.push_back(0.1 * i);
    x_estimate.push_back(0.101 * i);
  }
  RpeOptions options;
  options.delta = 2.0;
  options.delta_unit = DeltaUnit::kMeters;
  options.all_pairs = true;
  options.all_pairs_relative_tolerance = 0.02;
  RpeResult result;
  ASSERT_TRUE(ComputeRpe(AlongX(x_reference), AlongX(x_estimate), options, &result).ok());
  EXPECT_EQ(result.statistics.count, 81u);  // starts 0..80
  EXPECT_NEAR(result.statistics.mean / options.delta, 0.01, 1e-9);
  EXPECT_NEAR(result.statistics.max, 0.02, 1e-9);
  // Consecutive pairs see the same drift from far fewer segments.
  options.all_pairs = false;
  ASSERT_TRUE(ComputeRpe(AlongX(x_reference), AlongX(x_estimate), options, &result).ok());
  EXPECT_LT(result.statistics.count, 6u);
}

TEST(Rpe, WorldDisplacementLeavesAConstantAttitudeOffsetOut) {
  // The estimate has the reference's positions and an attitude 0.5 deg off
  // about a fixed body axis: the start-pose form sees angle x distance, the
  // world form nothing.
  const Trajectory reference = testing::Curve(60);
  Trajectory estimate = reference;
  const Eigen::Isometry3d offset = testing::MakePose(
      Eigen::Vector3d(0.0, 0.0, 0.5 * M_PI / 180.0), Eigen::Vector3d::Zero());
  for (Eigen::Isometry3d& T : estimate.T_G_b) T = T * offset;
  RpeOptions options;
  options.delta = 0.5;
  options.delta_unit = DeltaUnit::kMeters;
  options.all_pairs = true;
  RpeResult result;
  ASSERT_TRUE(ComputeRpe(reference, estimate, options, &result).ok());
  EXPECT_GT(result.statistics.mean, 0.5 * 0.5 * 0.5 * M_PI / 180.0);  // > half angle x delta
  options.translation_in_world = true;
  ASSERT_TRUE(ComputeRpe(reference, estimate, options, &result).ok());
  EXPECT_LT(result.statistics.max, 1e-12);

  // A rotation of the whole estimate (the map frame's gauge): the world form
  // sees it unless the alignment takes it out.
  Trajectory rotated = reference;
  const Eigen::Isometry3d T_other_G =
      testing::MakePose(Eigen::Vector3d(0.0, 0.01, 0.02), Eigen::Vector3d(1.0, 2.0, 0.0));
  for (Eigen::Isometry3d& T : rotated.T_G_b) T = T_other_G * T;
  ASSERT_TRUE(ComputeRpe(reference, rotated, options, &result).ok());
  EXPECT_GT(result.statistics.mean, 0.005);
  options.alignment = Alignment::kSe3;
  ASSERT_TRUE(ComputeRpe(reference, rotated, options, &result).ok());
  EXPECT_LT(result.statistics.max, 1e-9);

  options.relation = PoseRelation::kRotationAngleDeg;
  EXPECT_EQ(ComputeRpe(reference, rotated, options, &result).code(),
            Status::Code::kInvalidArgument);
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
