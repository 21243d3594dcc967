// Smooth rigid-body trajectories for simulated drones and moving objects.
//
// Position and yaw are one uniform quintic B-spline in R^4 (x, y, z, yaw):
// C4-continuous, so acceleration, jerk and snap are continuous and the
// attitude derived from them has continuous angular velocity and angular
// acceleration. Attitude (AttitudeMode::kQuadrotor) follows a quadrotor's
// differential flatness: the body z axis is the thrust direction
// (acceleration + gravity) and the body x axis is the yaw heading projected
// onto the plane normal to thrust, so roll and pitch follow the acceleration.
// AttitudeMode::kYawOnly keeps the body upright (walking people, ground robots).
//
// Frames: W is the simulation world (z up, gravity g_W = (0, 0, -9.81)); b is
// the body (IMU) frame.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace swarmlio::sim {

constexpr double kGravity = 9.81;  // [m/s^2]

enum class AttitudeMode { kQuadrotor, kYawOnly };

/// Rigid pose of the body in W.
struct Pose {
  Eigen::Matrix3d R_W_b = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_b_in_W = Eigen::Vector3d::Zero();
};

/// Full kinematic state at one instant.
struct KinematicState {
  Eigen::Matrix3d R_W_b = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_b_in_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_b_in_W = Eigen::Vector3d::Zero();      // [m/s]
  Eigen::Vector3d a_b_in_W = Eigen::Vector3d::Zero();      // [m/s^2]
  Eigen::Vector3d omega_b = Eigen::Vector3d::Zero();       // body angular rate [rad/s]
  Eigen::Vector3d alpha_b = Eigen::Vector3d::Zero();       // body angular acceleration [rad/s^2]
};

/// Uniform quintic B-spline in (x, y, z, yaw).
class Trajectory {
 public:
  /// `control_points` (x, y, z [m], yaw [rad]); at least 6. The curve is
  /// defined on [start_time, start_time + (n - 5) * knot_interval]; outside it
  /// the time is clamped (end the control points with 6 equal ones so that
  /// the clamped state is a consistent hover).
  Trajectory(double start_time_s, double knot_interval_s,
             std::vector<Eigen::Vector4d> control_points,
             AttitudeMode mode = AttitudeMode::kQuadrotor);
  Trajectory() = default;

  double start_time() const { return start_time_; }
  double end_time() const;
  AttitudeMode mode() const { return mode_; }
  double knot_interval() const { return knot_interval_; }
  const std::vector<Eigen::Vector4d>& control_points() const { return control_points_; }

  /// Pose only (cheap: no derivatives beyond the acceleration).
  Pose PoseAt(double t) const;
  /// Position only (cheapest).
  Eigen::Vector3d PositionAt(double t) const;
  /// Pose, velocities and accelerations (analytic).
  KinematicState StateAt(double t) const;
  /// d^k/dt^k of (x, y, z, yaw), k = 0..5.
  Eigen::Vector4d Derivative(double t, int k) const;

  /// Largest |acceleration| and |velocity| sampled every `dt` s (for checks).
  void Extremes(double dt, double* max_speed, double* max_acceleration,
                double* max_angular_rate) const;

 private:
  // Segment index and local parameter u in [0, 1] of time t (clamped).
  void Locate(double t, int* segment, double* u) const;

  double start_time_ = 0.0;
  double knot_interval_ = 1.0;
  std::vector<Eigen::Vector4d> control_points_;
  AttitudeMode mode_ = AttitudeMode::kQuadrotor;
};

}  // namespace swarmlio::sim
