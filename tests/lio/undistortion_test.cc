#include "swarmlio/lio/undistortion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/math/so3.h"
#include "tests/test_utils/helix_trajectory.h"

namespace swarmlio::lio {
namespace {

constexpr int64_t kImuPeriodNs = 5'000'000;    // 200 Hz
constexpr int64_t kImuPhaseNs = 1'300'000;     // IMU grid offset from the scan grid
constexpr int64_t kScanStartNs = 500'000'000;  // 0.5 s
constexpr int64_t kScanEndNs = 600'000'000;    // 10 Hz scan

using swarmlio::testing::Helix;


struct Extrinsic {
  Eigen::Matrix3d R_imu_lidar = so3::Exp(Eigen::Vector3d(0.1, -0.2, 0.3));
  Eigen::Vector3d p_lidar_in_imu{0.05, -0.02, 0.10};
};

// Scan poses from the propagator fed with noise-free IMU from the true state.
std::vector<ImuPose> PropagatedPoses(const Helix& helix) {
  std::unique_ptr<ImuPropagator> prop;
  EXPECT_TRUE(ImuPropagator::Create(ImuPropagatorOptions(), &prop).ok());
  // Last IMU sample at or before the scan start.
  int64_t k = (kScanStartNs - kImuPhaseNs) / kImuPeriodNs;
  const int64_t first_ns = k * kImuPeriodNs + kImuPhaseNs;
  SwarmState x0;
  x0.ego = helix.State(ToSeconds(first_ns));
  EXPECT_TRUE(
      prop->Reset(x0, 1e-6 * Eigen::MatrixXd::Identity(18, 18), helix.Sample(first_ns), 1.0).ok());
  for (++k; k * kImuPeriodNs + kImuPhaseNs <= kScanEndNs; ++k) {
    EXPECT_TRUE(prop->AddImu(helix.Sample(k * kImuPeriodNs + kImuPhaseNs)).ok());
  }
  const ImuSample next = helix.Sample(k * kImuPeriodNs + kImuPhaseNs);  // first after the end
  EXPECT_TRUE(prop->PropagateTo(kScanEndNs, &next).ok());
  return prop->scan_poses();
}

// World points seen from the moving LiDAR at random times of the scan.
LidarScan SyntheticScan(const Helix& helix,
                        const Extrinsic& ext,
                        int n,
                        std::mt19937& rng,
                        std::vector<Eigen::Vector3d>* world_points) {
  std::uniform_real_distribution<double> time_s(0.0, ToSeconds(kScanEndNs - kScanStartNs));
  std::uniform_real_distribution<double> range_m(5.0, 20.0);
  std::normal_distribution<double> dir;
  LidarScan scan;
  scan.stamp_ns = kScanStartNs;
  world_points->clear();
  for (int i = 0; i < n; ++i) {
    const double dt = time_s(rng);
    const double t = ToSeconds(kScanStartNs) + dt;
    const Eigen::Matrix3d R_W_L = helix.R(t) * ext.R_imu_lidar;
    const Eigen::Vector3d p_L_in_W = helix.p(t) + helix.R(t) * ext.p_lidar_in_imu;
    const Eigen::Vector3d ray = Eigen::Vector3d(dir(rng), dir(rng), dir(rng)).normalized();
    const Eigen::Vector3d p_in_L = ray * range_m(rng);
    world_points->push_back(R_W_L * p_in_L + p_L_in_W);
    LidarPoint q;
    q.x = static_cast<float>(p_in_L.x());
    q.y = static_cast<float>(p_in_L.y());
    q.z = static_cast<float>(p_in_L.z());
    q.reflectivity = static_cast<float>(i % 256);
    q.offset_time_s = dt;
    q.tag = static_cast<uint8_t>(i % 7);
    q.line = static_cast<uint8_t>(i % 6);
    scan.points.push_back(q);
  }
  return scan;
}

TEST(Undistortion, PointsReturnToTheirWorldPositions) {
  std::mt19937 rng(42);
  const Helix helix;
  const Extrinsic ext;
  std::vector<Eigen::Vector3d> world;
  const LidarScan scan = SyntheticScan(helix, ext, 5000, rng, &world);
  const std::vector<ImuPose> poses = PropagatedPoses(helix);
  ASSERT_EQ(poses.back().stamp_ns, kScanEndNs);
  ASSERT_LE(poses.front().stamp_ns, kScanStartNs);

  std::vector<UndistortedPoint> out;
  UndistortionStats stats;
  ASSERT_TRUE(UndistortScan(scan, poses, ext.R_imu_lidar, ext.p_lidar_in_imu, &out, &stats).ok());
  ASSERT_EQ(out.size(), scan.points.size());
  EXPECT_EQ(stats.num_points, 5000);
  EXPECT_EQ(stats.num_extrapolated, 0);
  EXPECT_EQ(stats.end_stamp_ns, kScanEndNs);

  const double t_end = ToSeconds(kScanEndNs);
  const Eigen::Matrix3d R_end = helix.R(t_end);
  const Eigen::Vector3d p_end = helix.p(t_end);
  double max_err = 0.0, max_err_raw = 0.0;
  for (size_t i = 0; i < out.size(); ++i) {
    const Eigen::Vector3d w = R_end * out[i].p_in_b_end + p_end;
    max_err = std::max(max_err, (w - world[i]).norm());
    // Without compensation: every point taken as measured at the scan end.
    const LidarPoint& q = scan.points[i];
    const Eigen::Vector3d raw_in_b =
        ext.R_imu_lidar * Eigen::Vector3d(q.x, q.y, q.z) + ext.p_lidar_in_imu;
    max_err_raw = std::max(max_err_raw, (R_end * raw_in_b + p_end - world[i]).norm());
    EXPECT_EQ(out[i].reflectivity, q.reflectivity);
    EXPECT_EQ(out[i].offset_time_s, q.offset_time_s);
    EXPECT_EQ(out[i].tag, q.tag);
    EXPECT_EQ(out[i].line, q.line);
  }
  std::printf(
      "[ figures  ] undistortion, %zu points over 0.1 s at 3 m/s, 1.5 rad/s: max error "
      "%.3e m (uncompensated %.3f m)\n",
      out.size(), max_err, max_err_raw);
  EXPECT_LT(max_err, 1e-4);
  EXPECT_GT(max_err_raw, 0.5);
}

TEST(Undistortion, BodyFramePointsGiveTheSameResultAsTheScan) {
  std::mt19937 rng(43);
  const Helix helix;
  const Extrinsic ext;
  std::vector<Eigen::Vector3d> world;
  const LidarScan scan = SyntheticScan(helix, ext, 500, rng, &world);
  const std::vector<ImuPose> poses = PropagatedPoses(helix);
  std::vector<UndistortedPoint> from_scan;
  ASSERT_TRUE(UndistortScan(scan, poses, ext.R_imu_lidar, ext.p_lidar_in_imu, &from_scan).ok());
  std::vector<lio::PointXYZT> in_b;
  for (const LidarPoint& q : scan.points) {
    lio::PointXYZT p;
    p.p_in_b = ext.R_imu_lidar * Eigen::Vector3d(q.x, q.y, q.z) + ext.p_lidar_in_imu;
    p.time_s = q.offset_time_s;
    in_b.push_back(p);
  }
  lio::PointXYZT bad;
  bad.p_in_b.x() = std::numeric_limits<double>::quiet_NaN();
  in_b.push_back(bad);
  std::vector<Eigen::Vector3d> out;
  UndistortionStats stats;
  ASSERT_TRUE(UndistortPoints(in_b, scan.stamp_ns, poses, &out, &stats).ok());
  ASSERT_EQ(out.size(), from_scan.size());
  EXPECT_EQ(stats.num_skipped_non_finite, 1);
  for (size_t i = 0; i < out.size(); ++i) {
    EXPECT_LT((out[i] - from_scan[i].p_in_b_end).norm(), 1e-12);
  }
  EXPECT_EQ(UndistortPoints(in_b, scan.stamp_ns, {}, &out).code(),
            Status::Code::kFailedPrecondition);
}

TEST(Undistortion, BodyPoseAtMatchesThePosesAtTheirStamps) {
  const Helix helix;
  const std::vector<ImuPose> poses = PropagatedPoses(helix);
  for (const ImuPose& pose : poses) {
    Eigen::Matrix3d R;
    Eigen::Vector3d p;
    BodyPoseAt(poses, pose.stamp_ns, 0.0, &R, &p);
    EXPECT_LT((p - pose.p_b_in_G).norm(), 1e-12);
    EXPECT_LT(so3::Log(R.transpose() * pose.R_G_b).norm(), 1e-12);
  }
  // The piecewise model reaches the next pose from the previous one.
  for (size_t i = 0; i + 1 < poses.size(); ++i) {
    Eigen::Matrix3d R;
    Eigen::Vector3d p;
    const double dt = ToSeconds(poses[i + 1].stamp_ns - poses[i].stamp_ns);
    const std::vector<ImuPose> one{poses[i]};
    BodyPoseAt(one, poses[i].stamp_ns, dt, &R, &p);
    EXPECT_LT((p - poses[i + 1].p_b_in_G).norm(), 1e-12);
    EXPECT_LT(so3::Log(R.transpose() * poses[i + 1].R_G_b).norm(), 1e-12);
  }
}

TEST(Undistortion, CountsExtrapolatedAndSkipsNonFinitePoints) {
  std::mt19937 rng(3);
  const Helix helix;
  const Extrinsic ext;
  std::vector<Eigen::Vector3d> world;
  LidarScan scan = SyntheticScan(helix, ext, 10, rng, &world);
  scan.points[0].offset_time_s = -0.02;  // before the first pose
  scan.points[1].offset_time_s = 0.2;    // after the scan end
  scan.points[2].x = std::numeric_limits<float>::quiet_NaN();
  std::vector<UndistortedPoint> out;
  UndistortionStats stats;
  ASSERT_TRUE(
      UndistortScan(scan, PropagatedPoses(helix), ext.R_imu_lidar, ext.p_lidar_in_imu, &out, &stats)
          .ok());
  EXPECT_EQ(stats.num_points, 9);
  EXPECT_EQ(stats.num_extrapolated, 2);
  EXPECT_EQ(stats.num_skipped_non_finite, 1);
  EXPECT_EQ(out.size(), 9u);
}

TEST(Undistortion, RejectsMissingOrUnsortedPoses) {
  LidarScan scan;
  scan.points.resize(3);
  std::vector<UndistortedPoint> out;
  EXPECT_EQ(
      UndistortScan(scan, {}, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), &out).code(),
      Status::Code::kFailedPrecondition);
  std::vector<ImuPose> poses(2);
  poses[0].stamp_ns = 10;
  poses[1].stamp_ns = 5;
  EXPECT_EQ(
      UndistortScan(scan, poses, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), &out).code(),
      Status::Code::kInvalidArgument);
}

}  // namespace
}  // namespace swarmlio::lio
