#include "swarmlio/eval/alignment.h"

#include <gtest/gtest.h>

#include "swarmlio/eval/ape.h"
#include "tests/eval/eval_test_util.h"

namespace swarmlio::eval {
namespace {

// The estimate is the reference seen through the inverse of a similarity
// (s, R, t): p_est = R^T (p_ref - t) / s, R_est = R^T R_ref.
Trajectory InverseSimilarity(const Trajectory& reference,
                             double s,
                             const Eigen::Matrix3d& R,
                             const Eigen::Vector3d& t) {
  Trajectory estimate = reference;
  for (Eigen::Isometry3d& T : estimate.T_G_b) {
    const Eigen::Vector3d p = R.transpose() * (T.translation() - t) / s;
    const Eigen::Matrix3d rotation = R.transpose() * T.linear();
    T.linear() = rotation;
    T.translation() = p;
  }
  return estimate;
}

TEST(Alignment, Sim3RecoversTheScale) {
  const Trajectory reference = testing::Curve(60);
  const double s = 2.5;
  const Eigen::Matrix3d R = so3::Exp(Eigen::Vector3d(0.3, -0.7, 1.9));
  const Eigen::Vector3d t(4.0, -1.0, 0.5);
  const Trajectory estimate = InverseSimilarity(reference, s, R, t);

  Trajectory aligned;
  UmeyamaResult transform;
  ASSERT_TRUE(AlignTrajectory(reference, estimate, Alignment::kSim3, &aligned, &transform).ok());
  EXPECT_NEAR(transform.scale, s, 1e-12);
  EXPECT_LT((transform.R_dst_src - R).norm(), 1e-12);
  EXPECT_LT((transform.t_dst_src - t).norm(), 1e-12);
  for (size_t i = 0; i < reference.size(); ++i) {
    EXPECT_LT((aligned.T_G_b[i].matrix() - reference.T_G_b[i].matrix()).norm(), 1e-12) << i;
  }

  ApeOptions options;
  options.alignment = Alignment::kSim3;
  ApeResult ape;
  ASSERT_TRUE(ComputeApe(reference, estimate, options, &ape).ok());
  EXPECT_NEAR(ape.alignment_transform.scale, s, 1e-12);
  EXPECT_LT(ape.statistics.max, 1e-12);
  options.relation = PoseRelation::kFull;
  ASSERT_TRUE(ComputeApe(reference, estimate, options, &ape).ok());
  EXPECT_LT(ape.statistics.max, 1e-12);

  // SE(3) cannot undo the scale: the error stays, the reported scale is 1.
  options.alignment = Alignment::kSe3;
  options.relation = PoseRelation::kTranslation;
  ASSERT_TRUE(ComputeApe(reference, estimate, options, &ape).ok());
  EXPECT_EQ(ape.alignment_transform.scale, 1.0);
  EXPECT_GT(ape.statistics.rmse, 0.1);
}

TEST(Alignment, Se3RemovesARigidOffset) {
  const Trajectory reference = testing::Curve(40);
  const Eigen::Vector3d w(0.0, 0.2, -2.0);
  const Trajectory estimate =
      InverseSimilarity(reference, 1.0, so3::Exp(w), Eigen::Vector3d(1, 2, 3));
  ApeOptions options;
  options.relation = PoseRelation::kRotationAngleDeg;
  ApeResult ape;
  ASSERT_TRUE(ComputeApe(reference, estimate, options, &ape).ok());
  // Without alignment every error pose is a rotation by |w|.
  EXPECT_NEAR(ape.statistics.min, w.norm() * 180.0 / 3.14159265358979323846, 1e-9);
  EXPECT_NEAR(ape.statistics.max, w.norm() * 180.0 / 3.14159265358979323846, 1e-9);
  options.alignment = Alignment::kSe3;
  ASSERT_TRUE(ComputeApe(reference, estimate, options, &ape).ok());
  EXPECT_LT(ape.statistics.max, 1e-9);
}

TEST(Alignment, NoneCopiesTheEstimate) {
  const Trajectory reference = testing::Curve(10);
  Trajectory estimate = testing::Curve(10);
  estimate.T_G_b[3].translation().x() += 1.0;
  Trajectory aligned;
  UmeyamaResult transform;
  ASSERT_TRUE(AlignTrajectory(reference, estimate, Alignment::kNone, &aligned, &transform).ok());
  EXPECT_EQ(aligned.T_G_b[3].matrix(), estimate.T_G_b[3].matrix());
  EXPECT_EQ(transform.scale, 1.0);
}

TEST(Alignment, Errors) {
  Trajectory aligned;
  UmeyamaResult transform;
  EXPECT_FALSE(
      AlignTrajectory(testing::Curve(5), testing::Curve(6), Alignment::kSe3, &aligned, &transform)
          .ok());
  EXPECT_FALSE(
      AlignTrajectory(testing::Curve(2), testing::Curve(2), Alignment::kSe3, &aligned, &transform)
          .ok());
  // All positions equal: degenerate.
  Trajectory still = testing::Curve(5);
  for (Eigen::Isometry3d& T : still.T_G_b) T.translation().setZero();
  EXPECT_FALSE(AlignTrajectory(still, still, Alignment::kSim3, &aligned, &transform).ok());
  Alignment alignment;
  EXPECT_TRUE(AlignmentFromString("sim3", &alignment));
  EXPECT_EQ(alignment, Alignment::kSim3);
  EXPECT_FALSE(AlignmentFromString("sim(3)", &alignment));
}

}  // namespace
}  // namespace swarmlio::eval
