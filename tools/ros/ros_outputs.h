// RosOutputs: what the ROS node publishes (a live::LiveSink, called on the
// estimator thread; docs/online.md "ROS node"). Topics in the node's
// private namespace (~), frames as options:
//   ~odometry           nav_msgs/Odometry per scan end: pose of body in world
//                       (the drone's global frame G), velocity in body
//   ~odometry_imu       nav_msgs/Odometry at every IMU sample (propagated)
//   ~path               nav_msgs/Path of the scan-end poses (the last max_path_poses)
//   ~cloud_registered   sensor_msgs/PointCloud2: the scan's points in world
//   ~local_map          sensor_msgs/PointCloud2: the odometry's map, throttled
//   ~teammates/<name>/odometry  nav_msgs/Odometry of each identified teammate,
//                       in this drone's world frame
//   ~teammate_markers   visualization_msgs/MarkerArray: a sphere and a label
//                       per teammate
//   /tf                 world -> body at every scan end (tf2_msgs/TFMessage)
// Stamps are the estimator's sensor stamps (ROS time for the node).
#pragma once

#include <nav_msgs/Path.h>
#include <ros/ros.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "swarmlio/live/clock.h"
#include "swarmlio/live/live_drone.h"
#include "swarmlio/live/live_sink.h"

namespace swarmlio::tools {

struct RosOutputOptions {
  std::string world_frame = "world";   // the drone's global frame G
  std::string body_frame = "body";     // the IMU/body frame b
  double local_map_period_s = 1.0;     // publish the local map this often [s sensor time];
                                       // 0 = never
  int max_path_poses = 3000;           // ~path keeps the last poses (5 min at 10 Hz; the
                                       // whole path is sent at every scan)
  bool publish_tf = true;
  int queue_size = 100;                // publisher queues [messages]
  double marker_lifetime_s = 2.0;      // a teammate's marker disappears when not updated [s]

  /// "" when valid.
  std::string Validate() const;
};

class RosOutputs : public live::LiveSink {
 public:
  /// Advertises on `node` (private topics) and `root` (/tf). `names[id]`
  /// names the teammates (their frames and topics); `forward` (may be null)
  /// also receives every call (the output files).
  /// `clock` (not owned): the LiveDrone's, times the publication latency.
  RosOutputs(ros::NodeHandle* node, ros::NodeHandle* root, const RosOutputOptions& options,
             const std::vector<std::string>& names, live::LiveSink* forward,
             const live::Clock* clock);

  /// The drone whose map ~local_map shows (read on the estimator thread,
  /// inside OnScan); set before LiveDrone::Run().
  void set_drone(const live::LiveDrone* drone) { drone_ = drone; }

  void OnScan(const swarm::DroneOutput& output, const live::ScanLatency& latency) override;
  void OnScanDropped(int64_t scan_stamp_ns, live::ScanDropReason reason) override;
  void OnImuPose(const live::ImuRatePose& pose) override;

  int64_t odometry_published() const { return odometry_published_; }
  /// Per published ~odometry: scan end (on the LiveDrone's time line) ->
  /// publication [ms], swarmlio_live's latency definition taken after the
  /// publish call; not for the scans of the final flush (ScanLatency::at_flush).
  /// Read after LiveDrone::Run().
  const std::vector<float>& latencies_ms() const { return latencies_ms_; }

 private:
  std::string TeammateName(int id) const;
  void PublishTeammates(const swarm::DroneOutput& output);

  ros::NodeHandle* node_;
  RosOutputOptions options_;
  std::vector<std::string> names_;
  live::LiveSink* forward_;
  const live::Clock* clock_;
  const live::LiveDrone* drone_ = nullptr;
  ros::Publisher odometry_, odometry_imu_, path_, cloud_, map_, markers_, tf_;
  std::map<int, ros::Publisher> teammate_odometry_;
  int64_t last_map_stamp_ns_ = 0;
  bool map_published_ = false;
  int64_t odometry_published_ = 0;
  nav_msgs::Path path_message_;  // the last max_path_poses poses
  std::vector<float> latencies_ms_;  // one float per scan (bounded by the run's length)
};

}  // namespace swarmlio::tools
