// Our definition of the Livox ROS driver's livox_ros_driver/CustomMsg, wire
// compatible with the driver (same datatype, MD5 and full definition text),
// so bags we write play in any ROS1 tool without the Livox driver installed.
//
// Wire layout (little endian): std_msgs/Header header, uint64 timebase [ns],
// uint32 point_num, uint8 lidar_id, uint8[3] rsvd, CustomPoint[] points with
// 19-byte points: uint32 offset_time [ns], float32 x y z [m], uint8
// reflectivity, uint8 tag, uint8 line.
#pragma once

#include <ros/message_traits.h>
#include <ros/serialization.h>
#include <std_msgs/Header.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace swarmlio::io::internal {

inline constexpr char kLivoxCustomMsgDataType[] = "livox_ros_driver/CustomMsg";
inline constexpr char kLivoxCustomMsgMd5[] = "e4d6829bdfe657cb6c21a746c86b21a6";
inline constexpr char kLivoxCustomPointDataType[] = "livox_ros_driver/CustomPoint";
inline constexpr char kLivoxCustomPointMd5[] = "109a3cc548bb1f96626be89a5008bd6d";
inline constexpr size_t kLivoxCustomPointBytes = 19;

/// One Livox return in the LiDAR frame.
struct LivoxCustomPoint {
  uint32_t offset_time = 0;  // [ns] relative to the scan
  float x = 0.f;             // [m]
  float y = 0.f;             // [m]
  float z = 0.f;             // [m]
  uint8_t reflectivity = 0;  // 0-255
  uint8_t tag = 0;
  uint8_t line = 0;
};

/// One Livox frame.
struct LivoxCustomMsg {
  std_msgs::Header header;
  uint64_t timebase = 0;  // [ns] time of the first point
  uint32_t point_num = 0;
  uint8_t lidar_id = 0;
  std::array<uint8_t, 3> rsvd{};
  std::vector<LivoxCustomPoint> points;
};

/// The genmsg-style full definition: the CustomMsg text, then "MSG:"
/// sections for std_msgs/Header and livox_ros_driver/CustomPoint, each after
/// a line of 80 '='.
const std::string& LivoxCustomMsgDefinition();

/// The definition of CustomPoint alone.
const std::string& LivoxCustomPointDefinition();

}  // namespace swarmlio::io::internal

namespace ros {
namespace message_traits {

template <>
struct IsMessage<swarmlio::io::internal::LivoxCustomMsg> : TrueType {};
template <>
struct HasHeader<swarmlio::io::internal::LivoxCustomMsg> : TrueType {};

template <>
struct MD5Sum<swarmlio::io::internal::LivoxCustomMsg> {
  static const char* value() { return swarmlio::io::internal::kLivoxCustomMsgMd5; }
  static const char* value(const swarmlio::io::internal::LivoxCustomMsg&) { return value(); }
};
template <>
struct DataType<swarmlio::io::internal::LivoxCustomMsg> {
  static const char* value() { return swarmlio::io::internal::kLivoxCustomMsgDataType; }
  static const char* value(const swarmlio::io::internal::LivoxCustomMsg&) { return value(); }
};
template <>
struct Definition<swarmlio::io::internal::LivoxCustomMsg> {
  static const char* value() { return swarmlio::io::internal::LivoxCustomMsgDefinition().c_str(); }
  static const char* value(const swarmlio::io::internal::LivoxCustomMsg&) { return value(); }
};

}  // namespace message_traits

namespace serialization {

template <>
struct Serializer<swarmlio::io::internal::LivoxCustomMsg> {
  template <typename Stream, typename Msg>
  inline static void allInOne(Stream& stream, Msg& m) {
    stream.next(m.header);
    stream.next(m.timebase);
    stream.next(m.point_num);
    stream.next(m.lidar_id);
    for (auto& byte : m.rsvd) stream.next(byte);
  }

  template <typename Stream>
  inline static void write(Stream& stream, const swarmlio::io::internal::LivoxCustomMsg& m) {
    allInOne(stream, m);
    stream.next(static_cast<uint32_t>(m.points.size()));
    for (const auto& p : m.points) {
      stream.next(p.offset_time);
      stream.next(p.x);
      stream.next(p.y);
      stream.next(p.z);
      stream.next(p.reflectivity);
      stream.next(p.tag);
      stream.next(p.line);
    }
  }

  // Used by tests only (the reader has its own bounds-checked decoder). The
  // IStream throws on overrun; the count is checked before resizing.
  template <typename Stream>
  inline static void read(Stream& stream, swarmlio::io::internal::LivoxCustomMsg& m) {
    allInOne(stream, m);
    uint32_t n = 0;
    stream.next(n);
    if (static_cast<uint64_t>(n) * swarmlio::io::internal::kLivoxCustomPointBytes >
        stream.getLength()) {
      throw StreamOverrunException("CustomMsg points length exceeds the buffer");
    }
    m.points.resize(n);
    for (auto& p : m.points) {
      stream.next(p.offset_time);
      stream.next(p.x);
      stream.next(p.y);
      stream.next(p.z);
      stream.next(p.reflectivity);
      stream.next(p.tag);
      stream.next(p.line);
    }
  }

  inline static uint32_t serializedLength(const swarmlio::io::internal::LivoxCustomMsg& m) {
    return serializationLength(m.header) + 8 + 4 + 1 + 3 + 4 +
           static_cast<uint32_t>(m.points.size() * swarmlio::io::internal::kLivoxCustomPointBytes);
  }
};

}  // namespace serialization
}  // namespace ros
