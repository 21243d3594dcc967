// sensor_msgs/Imu <-> ImuSample (IMU frame; rates rad/s, acceleration as the
// device reports it). Orientation and covariances are not part of ImuSample:
// they are ignored when reading and written as "no orientation".
#pragma once

#include <sensor_msgs/Imu.h>

#include <cstddef>
#include <cstdint>

#include "src/io/ros_message_reader.h"
#include "swarmlio/common/status.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::io::internal {

/// Decodes the serialized bytes of one sensor_msgs/Imu (ROS1) or
/// sensor_msgs/msg/Imu (ROS 2 CDR): the same fields, the same record.
Status DecodeImu(const uint8_t* data,
                 size_t size,
                 ImuSample* imu,
                 WireEncoding encoding = WireEncoding::kRos1);

/// Fills a sensor_msgs/Imu; orientation_covariance[0] = -1 marks the
/// orientation as unknown.
Status EncodeImu(const ImuSample& imu, uint32_t seq, sensor_msgs::Imu* msg);

}  // namespace swarmlio::io::internal
