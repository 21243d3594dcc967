#include "swarmlio/state/state_layout.h"

#include <gtest/gtest.h>

namespace swarmlio {
namespace {

TEST(ErrorStateLayout, EgoSegmentsTileTheFirst18Dimensions) {
  using L = ErrorStateLayout;
  const Segment segments[] = {L::kRotation, L::kPosition,   L::kVelocity,
                              L::kGyroBias, L::kAccelBias, L::kGravity};
  int next = 0;
  for (const Segment& s : segments) {
    EXPECT_EQ(s.offset, next);
    EXPECT_EQ(s.size, 3);
    next = s.end();
  }
  EXPECT_EQ(next, L::kEgoDim);
  EXPECT_EQ(L().Dim(), 18);
}

TEST(ErrorStateLayout, TeammatesAreAddedAndRemovedAtRunTime) {
  ErrorStateLayout layout;
  EXPECT_EQ(layout.AddTeammate(7).offset, 18);
  EXPECT_EQ(layout.AddTeammate(3).offset, 24);
  EXPECT_EQ(layout.AddTeammate(12).offset, 30);
  EXPECT_EQ(layout.Dim(), 18 + 6 * 3);
  EXPECT_EQ(layout.TeammateRotation(3).offset, 24);
  EXPECT_EQ(layout.TeammateTranslation(3).offset, 27);

  const Segment removed = layout.RemoveTeammate(3);
  EXPECT_EQ(removed.offset, 24);
  EXPECT_FALSE(layout.HasTeammate(3));
  EXPECT_EQ(layout.TeammateBlock(12).offset, 24);  // moved down
  EXPECT_EQ(layout.Dim(), 18 + 6 * 2);
  EXPECT_EQ(layout.teammate_ids(), (std::vector<int>{7, 12}));
}

TEST(ErrorStateLayoutDeathTest, UnknownTeammateIsAProgrammerError) {
  ErrorStateLayout layout;
  EXPECT_DEATH((void)layout.TeammateBlock(5), "teammate 5 is not in the state");
  layout.AddTeammate(5);
  EXPECT_DEATH(layout.AddTeammate(5), "already in the state");
}

TEST(CovarianceBlocks, AppendThenEraseRestoresTheMarginal) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Random(30, 30);
  Eigen::MatrixXd P = A * A.transpose();  // 18 ego + 2 teammates
  const Eigen::MatrixXd P0 = P;
  Eigen::MatrixXd P_new = 0.5 * Eigen::MatrixXd::Identity(6, 6);
  AppendCovarianceBlock(P_new, &P);
  ASSERT_EQ(P.rows(), 36);
  EXPECT_TRUE(P.bottomRightCorner(6, 6).isApprox(P_new));
  EXPECT_TRUE(P.topRightCorner(30, 6).isZero());
  EraseCovarianceBlock(Segment{30, 6}, &P);
  EXPECT_EQ(P, P0);

  // Erasing a middle block keeps the marginal of the others.
  EraseCovarianceBlock(Segment{18, 6}, &P);
  ASSERT_EQ(P.rows(), 24);
  EXPECT_EQ(P.topLeftCorner(18, 18), P0.topLeftCorner(18, 18));
  EXPECT_EQ(P.bottomRightCorner(6, 6), P0.bottomRightCorner(6, 6));
  EXPECT_EQ(P.topRightCorner(18, 6), P0.block(0, 24, 18, 6));
}

}  // namespace
}  // namespace swarmlio
