// Ground-truth trajectories from ROS1 bags (geometry_msgs/PoseStamped or
// nav_msgs/Odometry).
#pragma once

#include <string>

#include "swarmlio/common/status.h"
#include "swarmlio/eval/trajectory.h"
#include "swarmlio/io/bag_options.h"

namespace swarmlio::eval {

/// Reads every pose on options.ground_truth_topic of the bag at `path` into a
/// stamped trajectory (stamps = ToSeconds(header stamp), T_G_b from the
/// pose). BagReader needs IMU and LiDAR topics (found by type when the
/// configured ones are absent or "auto"); its per-point time check is turned
/// off (scans are not used), its pose checks drop non-finite and
/// non-increasing poses (counted in its stats). A truncated or unindexed bag
/// gives the poses before the damage. Errors: the bag cannot be read, the
/// topic is absent or empty.
Status ReadBagGroundTruth(const std::string& path,
                          const io::BagReaderOptions& options,
                          Trajectory* trajectory);

}  // namespace swarmlio::eval
