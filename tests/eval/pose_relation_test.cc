#include "swarmlio/eval/pose_relation.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/eval/eval_test_util.h"

namespace swarmlio::eval {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(PoseRelation, RotationAngleIsAccurateNearZeroAndPi) {
  for (const double angle : {0.0, 1e-9, 1e-5, 0.3, 2.0, kPi - 1e-7, kPi}) {
    const Eigen::Vector3d w = angle * Eigen::Vector3d(1, -2, 0.5).normalized();
    EXPECT_NEAR(RotationAngleRad(so3::Exp(w)), angle, 1e-15 + 1e-13 * angle) << angle;
  }
}

TEST(PoseRelation, ValuesOfAKnownErrorPose) {
  const Eigen::Vector3d w(0.0, 0.0, 0.25);
  const Eigen::Vector3d t(3.0, 4.0, 0.0);
  const Eigen::Isometry3d E = testing::MakePose(w, t);
  EXPECT_DOUBLE_EQ(PoseRelationError(E, PoseRelation::kTranslation), 5.0);
  EXPECT_NEAR(PoseRelationError(E, PoseRelation::kRotationAngleRad), 0.25, 1e-15);
  EXPECT_NEAR(PoseRelationError(E, PoseRelation::kRotationAngleDeg), 0.25 * 180 / kPi, 1e-13);
  // |R - I|_F for a rotation by a: sqrt(2 (2 - 2 cos a)) (two 2 x 2 entries change).
  const double rot = std::sqrt(4.0 - 4.0 * std::cos(0.25));
  EXPECT_NEAR(PoseRelationError(E, PoseRelation::kRotationPart), rot, 1e-15);
  // evo's full_transformation: |E - I|_F of the 4 x 4 matrix.
  EXPECT_NEAR(PoseRelationError(E, PoseRelation::kFull), std::sqrt(rot * rot + 25.0), 1e-14);
}

TEST(PoseRelation, EveryRelationIsInvariantUnderInversion) {
  const Eigen::Isometry3d E =
      testing::MakePose(Eigen::Vector3d(0.2, -0.4, 0.9), Eigen::Vector3d(1.0, -2.0, 0.5));
  for (const PoseRelation relation :
       {PoseRelation::kTranslation, PoseRelation::kRotationPart, PoseRelation::kRotationAngleRad,
        PoseRelation::kRotationAngleDeg, PoseRelation::kFull}) {
    EXPECT_NEAR(PoseRelationError(E, relation), PoseRelationError(E.inverse(), relation), 1e-14)
        << PoseRelationName(relation);
  }
}

TEST(PoseRelation, Names) {
  PoseRelation relation;
  for (const char* name : {"trans_part", "rot_part", "angle_rad", "angle_deg", "full"}) {
    ASSERT_TRUE(PoseRelationFromString(name, &relation)) << name;
    EXPECT_STREQ(PoseRelationName(relation), name);
  }
  ASSERT_TRUE(PoseRelationFromString("trans", &relation));
  EXPECT_EQ(relation, PoseRelation::kTranslation);
  EXPECT_STREQ(PoseRelationUnit(relation), "m");
  EXPECT_FALSE(PoseRelationFromString("angle", &relation));
}

}  // namespace
}  // namespace swarmlio::eval
