// A smooth analytic test trajectory with known derivatives, shared by the
// IMU propagation and motion-compensation tests: a helix at ~3 m/s turning at
// 1.5 rad/s with roll and pitch oscillations. IMU samples generated from it
// are exact (noise-free) specific force and angular rate in the body frame.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>

#include "swarmlio/math/so3.h"
#include "swarmlio/sensors/measurements.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::testing {

inline Eigen::Matrix3d Rx(double a) { return so3::Exp(Eigen::Vector3d(a, 0, 0)); }
inline Eigen::Matrix3d Ry(double a) { return so3::Exp(Eigen::Vector3d(0, a, 0)); }
inline Eigen::Matrix3d Rz(double a) { return so3::Exp(Eigen::Vector3d(0, 0, a)); }

// Helix p = [r cos(W t), r sin(W t), c t + h sin(W2 t)] with attitude
// R_W_b = Rz(alpha) Ry(gamma) Rx(beta); all derivatives analytic.
struct Helix {
  double r = 2.0, W = 1.5, c = 0.5, h = 0.3, W2 = 2.0;
  Eigen::Vector3d g_in_W{0.0, 0.0, -9.81};

  double alpha(double t) const { return W * t + 0.3; }
  double alpha_dot() const { return W; }
  double beta(double t) const { return 0.3 * std::sin(2.0 * t); }
  double beta_dot(double t) const { return 0.6 * std::cos(2.0 * t); }
  double gamma(double t) const { return 0.2 * std::sin(1.3 * t + 0.5); }
  double gamma_dot(double t) const { return 0.26 * std::cos(1.3 * t + 0.5); }

  Eigen::Matrix3d R(double t) const { return Rz(alpha(t)) * Ry(gamma(t)) * Rx(beta(t)); }
  Eigen::Vector3d p(double t) const {
    return {r * std::cos(W * t), r * std::sin(W * t), c * t + h * std::sin(W2 * t)};
  }
  Eigen::Vector3d v(double t) const {
    return {-r * W * std::sin(W * t), r * W * std::cos(W * t), c + h * W2 * std::cos(W2 * t)};
  }
  Eigen::Vector3d a(double t) const {
    return {-r * W * W * std::cos(W * t), -r * W * W * std::sin(W * t),
            -h * W2 * W2 * std::sin(W2 * t)};
  }
  // Body angular rate: (Ry Rx)^T [0 0 a'] + Rx^T [0 g' 0] + [b' 0 0].
  Eigen::Vector3d w_b(double t) const {
    const Eigen::Matrix3d B = Ry(gamma(t)) * Rx(beta(t));
    return B.transpose() * Eigen::Vector3d(0, 0, alpha_dot()) +
           Rx(beta(t)).transpose() * Eigen::Vector3d(0, gamma_dot(t), 0) +
           Eigen::Vector3d(beta_dot(t), 0, 0);
  }
  Eigen::Vector3d f_b(double t) const { return R(t).transpose() * (a(t) - g_in_W); }

  EgoState State(double t) const {
    EgoState x;
    x.q_G_b = Eigen::Quaterniond(R(t));
    x.p_b_in_G = p(t);
    x.v_b_in_G = v(t);
    x.g_in_G = g_in_W;
    return x;
  }
  ImuSample Sample(int64_t stamp_ns) const {
    const double t = ToSeconds(stamp_ns);
    ImuSample s;
    s.stamp_ns = stamp_ns;
    s.angular_velocity_rad_s = w_b(t);
    s.linear_acceleration = f_b(t);
    return s;
  }
};

}  // namespace swarmlio::testing
