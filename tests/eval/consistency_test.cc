// Ground truth in the estimator's G or in another frame (mocap, simulator
// world): CheckGroundTruthFrame decides, AlignGroundTruthByFirstPose moves it
// into G, and a declared frame overrides the detection.
#include "swarmlio/eval/consistency.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "swarmlio/math/so3.h"

namespace swarmlio::eval {
namespace {

// One estimated pose (an updated scan's) with its position covariance.
void AddPose(int64_t stamp_ns,
             const Eigen::Quaterniond& q_G_b,
             const Eigen::Vector3d& p_b_in_G,
             const Eigen::Matrix3d& P_pp,
             CovariantTrajectory* estimate) {
  Eigen::Isometry3d T_G_b = Eigen::Isometry3d::Identity();
  T_G_b.linear() = q_G_b.normalized().toRotationMatrix();
  T_G_b.translation() = p_b_in_G;
  estimate->poses.stamps_s.push_back(ToSeconds(stamp_ns));
  estimate->poses.T_G_b.push_back(T_G_b);
  estimate->position_covariances.push_back(P_pp);
}

// An estimate along a curve in G (1 cm off the truth), and its ground truth
// in G, 20 Hz, 5 s.
void MakeRun(CovariantTrajectory* scans, std::vector<PoseStamped>* truth) {
  for (int k = 0; k < 100; ++k) {
    const double t = 0.05 * k;
    PoseStamped p;
    p.stamp_ns = 1'000'000'000LL + 50'000'000LL * k;
    p.p_b_in_G = Eigen::Vector3d(std::sin(t), 0.5 * t, 0.1 * t * t);
    p.q_G_b = so3::ExpQuaternion(Eigen::Vector3d(0.0, 0.02 * t, 0.3 * t));
    truth->push_back(p);
    AddPose(p.stamp_ns, p.q_G_b, p.p_b_in_G + Eigen::Vector3d(0.01, 0.0, 0.0),
            1e-4 * Eigen::Matrix3d::Identity(), scans);
  }
}

std::vector<PoseStamped> InWorld(const std::vector<PoseStamped>& truth) {
  const Eigen::Quaterniond q_W_G = so3::ExpQuaternion(Eigen::Vector3d(0.1, -0.2, 1.4));
  const Eigen::Vector3d p_G_in_W(4.0, -2.0, 1.0);
  std::vector<PoseStamped> out = truth;
  for (PoseStamped& p : out) {
    p.p_b_in_G = q_W_G * p.p_b_in_G + p_G_in_W;
    p.q_G_b = q_W_G * p.q_G_b;
  }
  return out;
}

TEST(FrameCheck, GroundTruthInGIsDetected) {
  CovariantTrajectory scans;
  std::vector<PoseStamped> truth;
  MakeRun(&scans, &truth);
  FrameCheck check;
  ASSERT_TRUE(CheckGroundTruthFrame(scans.poses, TrajectoryFromPoses(truth),
                                    GroundTruthFrame::kAuto, FrameCheckOptions(), &check)
                  .ok());
  EXPECT_TRUE(check.compared);
  EXPECT_TRUE(check.same_frame);
  EXPECT_FALSE(check.declared);
  EXPECT_NEAR(check.position_offset_m, 0.01, 1e-9);
  EXPECT_NE(check.Summary().find("ground truth in G"), std::string::npos) << check.Summary();
}

TEST(FrameCheck, ForeignFrameIsDetectedAndAlignedByTheFirstPose) {
  CovariantTrajectory scans;
  std::vector<PoseStamped> truth;
  MakeRun(&scans, &truth);
  const std::vector<PoseStamped> world = InWorld(truth);
  FrameCheck check;
  ASSERT_TRUE(CheckGroundTruthFrame(scans.poses, TrajectoryFromPoses(world),
                                    GroundTruthFrame::kAuto, FrameCheckOptions(), &check)
                  .ok());
  EXPECT_FALSE(check.same_frame);
  EXPECT_GT(check.position_offset_m, 1.0);
  EXPECT_NE(check.Summary().find("ground truth in another frame: aligned by first pose and SE(3)"),
            std::string::npos)
      << check.Summary();

  // Unaligned, the NEES of a foreign frame is huge; aligned by the first pose
  // the position errors are the estimate's own (1 cm here).
  ConsistencyStats raw, aligned_stats;
  ASSERT_TRUE(EvaluateConsistency(scans, TrajectoryFromPoses(world), 0.06, &raw).ok());
  EXPECT_GT(raw.mean_position_nees, 1e4);
  Trajectory aligned;
  ASSERT_TRUE(
      AlignGroundTruthByFirstPose(scans.poses, TrajectoryFromPoses(world), check, 0.06, &aligned)
          .ok());
  ASSERT_TRUE(EvaluateConsistency(scans, aligned, 0.06, &aligned_stats).ok());
  EXPECT_LT(aligned_stats.position_rmse_m, 0.012);

  // Declared: the manifest wins over the detection.
  ASSERT_TRUE(CheckGroundTruthFrame(scans.poses, TrajectoryFromPoses(world), GroundTruthFrame::kG,
                                    FrameCheckOptions(), &check)
                  .ok());
  EXPECT_TRUE(check.same_frame);
  EXPECT_TRUE(check.declared);
  ASSERT_TRUE(CheckGroundTruthFrame(scans.poses, TrajectoryFromPoses(truth),
                                    GroundTruthFrame::kOther, FrameCheckOptions(), &check)
                  .ok());
  EXPECT_FALSE(check.same_frame);
}

// The gauge of a LIO: the map is anchored by the first scan through the
// LiDAR-IMU calibration, so a calibration rotation error dR rotates every
// estimated position about the start. A run along a 60 m corridor-like
// path with zero-mean errors drawn from the reported covariance, seen in a
// frame rotated by 0.4 deg about the start: in G the NEES is far above 3;
// after the gauge alignment it is 3 within its sampling band, and the fitted
// rotation is the 0.38 deg. A covariance 4x too small fails the aligned bound,
// and so does an alignment applied the wrong way round (R^T).
TEST(GaugeAlignedNees, RemovesAFrameRotationAboutTheStartAndNothingElse) {
  const Eigen::Vector3d dtheta(0.002, -0.003, 0.0055);  // |dtheta| = 0.0066 rad = 0.38 deg
  const Eigen::Quaterniond q_map_G = so3::ExpQuaternion(dtheta);
  const double sigma_m = 0.004;
  auto make = [&](double covariance_scale, CovariantTrajectory* scans,
                  std::vector<PoseStamped>* truth) {
    std::mt19937 rng(7);
    std::normal_distribution<double> normal(0.0, sigma_m);
    for (int k = 0; k < 600; ++k) {
      const double t = 0.1 * k;
      PoseStamped p;
      p.stamp_ns = 1'000'000'000LL + 100'000'000LL * k;
      p.p_b_in_G = Eigen::Vector3d(1.0 * t, 1.5 * std::sin(0.3 * t), 1.0 + 0.5 * std::cos(0.2 * t));
      if (k == 0) p.p_b_in_G.setZero();
      truth->push_back(p);
      const Eigen::Vector3d noise =
          k == 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
      AddPose(p.stamp_ns, Eigen::Quaterniond::Identity(), q_map_G * p.p_b_in_G + noise,
              covariance_scale * sigma_m * sigma_m * Eigen::Matrix3d::Identity(), scans);
    }
  };
  CovariantTrajectory scans;
  std::vector<PoseStamped> truth;
  make(1.0, &scans, &truth);
  ConsistencyStats s;
  ASSERT_TRUE(EvaluateConsistency(scans, TrajectoryFromPoses(truth), 0.2, &s).ok());
  EXPECT_GT(s.mean_position_nees, 100.0);
  // 600 samples of a chi^2(3): the mean has a std of 0.1; the fit takes 3 dof.
  EXPECT_GT(s.mean_position_nees_aligned, 2.6);
  EXPECT_LT(s.mean_position_nees_aligned, 3.3);
  EXPECT_NEAR(s.gauge_rotation_deg, dtheta.norm() * 180.0 / M_PI, 0.01);

  // Overconfident by 4x: the aligned NEES shows it.
  CovariantTrajectory over;
  std::vector<PoseStamped> truth_over;
  make(0.25, &over, &truth_over);
  ASSERT_TRUE(EvaluateConsistency(over, TrajectoryFromPoses(truth_over), 0.2, &s).ok());
  EXPECT_GT(s.mean_position_nees_aligned, 10.0);
}

TEST(GaugeAlignedNees, AHoverFixesNoRotation) {
  CovariantTrajectory scans;
  std::vector<PoseStamped> truth;
  for (int k = 0; k < 50; ++k) {
    PoseStamped p;
    p.stamp_ns = 1'000'000'000LL + 100'000'000LL * k;
    p.p_b_in_G = Eigen::Vector3d(0.001 * k, 0.0, 0.0);  // 5 cm along one line
    truth.push_back(p);
    AddPose(p.stamp_ns, p.q_G_b, p.p_b_in_G, 1e-4 * Eigen::Matrix3d::Identity(), &scans);
  }
  ConsistencyStats s;
  ASSERT_TRUE(EvaluateConsistency(scans, TrajectoryFromPoses(truth), 0.2, &s).ok());
  EXPECT_TRUE(std::isnan(s.mean_position_nees_aligned));
}

TEST(FrameCheck, NoOverlapIsAnError) {
  CovariantTrajectory scans;
  std::vector<PoseStamped> truth;
  MakeRun(&scans, &truth);
  for (PoseStamped& p : truth) p.stamp_ns += 100'000'000'000LL;
  FrameCheck check;
  EXPECT_EQ(CheckGroundTruthFrame(scans.poses, TrajectoryFromPoses(truth), GroundTruthFrame::kAuto,
                                  FrameCheckOptions(), &check)
                .code(),
            Status::Code::kFailedPrecondition);
}

}  // namespace
}  // namespace swarmlio::eval
