// The own IMU motion history of swarm::DroneEstimator for the time
// compensation of late passive observations (docs/swarm.md section 8).
// A teammate observed the ego at t_j <= t_k (t_k: the scan end, the time of
// the ego state). With the kinematic accelerations a(s) = R(s)(f(s) - b_a) + g
// over [t_j, t_k] and T = t_k - t_j:
//
//   p(t_j) = p(t_k) - v(t_k) T + int_{t_j}^{t_k} (s - t_j) a(s) ds.
//
// The history gives the weighted integrals of a(s) and R(s) (an
// ImuRetrodiction); p(t_k), v(t_k), R, b_a and g are the state's, so the
// passive factor relates the past position to the current state with the
// right Jacobians (factors/passive_observation_factor.h). An earlier version
// chained the propagated positions and treated the displacement as exact:
// its error was the intermediate posteriors' velocity errors, which the
// current state does not describe, and with 0.3-0.4 s of latency the
// wall-facing Avia diverged (docs/swarm.md). Internal to src/swarm.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <vector>

#include "factors/passive_observation_factor.h"
#include "swarmlio/lio/imu_propagator.h"

namespace swarmlio::swarm::internal {

class DeadReckoningTrack {
 public:
  /// Appends one scan's propagated poses (ImuPropagator::scan_poses()): pose
  /// k's acceleration holds until pose k + 1. Keeps the last `keep_s` seconds.
  void Append(const std::vector<lio::ImuPose>& poses, double keep_s);

  /// The integrals over [t_j, t_k] with weight (s - t_j); false when the
  /// history does not cover [t_j, t_k] or t_j > t_k.
  bool Retrodiction(int64_t t_j_ns, int64_t t_k_ns, ImuRetrodiction* r) const;

  size_t size() const { return segments_.size(); }

 private:
  struct Segment {
    int64_t begin_ns = 0;
    int64_t end_ns = 0;
    Eigen::Vector3d acc_in_G = Eigen::Vector3d::Zero();  // [m/s^2]
    Eigen::Matrix3d R_G_b = Eigen::Matrix3d::Identity();
  };
  std::deque<Segment> segments_;  // contiguous, in time order
};

}  // namespace swarmlio::swarm::internal
