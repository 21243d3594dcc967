// livox_ros_driver/CustomMsg <-> LidarScan.
//
// The scan stamp is the header stamp; each point's offset_time [ns] becomes
// offset_time_s (offset_time / 1e9, i.e. relative to the header stamp as in
// FAST-LIO; the driver sets header stamp = timebase). timebase and lidar_id
// are kept in LidarScan::livox_timebase_ns / livox_lidar_id.
#pragma once

#include <cstddef>
#include <cstdint>

#include "src/io/custom_msg.h"
#include "src/io/ros_message_reader.h"
#include "swarmlio/common/status.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::io::internal {

/// Decodes the serialized bytes of one CustomMsg (ROS1, or ROS 2 CDR for
/// livox_ros_driver2/msg/CustomMsg, whose points are each aligned to 4 bytes). point_num must equal
/// the points array length. Points are returned as stored (NaN included).
Status DecodeLivoxCustomMsg(const uint8_t* data,
                            size_t size,
                            LidarScan* scan,
                            WireEncoding encoding = WireEncoding::kRos1);

/// Fills a CustomMsg. offset_time_s must round to [0, 2^32) ns;
/// reflectivity is rounded and clamped to 0..255 (NaN -> 0).
Status EncodeLivoxCustomMsg(const LidarScan& scan, uint32_t seq, LivoxCustomMsg* msg);

}  // namespace swarmlio::io::internal
