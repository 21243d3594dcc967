// Helpers for the io tests: a per-test temporary directory, a raw message
// type that writes arbitrary bytes under any datatype/MD5, ROS
// (de)serialization shortcuts, deterministic sample records and bit-exact
// comparisons.
#pragma once

#include <gtest/gtest.h>
#include <ros/message_traits.h>
#include <ros/serialization.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "swarmlio/io/bag_reader.h"
#include "swarmlio/sensors/measurements.h"
#include "test_utils/temp_dir.h"

namespace swarmlio::io::testing {

using swarmlio::testing::TempDir;

/// A message that serializes to `bytes` verbatim, with any datatype and MD5.
struct RawMessage {
  std::string datatype;
  std::string md5sum;
  std::string definition;
  std::vector<uint8_t> bytes;
};

template <class M>
std::vector<uint8_t> Serialize(const M& msg) {
  std::vector<uint8_t> bytes(ros::serialization::serializationLength(msg));
  ros::serialization::OStream stream(bytes.data(), static_cast<uint32_t>(bytes.size()));
  ros::serialization::serialize(stream, msg);
  return bytes;
}

template <class M>
M Deserialize(std::vector<uint8_t> bytes) {
  M msg;
  ros::serialization::IStream stream(bytes.data(), static_cast<uint32_t>(bytes.size()));
  ros::serialization::deserialize(stream, msg);
  return msg;
}

inline bool BitEqual(float a, float b) { return std::memcmp(&a, &b, sizeof(a)) == 0; }
inline bool BitEqual(double a, double b) { return std::memcmp(&a, &b, sizeof(a)) == 0; }

inline ImuSample MakeImu(int i, int64_t stamp_ns) {
  ImuSample imu;
  imu.stamp_ns = stamp_ns;
  imu.frame_id = "imu_link";
  imu.angular_velocity_rad_s = Eigen::Vector3d(0.01 * i, -0.02 * i + 0.3, std::sin(0.1 * i));
  imu.linear_acceleration = Eigen::Vector3d(0.1 * i - 1.0, 9.81 + 1e-3 * i, std::cos(0.2 * i));
  return imu;
}

/// A scan whose offsets are k / 4096 s: exact in every time unit and type.
inline LidarScan MakeScan(int i, int64_t stamp_ns, int num_points) {
  LidarScan scan;
  scan.stamp_ns = stamp_ns;
  scan.frame_id = "livox_frame";
  for (int k = 0; k < num_points; ++k) {
    LidarPoint p;
    p.x = 1.0f + 0.37f * static_cast<float>(k) + static_cast<float>(i);
    p.y = -2.5f + 0.011f * static_cast<float>(k * k);
    p.z = std::sin(0.3f * static_cast<float>(k)) * 0.7f;
    p.reflectivity = static_cast<float>((k * 37 + i) % 256);
    p.offset_time_s = static_cast<double>(k) / 4096.0;
    p.tag = static_cast<uint8_t>(k % 4 * 16);
    p.line = static_cast<uint8_t>(k % 6);
    scan.points.push_back(p);
  }
  return scan;
}

/// A Livox scan: integer-ns offsets and metadata, as CustomMsg carries them.
inline LidarScan MakeLivoxScan(int i, int64_t stamp_ns, int num_points) {
  LidarScan scan = MakeScan(i, stamp_ns, num_points);
  scan.livox_timebase_ns = static_cast<uint64_t>(stamp_ns) + 17;
  scan.livox_lidar_id = static_cast<uint8_t>(i % 3);
  for (int k = 0; k < num_points; ++k) {
    const uint32_t offset_ns = static_cast<uint32_t>(k) * 10007u + 3u;
    scan.points[k].offset_time_s = static_cast<double>(offset_ns) / 1e9;
  }
  return scan;
}

inline PoseStamped MakePose(int i, int64_t stamp_ns) {
  PoseStamped pose;
  pose.stamp_ns = stamp_ns;
  pose.frame_id = "world";
  pose.p_b_in_G = Eigen::Vector3d(0.5 * i, -0.25 * i, 1.0 + 1e-3 * i);
  pose.q_G_b = Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * i, Eigen::Vector3d::UnitZ()));
  return pose;
}

