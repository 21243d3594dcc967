// Constant-velocity Kalman filter of a tracked object's position and velocity
// (paper Sec. III-C-1, "temporary tracker"; Swarm-LIO2 esikf_tracker.hpp).
//
// State x = [p; v] in the observer's global frame G_i, covariance P (6x6).
// Prediction over dt (continuous white-acceleration model, density q):
//   p' = p + v dt,  v' = v,
//   Q = q [dt^3/3 I, dt^2/2 I; dt^2/2 I, dt I].
// Position measurement z = p + n, n ~ N(0, R).
#pragma once

#include <Eigen/Core>
#include <string>

#include "swarmlio/common/time.h"
#include "swarmlio/common/option_fields.h"

namespace swarmlio::teammate {

/// YAML section `teammate.filter`.
struct CvFilterOptions {
  /// Acceleration noise density sqrt(q): how hard the target may manoeuvre.
  /// (Swarm-LIO2 adds 0.01 to the velocity variance per 30 Hz step; a
  /// drone in an excitation flight accelerates at ~1-3 m/s^2.)
  double accel_noise_density_m_s2_sqrt_hz = 3.0;
  double initial_velocity_sigma_m_s = 1.0;  // 1-sigma of the unknown velocity at creation
  double lidar_position_sigma_m = 0.03;     // 1-sigma of a cluster position (0.001 m^2)

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("accel_noise_density_m_s2_sqrt_hz", accel_noise_density_m_s2_sqrt_hz,
      FieldSpec::Positive("m/s^2/sqrt(Hz)", "white-acceleration noise of the constant-velocity model"));
    v("initial_velocity_sigma_m_s", initial_velocity_sigma_m_s,
      FieldSpec::Positive("m/s", "1-sigma velocity of a new tracker"));
    v("lidar_position_sigma_m", lidar_position_sigma_m,
      FieldSpec::Positive("m", "1-sigma of a LiDAR cluster position"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

class ConstantVelocityFilter {
 public:
  using Vector6d = Eigen::Matrix<double, 6, 1>;
  using Matrix6d = Eigen::Matrix<double, 6, 6>;

  /// Starts at `p_in_G` with velocity `v_in_G` at time `stamp_ns`.
  void Initialize(int64_t stamp_ns, const Eigen::Vector3d& p_in_G, const Eigen::Vector3d& v_in_G,
                  double position_sigma_m, double velocity_sigma_m_s);

  /// Moves the state to `stamp_ns` (dt may be negative; Q uses |dt|).
  void PredictTo(int64_t stamp_ns, double accel_noise_density_m_s2_sqrt_hz);
  /// Same, with the velocity replaced by a known one (teammate trackers:
  /// the velocity the teammate broadcasts): p' = p + v dt, Q on p only.
  void PredictWithVelocity(int64_t stamp_ns, const Eigen::Vector3d& v_in_G,
                           double velocity_sigma_m_s);

  /// Position update; returns the squared Mahalanobis distance of the innovation.
  double Update(const Eigen::Vector3d& z_in_G, const Eigen::Matrix3d& R);

  /// Extrapolated position at `stamp_ns` (state unchanged).
  Eigen::Vector3d PositionAt(int64_t stamp_ns) const { return p() + v() * SecondsBetween(stamp_ns_, stamp_ns); }

  int64_t stamp_ns() const { return stamp_ns_; }
  Eigen::Vector3d p() const { return x_.head<3>(); }
  Eigen::Vector3d v() const { return x_.tail<3>(); }
  const Vector6d& x() const { return x_; }
  const Matrix6d& P() const { return P_; }

 private:
  int64_t stamp_ns_ = 0;
  Vector6d x_ = Vector6d::Zero();
  Matrix6d P_ = Matrix6d::Identity();
};

}  // namespace swarmlio::teammate
