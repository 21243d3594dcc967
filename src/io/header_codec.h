// Decoding of the std_msgs/Header that starts every stamped message.
#pragma once

#include <cstdint>
#include <string>

#include "src/io/ros_message_reader.h"
#include "swarmlio/common/status.h"

namespace swarmlio::io::internal {

/// ROS time (sec, nsec) as integer nanoseconds.
inline int64_t StampNsFromRos(uint32_t sec, uint32_t nsec) {
  return static_cast<int64_t>(sec) * 1000000000LL + static_cast<int64_t>(nsec);
}

/// Reads std_msgs/Header in the reader's encoding: ROS1 (uint32 seq, time
/// stamp, string frame_id) or ROS 2 CDR (int32 sec, uint32 nanosec, string
/// frame_id; a negative sec is DataLoss).
Status ReadRosHeader(RosMessageReader* reader, int64_t* stamp_ns, std::string* frame_id);

}  // namespace swarmlio::io::internal
