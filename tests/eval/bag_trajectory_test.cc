#include "swarmlio/eval/bag_trajectory.h"

#include <gtest/gtest.h>

#include <memory>

#include "swarmlio/io/bag_writer.h"
#include "tests/eval/eval_test_util.h"

namespace swarmlio::eval {
namespace {

// A bag with IMU samples, one scan and `num_poses` ground-truth poses.
void WriteBag(const std::string& path,
              int num_poses,
              const io::BagWriterOptions& options = io::BagWriterOptions()) {
  std::unique_ptr<io::BagWriter> writer;
  ASSERT_TRUE(io::BagWriter::Open(path, options, &writer).ok());
  const int64_t t0_ns = 2000000000;
  LidarScan scan;
  scan.stamp_ns = t0_ns;
  scan.frame_id = "livox_frame";
  scan.points.resize(3);
  for (int k = 0; k < 3; ++k) scan.points[k].x = 1.0f + static_cast<float>(k);
  ASSERT_TRUE(writer->WriteScan(scan).ok());
  for (int i = 0; i < 20; ++i) {
    ImuSample imu;
    imu.stamp_ns = t0_ns + i * 5000000LL;
    imu.linear_acceleration = Eigen::Vector3d(0, 0, 9.81);
    ASSERT_TRUE(writer->WriteImu(imu).ok());
  }
  for (int i = 0; i < num_poses; ++i) {
    PoseStamped pose;
    pose.stamp_ns = t0_ns + i * 10000000LL + 7;
    pose.frame_id = "world";
    pose.p_b_in_G = Eigen::Vector3d(0.5 * i, -0.25 * i, 1.0);
    pose.q_G_b = Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d::UnitZ()));
    ASSERT_TRUE(writer->WriteGroundTruth(pose).ok());
  }
  ASSERT_TRUE(writer->Close().ok());
}

TEST(BagGroundTruth, ReadsThePoses) {
  testing::TempDir dir;
  const std::string path = dir.File("run.bag");
  WriteBag(path, 6);
  Trajectory trajectory;
  const Status status = ReadBagGroundTruth(path, io::BagReaderOptions(), &trajectory);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(trajectory.size(), 6u);
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(trajectory.stamps_s[i], ToSeconds(2000000000 + i * 10000000LL + 7));
    EXPECT_EQ(trajectory.T_G_b[i].translation(), Eigen::Vector3d(0.5 * i, -0.25 * i, 1.0));
    EXPECT_NEAR(Eigen::AngleAxisd(trajectory.T_G_b[i].linear()).angle(), 0.1 * i, 1e-12);
  }
}

TEST(BagGroundTruth, ReadsOdometryOnOtherTopics) {
  testing::TempDir dir;
  const std::string path = dir.File("odom.bag");
  io::BagWriterOptions writer_options;
  writer_options.imu_topic = "/mavros/imu/data";
  writer_options.lidar_topic = "/os_cloud_node/points";
  writer_options.ground_truth_topic = "/vicon/uav1/odom";
  writer_options.ground_truth_format = io::GroundTruthFormat::kOdometry;
  WriteBag(path, 5, writer_options);
  io::BagReaderOptions options;
  options.ground_truth_topic = "auto";  // IMU and LiDAR: defaults, absent, found by type
  Trajectory trajectory;
  const Status status = ReadBagGroundTruth(path, options, &trajectory);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(trajectory.size(), 5u);
  EXPECT_EQ(trajectory.stamps_s[4], ToSeconds(2000000000 + 4 * 10000000LL + 7));
  EXPECT_EQ(trajectory.T_G_b[4].translation(), Eigen::Vector3d(2.0, -1.0, 1.0));
}

TEST(BagGroundTruth, Errors) {
  testing::TempDir dir;
  Trajectory trajectory;
  EXPECT_FALSE(
      ReadBagGroundTruth(dir.File("missing.bag"), io::BagReaderOptions(), &trajectory).ok());
  const std::string path = dir.File("run.bag");
  WriteBag(path, 3);
  io::BagReaderOptions options;
  options.ground_truth_topic = "/other/pose";
  const Status status = ReadBagGroundTruth(path, options, &trajectory);
  EXPECT_EQ(status.code(), Status::Code::kNotFound);
  EXPECT_NE(status.message().find("/other/pose"), std::string::npos) << status.message();
  const std::string no_poses = dir.File("empty.bag");
  WriteBag(no_poses, 0);
  EXPECT_FALSE(ReadBagGroundTruth(no_poses, io::BagReaderOptions(), &trajectory).ok());
}

}  // namespace
}  // namespace swarmlio::eval
