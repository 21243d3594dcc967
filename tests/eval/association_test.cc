#include "swarmlio/eval/association.h"

#include <gtest/gtest.h>

#include <vector>

#include "tests/eval/eval_test_util.h"

namespace swarmlio::eval {
namespace {

Trajectory Stamped(const std::vector<double>& stamps_s) {
  Trajectory trajectory;
  for (size_t i = 0; i < stamps_s.size(); ++i) {
    trajectory.stamps_s.push_back(stamps_s[i]);
    trajectory.T_G_b.push_back(
        testing::MakePose(Eigen::Vector3d::Zero(), Eigen::Vector3d(static_cast<double>(i), 0, 0)));
  }
  return trajectory;
}

using Ids = std::vector<size_t>;

TEST(Association, KeepsPairsWithinTheToleranceInclusive) {
  // Stamps are exact binary fractions, so |dt| == tolerance is exact.
  const Trajectory reference = Stamped({0, 1, 2, 3, 4, 5, 6, 7, 8, 9});
  const Trajectory estimate = Stamped({0.25, 1.5, 3.75, 5.375, 7.0, 20.0});
  TrajectoryAssociationOptions options;
  options.max_time_diff_s = 0.25;
  AssociatedTrajectories result;
  ASSERT_TRUE(AssociateTrajectories(reference, estimate, options, &result).ok());
  // 0.25 -> 0 and 3.75 -> 4 (|dt| = tolerance), 7 -> 7; 1.5, 5.375 and 20 are too far.
  EXPECT_EQ(result.estimate_ids, (Ids{0, 2, 4}));
  EXPECT_EQ(result.reference_ids, (Ids{0, 4, 7}));
  EXPECT_EQ(result.max_pairs, 6u);
  ASSERT_EQ(result.reference.size(), 3u);
  EXPECT_EQ(result.reference.stamps_s[1], 4.0);
  EXPECT_EQ(result.estimate.stamps_s[1], 3.75);
  EXPECT_EQ(result.estimate.T_G_b[1].translation().x(), 2.0);  // the poses follow the ids
  // Just inside: |dt| == tolerance no longer passes.
  options.max_time_diff_s = 0.25 - 1.0 / 1024;
  ASSERT_TRUE(AssociateTrajectories(reference, estimate, options, &result).ok());
  EXPECT_EQ(result.estimate_ids, (Ids{4}));
}

TEST(Association, DefaultToleranceIsTenMilliseconds) {
  EXPECT_EQ(TrajectoryAssociationOptions().max_time_diff_s, 0.01);
  const Trajectory reference = Stamped({10.0, 10.1, 10.2, 10.3});
  const Trajectory estimate = Stamped({10.009, 10.1115, 10.195});
  AssociatedTrajectories result;
  ASSERT_TRUE(AssociateTrajectories(reference, estimate, {}, &result).ok());
  EXPECT_EQ(result.estimate_ids, (Ids{0, 2}));
  EXPECT_EQ(result.reference_ids, (Ids{0, 2}));
}

TEST(Association, TiesGoToTheFirstStampAndDuplicatesToTheFirstPose) {
  const Trajectory reference = Stamped({0, 1, 1, 2, 3});
  const Trajectory estimate = Stamped({1.0, 1.5});
  TrajectoryAssociationOptions options;
  options.max_time_diff_s = 0.5;
  AssociatedTrajectories result;
  ASSERT_TRUE(AssociateTrajectories(reference, estimate, options, &result).ok());
  EXPECT_EQ(result.reference_ids, (Ids{1, 1}));  // 1.0: first of two; 1.5: tie 1 vs 2 -> 1
}

TEST(Association, TheShorterTrajectoryIsMatchedAndLongPosesMayRepeat) {
  // The reference is shorter here: its stamps are matched into the estimate.
  const Trajectory reference = Stamped({1.0, 1.03});
  const Trajectory estimate = Stamped({1.02, 5.0, 6.0, 7.0});
  TrajectoryAssociationOptions options;
  options.max_time_diff_s = 0.05;
  AssociatedTrajectories result;
  ASSERT_TRUE(AssociateTrajectories(reference, estimate, options, &result).ok());
  EXPECT_EQ(result.reference_ids, (Ids{0, 1}));
  EXPECT_EQ(result.estimate_ids, (Ids{0, 0}));
  EXPECT_EQ(result.max_pairs, 2u);
}

TEST(Association, EqualSizesMatchTheEstimateIntoTheReference) {
  const Trajectory reference = Stamped({0.0, 1.0, 2.0});
  const Trajectory estimate = Stamped({0.9, 1.1, 5.0});
  TrajectoryAssociationOptions options;
  options.max_time_diff_s = 0.2;
  AssociatedTrajectories result;
  ASSERT_TRUE(AssociateTrajectories(reference, estimate, options, &result).ok());
  EXPECT_EQ(result.estimate_ids, (Ids{0, 1}));
  EXPECT_EQ(result.reference_ids, (Ids{1, 1}));
}

TEST(Association, OffsetShiftsTheEstimate) {
  const Trajectory reference = Stamped({0, 1, 2, 3, 4});
  const Trajectory estimate = Stamped({10.5, 11.5});
  TrajectoryAssociationOptions options;
  options.max_time_diff_s = 0.0;
  options.time_offset_s = -8.5;
  AssociatedTrajectories result;
  ASSERT_TRUE(AssociateTrajectories(reference, estimate, options, &result).ok());
  EXPECT_EQ(result.reference_ids, (Ids{2, 3}));
}

TEST(Association, NoOverlapIsAnError) {
  const Trajectory reference = Stamped({0, 1, 2});
  const Trajectory estimate = Stamped({100, 101});
  AssociatedTrajectories result;
  const Status status = AssociateTrajectories(reference, estimate, {}, &result);
  EXPECT_EQ(status.code(), Status::Code::kFailedPrecondition);
  EXPECT_NE(status.message().find("no matching stamps"), std::string::npos) << status.message();
}

TEST(Association, UnstampedTrajectoriesPairByIndex) {
  Trajectory reference = Stamped({0, 1, 2});
  Trajectory estimate = Stamped({5, 6, 7});
  reference.stamps_s.clear();
  AssociatedTrajectories result;
  ASSERT_TRUE(AssociateTrajectories(reference, estimate, {}, &result).ok());
  EXPECT_EQ(result.reference_ids, (Ids{0, 1, 2}));
  EXPECT_EQ(result.estimate_ids, (Ids{0, 1, 2}));
  estimate.T_G_b.pop_back();
  estimate.stamps_s.pop_back();
  EXPECT_FALSE(AssociateTrajectories(reference, estimate, {}, &result).ok());
}

TEST(Association, RejectsBadInput) {
  const Trajectory good = Stamped({0, 1, 2});
  AssociatedTrajectories result;
  TrajectoryAssociationOptions negative;
  negative.max_time_diff_s = -1.0;
  EXPECT_FALSE(AssociateTrajectories(good, good, negative, &result).ok());
  EXPECT_FALSE(AssociateTrajectories(Trajectory(), good, {}, &result).ok());
  EXPECT_FALSE(AssociateTrajectories(good, Trajectory(), {}, &result).ok());
  Trajectory decreasing = Stamped({0, 2, 1});
  EXPECT_FALSE(AssociateTrajectories(good, decreasing, {}, &result).ok());
  Trajectory not_finite = Stamped({0, 1, 2});
  not_finite.T_G_b[1].translation().x() = std::nan("");
  EXPECT_FALSE(AssociateTrajectories(good, not_finite, {}, &result).ok());
}

}  // namespace
}  // namespace swarmlio::eval