inline void ExpectImuEqual(const ImuSample& a, const ImuSample& b) {
  EXPECT_EQ(a.stamp_ns, b.stamp_ns);
  EXPECT_EQ(a.frame_id, b.frame_id);
  for (int j = 0; j < 3; ++j) {
    EXPECT_TRUE(BitEqual(a.angular_velocity_rad_s[j], b.angular_velocity_rad_s[j])) << j;
    EXPECT_TRUE(BitEqual(a.linear_acceleration[j], b.linear_acceleration[j])) << j;
  }
}

inline void ExpectPoseEqual(const PoseStamped& a, const PoseStamped& b) {
  EXPECT_EQ(a.stamp_ns, b.stamp_ns);
  EXPECT_EQ(a.frame_id, b.frame_id);
  for (int j = 0; j < 3; ++j) EXPECT_TRUE(BitEqual(a.p_b_in_G[j], b.p_b_in_G[j])) << j;
  for (int j = 0; j < 4; ++j) EXPECT_TRUE(BitEqual(a.q_G_b.coeffs()[j], b.q_G_b.coeffs()[j])) << j;
}

inline void ExpectScanEqual(const LidarScan& a, const LidarScan& b) {
  EXPECT_EQ(a.stamp_ns, b.stamp_ns);
  EXPECT_EQ(a.frame_id, b.frame_id);
  EXPECT_EQ(a.livox_timebase_ns, b.livox_timebase_ns);
  EXPECT_EQ(a.livox_lidar_id, b.livox_lidar_id);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (size_t k = 0; k < a.points.size(); ++k) {
    const LidarPoint& p = a.points[k];
    const LidarPoint& q = b.points[k];
    EXPECT_TRUE(BitEqual(p.x, q.x)) << k;
    EXPECT_TRUE(BitEqual(p.y, q.y)) << k;
    EXPECT_TRUE(BitEqual(p.z, q.z)) << k;
    EXPECT_TRUE(BitEqual(p.reflectivity, q.reflectivity)) << k;
    EXPECT_TRUE(BitEqual(p.offset_time_s, q.offset_time_s))
        << k << ": " << p.offset_time_s << " vs " << q.offset_time_s;
    EXPECT_EQ(p.tag, q.tag) << k;
    EXPECT_EQ(p.line, q.line) << k;
  }
}

/// The same records in the same order, bit for bit.
inline void ExpectSameRecords(const std::vector<BagRecord>& a, const std::vector<BagRecord>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].data.index(), b[i].data.index()) << i;
    if (a[i].imu() != nullptr) ExpectImuEqual(*a[i].imu(), *b[i].imu());
    if (a[i].scan() != nullptr) ExpectScanEqual(*a[i].scan(), *b[i].scan());
    if (a[i].ground_truth() != nullptr) {
      ExpectPoseEqual(*a[i].ground_truth(), *b[i].ground_truth());
    }
  }
}

}  // namespace swarmlio::io::testing

namespace ros {
namespace message_traits {

template <>
struct IsMessage<swarmlio::io::testing::RawMessage> : TrueType {};

template <>
struct MD5Sum<swarmlio::io::testing::RawMessage> {
  static const char* value(const swarmlio::io::testing::RawMessage& m) { return m.md5sum.c_str(); }
};
template <>
struct DataType<swarmlio::io::testing::RawMessage> {
  static const char* value(const swarmlio::io::testing::RawMessage& m) {
    return m.datatype.c_str();
  }
};
template <>
struct Definition<swarmlio::io::testing::RawMessage> {
  static const char* value(const swarmlio::io::testing::RawMessage& m) {
    return m.definition.c_str();
  }
};

}  // namespace message_traits

namespace serialization {

template <>
struct Serializer<swarmlio::io::testing::RawMessage> {
  template <typename Stream>
  inline static void write(Stream& stream, const swarmlio::io::testing::RawMessage& m) {
    if (!m.bytes.empty())
      std::memcpy(stream.advance(m.bytes.size()), m.bytes.data(), m.bytes.size());
  }
  inline static uint32_t serializedLength(const swarmlio::io::testing::RawMessage& m) {
    return static_cast<uint32_t>(m.bytes.size());
  }
};

}  // namespace serialization
}  // namespace ros
