// Conversions between integer-nanosecond stamps and ros::Time.
#pragma once

#include <ros/time.h>

#include <cstdint>

#include "swarmlio/common/status.h"

namespace swarmlio::io::internal {

/// Converts stamp_ns to ros::Time; fails outside [0, 2^32) s.
Status RosTimeFromStampNs(int64_t stamp_ns, ros::Time* time);

/// Like RosTimeFromStampNs but maps 0 to 1 ns: rosbag refuses a record time
/// below ros::TIME_MIN.
Status BagTimeFromStampNs(int64_t stamp_ns, ros::Time* time);

/// ros::Time as integer nanoseconds.
inline int64_t StampNsFromRosTime(const ros::Time& time) {
  return static_cast<int64_t>(time.sec) * 1000000000LL + static_cast<int64_t>(time.nsec);
}

}  // namespace swarmlio::io::internal
