// The own dead-reckoned track of swarm::DroneEstimator (docs/swarm.md section
// 8): the IMU-propagated positions within each scan, chained across scans
// WITHOUT the updates' corrections. Over the 0.1-0.5 s by which a passive
// observation is late, s(t_j) - s(t_k) is the own displacement including the
// accelerations that a constant-velocity shift v (t_j - t_k) misses. Internal
// to src/swarm.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <utility>
#include <vector>

#include "swarmlio/lio/imu_propagator.h"

namespace swarmlio::swarm::internal {

class DeadReckoningTrack {
 public:
  /// Appends one scan's propagated poses (ImuPropagator::scan_poses(): from
  /// the previous scan end, at the posterior, to this scan's end). Only the
  /// increments between consecutive poses enter, so the jump of the update
  /// between the last scan's end and this scan's first pose does not. Keeps
  /// the samples of the last `keep_s` seconds.
  void Append(const std::vector<ImuPose>& poses, double keep_s);

  /// s(t_j) - s(t_k), linear between the samples [m]; false when the track
  /// does not cover [t_j, t_k] or t_j > t_k.
  bool Displacement(int64_t t_j_ns, int64_t t_k_ns, Eigen::Vector3d* displacement) const;

  size_t size() const { return track_.size(); }

 private:
  Eigen::Vector3d At(int64_t t_ns) const;

  std::deque<std::pair<int64_t, Eigen::Vector3d>> track_;  // (stamp [ns], s [m])
};

}  // namespace swarmlio::swarm::internal
