#include "src/io/ros_time.h"

#include <limits>
#include <string>

namespace swarmlio::io::internal {

Status RosTimeFromStampNs(int64_t stamp_ns, ros::Time* time) {
  constexpr int64_t kNsPerS = 1000000000LL;
  const int64_t sec = stamp_ns / kNsPerS;
  if (stamp_ns < 0 || sec > static_cast<int64_t>(std::numeric_limits<uint32_t>::max())) {
    return Status::OutOfRange("stamp " + std::to_string(stamp_ns) +
                              " ns is outside the ROS1 time range [0, 2^32) s");
  }
  time->sec = static_cast<uint32_t>(sec);
  time->nsec = static_cast<uint32_t>(stamp_ns % kNsPerS);
  return Status::Ok();
}

Status BagTimeFromStampNs(int64_t stamp_ns, ros::Time* time) {
  SWARMLIO_RETURN_IF_ERROR(RosTimeFromStampNs(stamp_ns, time));
  if (time->sec == 0 && time->nsec == 0) time->nsec = 1;
  return Status::Ok();
}

}  // namespace swarmlio::io::internal
