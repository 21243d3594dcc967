// Formats of LiDAR logs shared by the sensor presets, the bag reader/writer
// and the simulator: the message type of a scan and the unit of its per-point
// time field (FAST-LIO's `timestamp_unit`).
#pragma once

#include <array>
#include <utility>

#include "swarmlio/common/option_fields.h"

namespace swarmlio {

enum class LidarMessageFormat { kLivoxCustomMsg, kPointCloud2 };
/// Unit of the per-point time field of the incoming message.
enum class TimestampUnit { kSecond, kMillisecond, kMicrosecond, kNanosecond };

/// Ticks of `unit` in one second (exactly 1, 1e3, 1e6 or 1e9).
constexpr double TimestampUnitTicksPerSecond(TimestampUnit unit) {
  switch (unit) {
    case TimestampUnit::kSecond:
      return 1.0;
    case TimestampUnit::kMillisecond:
      return 1e3;
    case TimestampUnit::kMicrosecond:
      return 1e6;
    case TimestampUnit::kNanosecond:
      return 1e9;
  }
  return 1.0;
}

/// Seconds per tick of `unit`.
constexpr double TimestampUnitToSeconds(TimestampUnit unit) {
  switch (unit) {
    case TimestampUnit::kSecond:
      return 1.0;
    case TimestampUnit::kMillisecond:
      return 1e-3;
    case TimestampUnit::kMicrosecond:
      return 1e-6;
    case TimestampUnit::kNanosecond:
      return 1e-9;
  }
  return 1.0;
}

}  // namespace swarmlio

namespace swarmlio::config {

template <>
struct EnumTraits<LidarMessageFormat> {
  static constexpr std::array<std::pair<LidarMessageFormat, const char*>, 2> kNames{{
      {LidarMessageFormat::kLivoxCustomMsg, "livox_custom_msg"},
      {LidarMessageFormat::kPointCloud2, "pointcloud2"},
  }};
};

template <>
struct EnumTraits<TimestampUnit> {
  static constexpr std::array<std::pair<TimestampUnit, const char*>, 4> kNames{{
      {TimestampUnit::kSecond, "s"},
      {TimestampUnit::kMillisecond, "ms"},
      {TimestampUnit::kMicrosecond, "us"},
      {TimestampUnit::kNanosecond, "ns"},
  }};
};

}  // namespace swarmlio::config
