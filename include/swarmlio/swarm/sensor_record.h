// SensorRecord: one input of a drone's component (DroneEstimator::Add): an
// IMU sample or a LiDAR scan (stamped on the drone's clock), or a message
// received from a teammate (its arrival time on the drone's clock). Every
// driver (the offline replay, the live process, the ROS node, the tests)
// hands its inputs over as these records, through driver::DroneDriver.
#pragma once

#include <cstdint>
#include <variant>

#include "swarmlio/net/message_channel.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::swarm {

using SensorRecord = std::variant<ImuSample, LidarScan, net::ReceivedMessage>;

/// The record's stamp: the sample's, the scan's, or the message's arrival [ns].
inline int64_t StampOf(const SensorRecord& record) {
  if (const auto* imu = std::get_if<ImuSample>(&record)) return imu->stamp_ns;
  if (const auto* scan = std::get_if<LidarScan>(&record)) return scan->stamp_ns;
  return std::get<net::ReceivedMessage>(record).arrival_ns;
}

}  // namespace swarmlio::swarm
