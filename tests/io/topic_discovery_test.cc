// Topic discovery by message type: IMU and LiDAR topics left "auto"/"" or
// configured but absent are found when exactly one topic has a matching
// type; otherwise the error lists the candidates and names the option.
// Ground truth as nav_msgs/Odometry.
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>

#include <memory>
#include <string>
#include <vector>

#include "src/io/custom_msg.h"
#include "src/io/custom_msg_codec.h"
#include "src/io/imu_codec.h"
#include "src/io/odometry_msg.h"
#include "src/io/pointcloud2_codec.h"
#include "src/io/pose_codec.h"
#include "tests/io/bag_test_util.h"
#include "tests/io/io_test_util.h"

namespace swarmlio::io {
namespace {

using testing::MakeImu;
using testing::MakeLivoxScan;
using testing::MakePose;
using testing::MakeScan;
using testing::ReadAll;
using testing::Select;
using testing::TempDir;

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

ros::Time T(int64_t ns) {
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(ns));
  return t;
}

enum class Kind { kImu, kCustomMsg, kPointCloud2, kPoseStamped, kOdometry };

struct TopicSpec {
  std::string topic;
  Kind kind;
};

// Writes 5 messages per topic, 0.1 s apart, starting at 1 s.
void WriteTopics(const std::string& path, const std::vector<TopicSpec>& topics) {
  rosbag::Bag bag;
  bag.open(path, rosbag::bagmode::Write);
  for (int i = 0; i < 5; ++i) {
    const int64_t stamp = 1000000000 + i * 100000000LL;
    for (const TopicSpec& spec : topics) {
      switch (spec.kind) {
        case Kind::kImu: {
          sensor_msgs::Imu msg;
          ASSERT_TRUE(internal::EncodeImu(MakeImu(i, stamp), i, &msg).ok());
          bag.write(spec.topic, T(stamp), msg);
          break;
        }
        case Kind::kCustomMsg: {
          internal::LivoxCustomMsg msg;
          ASSERT_TRUE(internal::EncodeLivoxCustomMsg(MakeLivoxScan(i, stamp, 8), i, &msg).ok());
          bag.write(spec.topic, T(stamp), msg);
          break;
        }
        case Kind::kPointCloud2: {
          sensor_msgs::PointCloud2 msg;
          ASSERT_TRUE(internal::EncodePointCloud2(MakeScan(i, stamp, 8), i,
                                                  TimestampUnit::kMicrosecond, "time", &msg)
                          .ok());
          bag.write(spec.topic, T(stamp), msg);
          break;
        }
        case Kind::kPoseStamped: {
          geometry_msgs::PoseStamped msg;
          ASSERT_TRUE(internal::EncodePoseStamped(MakePose(i, stamp), i, &msg).ok());
          bag.write(spec.topic, T(stamp), msg);
          break;
        }
        case Kind::kOdometry: {
          internal::NavOdometry msg;
          ASSERT_TRUE(internal::EncodeOdometry(MakePose(i, stamp), i, &msg).ok());
          bag.write(spec.topic, T(stamp), msg);
          break;
        }
      }
    }
  }
  bag.close();
}

BagReaderOptions AutoTopics() {
  BagReaderOptions options;
  options.imu_topic = "auto";
  options.lidar_topic = "";
  options.ground_truth_topic = "auto";
  return options;
}

TEST(TopicDiscoveryTest, FindsTheOnlyTopicOfEachType) {
  TempDir dir;
  const std::string path = dir.File("ouster.bag");
  WriteTopics(path, {{"/os_cloud_node/imu", Kind::kImu},
                     {"/os_cloud_node/points", Kind::kPointCloud2},
                     {"/vrpn_client_node/uav1/pose", Kind::kPoseStamped}});
  std::unique_ptr<BagReader> reader;
  ASSERT_TRUE(BagReader::Open(path, AutoTopics(), &reader).ok());
  EXPECT_EQ(reader->imu_topic(), "/os_cloud_node/imu");
  EXPECT_EQ(reader->lidar_topic(), "/os_cloud_node/points");
  EXPECT_EQ(reader->lidar_message_type(), LidarMessageType::kPointCloud2);
  EXPECT_EQ(reader->ground_truth_topic(), "/vrpn_client_node/uav1/pose");
  EXPECT_EQ(reader->ground_truth_message_type(), GroundTruthMessageType::kPoseStamped);

  // The defaults (/livox/imu, /livox/lidar) are absent: found by type too;
  // the absent default ground-truth topic means no ground truth.
  std::vector<BagRecord> records;
  ReadStats stats;
  const Status status = ReadAll(path, BagReaderOptions(), &records, &stats);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(stats.imu_samples, 5);
  EXPECT_EQ(stats.scans, 5);
  EXPECT_EQ(stats.ground_truth_poses, 0);
  testing::ExpectScanEqual(Select<LidarScan>(records)[2], MakeScan(2, 1200000000, 8));
}

TEST(TopicDiscoveryTest, TheLidarFormatFollowsTheFoundTopicsType) {
  TempDir dir;
  for (const char* type : {"livox_ros_driver/CustomMsg", "livox_ros_driver2/CustomMsg"}) {
    const std::string path = dir.File("livox.bag");
    {
      rosbag::Bag bag;
      bag.open(path, rosbag::bagmode::Write);
      sensor_msgs::Imu imu;
      ASSERT_TRUE(internal::EncodeImu(MakeImu(0, 5), 0, &imu).ok());
      bag.write("/imu", T(5), imu);
      internal::LivoxCustomMsg msg;
      ASSERT_TRUE(internal::EncodeLivoxCustomMsg(MakeLivoxScan(0, 10, 4), 0, &msg).ok());
      testing::RawMessage raw;
      raw.datatype = type;
      raw.md5sum = internal::kLivoxCustomMsgMd5;
      raw.definition = internal::LivoxCustomMsgDefinition();
      raw.bytes = testing::Serialize(msg);
      bag.write("/avia/points", T(10), raw);
      bag.close();
    }
    std::vector<BagRecord> records;
    const Status status = ReadAll(path, AutoTopics(), &records);
    ASSERT_TRUE(status.ok()) << type << ": " << status.message();
    const auto scans = Select<LidarScan>(records);
    ASSERT_EQ(scans.size(), 1u);
    testing::ExpectScanEqual(scans[0], MakeLivoxScan(0, 10, 4));
  }
}

TEST(TopicDiscoveryTest, AConfiguredTopicThatExistsWins) {
  TempDir dir;
  const std::string path = dir.File("two_imus.bag");
  WriteTopics(path, {{"/imu0", Kind::kImu}, {"/imu1", Kind::kImu}, {"/lidar", Kind::kCustomMsg}});
  BagReaderOptions options;
  options.imu_topic = "/imu1";
  std::unique_ptr<BagReader> reader;
  const Status status = BagReader::Open(path, options, &reader);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(reader->imu_topic(), "/imu1");
  EXPECT_EQ(reader->lidar_topic(), "/lidar");
}

TEST(TopicDiscoveryTest, SeveralCandidatesAreListedWithTheOptionToSet) {
  TempDir dir;
  const std::string path = dir.File("ambiguous.bag");
  WriteTopics(path, {{"/imu0", Kind::kImu},
                     {"/imu1", Kind::kImu},
                     {"/livox/lidar_raw", Kind::kCustomMsg},
                     {"/livox/points", Kind::kPointCloud2},
                     {"/gt/odom", Kind::kOdometry},
                     {"/gt/pose", Kind::kPoseStamped}});
  std::unique_ptr<BagReader> reader;
  Status status = BagReader::Open(path, AutoTopics(), &reader);
  EXPECT_EQ(status.code(), Status::Code::kNotFound);
  EXPECT_TRUE(Contains(status.message(), path)) << status.message();
  EXPECT_TRUE(Contains(status.message(), "imu_topic is 'auto'")) << status.message();
  EXPECT_TRUE(Contains(status.message(),
                       "2 topics have type sensor_msgs/Imu: "
                       "/imu0 [sensor_msgs/Imu], /imu1 [sensor_msgs/Imu]; "
                       "set imu_topic to one of them"))
      << status.message();

  BagReaderOptions options = AutoTopics();
  options.imu_topic = "/imu0";
  options.lidar_topic = "/velodyne_points";  // absent
  status = BagReader::Open(path, options, &reader);
  EXPECT_EQ(status.code(), Status::Code::kNotFound);
  EXPECT_TRUE(Contains(status.message(), "lidar_topic '/velodyne_points' not found"))
      << status.message();
  EXPECT_TRUE(Contains(status.message(),
                       "/livox/lidar_raw [livox_ros_driver/CustomMsg], "
                       "/livox/points [sensor_msgs/PointCloud2]; set "
                       "lidar_topic to one of them"))
      << status.message();

  options.lidar_topic = "/livox/points";
  status = BagReader::Open(path, options, &reader);
  EXPECT_TRUE(Contains(status.message(), "ground_truth_topic")) << status.message();
  EXPECT_TRUE(Contains(status.message(),
                       "/gt/odom [nav_msgs/Odometry], "
                       "/gt/pose [geometry_msgs/PoseStamped]"))
      << status.message();
  options.ground_truth_topic = "/gt/odom";
  ASSERT_TRUE(BagReader::Open(path, options, &reader).ok());
  EXPECT_EQ(reader->ground_truth_message_type(), GroundTruthMessageType::kOdometry);
}

TEST(TopicDiscoveryTest, NoCandidateListsTheBagsTopics) {
  TempDir dir;
  const std::string path = dir.File("no_imu.bag");
  WriteTopics(path, {{"/lidar", Kind::kPointCloud2}, {"/pose", Kind::kPoseStamped}});
  std::unique_ptr<BagReader> reader;
  const Status status = BagReader::Open(path, AutoTopics(), &reader);
  EXPECT_EQ(status.code(), Status::Code::kNotFound);
  EXPECT_TRUE(Contains(status.message(), "no topic has type sensor_msgs/Imu")) << status.message();
  EXPECT_TRUE(Contains(status.message(),
                       "the bag has topics: /lidar [sensor_msgs/PointCloud2], "
                       "/pose [geometry_msgs/PoseStamped]"))
      << status.message();
}

TEST(TopicDiscoveryTest, AnAbsentGroundTruthTopicIsNotReplacedSilently) {
  TempDir dir;
  const std::string path = dir.File("odom.bag");
  WriteTopics(path,
              {{"/imu", Kind::kImu}, {"/lidar", Kind::kCustomMsg}, {"/odom", Kind::kOdometry}});
  std::unique_ptr<BagReader> reader;
  ASSERT_TRUE(BagReader::Open(path, BagReaderOptions(), &reader).ok());
  EXPECT_FALSE(reader->has_ground_truth());  // /odom may be an estimate
  ASSERT_TRUE(BagReader::Open(path, AutoTopics(), &reader).ok());
  EXPECT_EQ(reader->ground_truth_topic(), "/odom");
}

TEST(TopicDiscoveryTest, OdometryGroundTruthIsRead) {
  TempDir dir;
  const std::string path = dir.File("odom_gt.bag");
  BagWriterOptions writer_options;
  writer_options.ground_truth_format = GroundTruthFormat::kOdometry;
  writer_options.ground_truth_topic = "/mocap/odom";
  testing::WriteSimpleBag(path, writer_options, 60);
  BagReaderOptions options;
  options.ground_truth_topic = "/mocap/odom";
  std::vector<BagRecord> records;
  ReadStats stats;
  const Status status = ReadAll(path, options, &records, &stats);
  ASSERT_TRUE(status.ok()) << status.message();
  const auto poses = Select<PoseStamped>(records);
  ASSERT_EQ(poses.size(), 6u);
  for (size_t k = 0; k < poses.size(); ++k) {
    const int i = static_cast<int>(10 * k);
    testing::ExpectPoseEqual(poses[k], MakePose(i, 1000000000 + i * 5000000LL));
  }

  // Right type name, wrong MD5: not our definition.
  const std::string fake = dir.File("fake_odom.bag");
  {
    rosbag::Bag bag;
    bag.open(fake, rosbag::bagmode::Write);
    sensor_msgs::Imu imu;
    bag.write("/livox/imu", T(5), imu);
    internal::LivoxCustomMsg scan;
    bag.write("/livox/lidar", T(5), scan);
    testing::RawMessage raw;
    raw.datatype = "nav_msgs/Odometry";
    raw.md5sum = "0123456789abcdef0123456789abcdef";
    bag.write("/ground_truth/pose", T(5), raw);
    bag.close();
  }
  std::unique_ptr<BagReader> reader;
  const Status wrong = BagReader::Open(fake, BagReaderOptions(), &reader);
  EXPECT_EQ(wrong.code(), Status::Code::kInvalidArgument);
  EXPECT_TRUE(Contains(wrong.message(), "MD5")) << wrong.message();
}

}  // namespace
}  // namespace swarmlio::io
