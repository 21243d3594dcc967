// ImuRateOdometry: the drone's state propagated to every IMU sample between
// scan updates, the IMU-rate pose a flight controller needs (lio::Odometry
// only propagates inside its scan pipeline, up to each scan end). After each
// scan's posterior (state at the scan end) it restarts from that state and
// re-propagates the IMU samples already received after the scan end; each
// new sample then advances it by one step of the propagator's discrete
// model (lio/imu_propagator.h: PropagateEgo with the midpoint input, biases
// and gravity from the posterior; no covariance). No threads, no clock.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <deque>

#include "swarmlio/sensors/measurements.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::live {

/// The propagated body state at one IMU sample (odometry time line, i.e.
/// the IMU stamp minus odometry.imu_time_offset_s; body in the drone's G).
struct ImuRatePose {
  int64_t stamp_ns = 0;
  Eigen::Quaterniond q_G_b = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_b_in_G = Eigen::Vector3d::Zero();  // [m]
  Eigen::Vector3d v_b_in_G = Eigen::Vector3d::Zero();  // [m/s]
  Eigen::Vector3d angular_velocity_in_b_rad_s = Eigen::Vector3d::Zero();  // bias removed
};

class ImuRateOdometry {
 public:
  /// `imu_time_offset_ns`: the odometry's IMU time offset (subtracted from
  /// IMU stamps); `max_buffered_samples` bounds the samples kept for the
  /// re-propagation after a scan (>= one scan period plus the processing delay).
  explicit ImuRateOdometry(int64_t imu_time_offset_ns, size_t max_buffered_samples = 1000);

  /// A scan's posterior `state` at `stamp_ns` (the scan end): restarts from
  /// it and re-propagates the buffered samples after it.
  void ResetToScan(const EgoState& state, int64_t stamp_ns, double acceleration_to_m_s2);

  /// One raw IMU sample (as given to the odometry). True, with `*pose`, once
  /// a scan posterior exists and the sample is after the current state time.
  bool AddImu(const ImuSample& sample, double acceleration_to_m_s2, ImuRatePose* pose);

  bool has_state() const { return has_state_; }

 private:
  struct Sample {
    int64_t stamp_ns = 0;  // odometry time line
    Eigen::Vector3d angular_velocity_rad_s;
    Eigen::Vector3d linear_acceleration;  // raw unit
  };
  // Advances state_ from stamp_ns_ to `next` (input: midpoint between the
  // previous sample and `next`).
  void StepTo(const Sample& next, double acceleration_to_m_s2);
  ImuRatePose Pose() const;

  int64_t imu_time_offset_ns_;
  size_t max_buffered_samples_;
  std::deque<Sample> buffer_;
  bool has_state_ = false;
  EgoState state_;
  int64_t stamp_ns_ = 0;
  bool has_previous_ = false;
  Sample previous_;  // the input held at stamp_ns_
};

}  // namespace swarmlio::live
