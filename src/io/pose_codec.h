// geometry_msgs/PoseStamped <-> PoseStamped (body frame b in global frame G).
#pragma once

#include <geometry_msgs/PoseStamped.h>

#include <cstddef>
#include <cstdint>

#include "swarmlio/common/status.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::io::internal {

/// Decodes the serialized bytes of one geometry_msgs/PoseStamped. The
/// quaternion is taken as stored (not normalized).
Status DecodePoseStamped(const uint8_t* data, size_t size, PoseStamped* pose);

Status EncodePoseStamped(const PoseStamped& pose, uint32_t seq, geometry_msgs::PoseStamped* msg);

}  // namespace swarmlio::io::internal
