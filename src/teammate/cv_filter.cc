#include "swarmlio/teammate/cv_filter.h"

#include "swarmlio/common/time.h"

#include <Eigen/Cholesky>
#include <cmath>

namespace swarmlio::teammate {

void ConstantVelocityFilter::Initialize(int64_t stamp_ns, const Eigen::Vector3d& p_in_G,
                                        const Eigen::Vector3d& v_in_G, double position_sigma_m,
                                        double velocity_sigma_m_s) {
  stamp_ns_ = stamp_ns;
  x_ << p_in_G, v_in_G;
  P_.setZero();
  P_.topLeftCorner<3, 3>().diagonal().setConstant(position_sigma_m * position_sigma_m);
  P_.bottomRightCorner<3, 3>().diagonal().setConstant(velocity_sigma_m_s * velocity_sigma_m_s);
}

void ConstantVelocityFilter::PredictTo(int64_t stamp_ns, double accel_noise_density_m_s2_sqrt_hz) {
  const double dt = SecondsBetween(stamp_ns_, stamp_ns);
  stamp_ns_ = stamp_ns;
  if (dt == 0.0) return;
  Matrix6d F = Matrix6d::Identity();
  F.topRightCorner<3, 3>().diagonal().setConstant(dt);
  x_ = F * x_;
  const double q = accel_noise_density_m_s2_sqrt_hz * accel_noise_density_m_s2_sqrt_hz;
  const double a = std::abs(dt);
  Matrix6d Q = Matrix6d::Zero();
  Q.topLeftCorner<3, 3>().diagonal().setConstant(q * a * a * a / 3.0);
  Q.topRightCorner<3, 3>().diagonal().setConstant(q * a * a / 2.0);
  Q.bottomLeftCorner<3, 3>().diagonal().setConstant(q * a * a / 2.0);
  Q.bottomRightCorner<3, 3>().diagonal().setConstant(q * a);
  P_ = F * P_ * F.transpose() + Q;
}

void ConstantVelocityFilter::PredictWithVelocity(int64_t stamp_ns, const Eigen::Vector3d& v_in_G,
                                                 double velocity_sigma_m_s) {
  const double dt = SecondsBetween(stamp_ns_, stamp_ns);
  stamp_ns_ = stamp_ns;
  x_.tail<3>() = v_in_G;
  x_.head<3>() += v_in_G * dt;
  const double var_v = velocity_sigma_m_s * velocity_sigma_m_s;
  P_.topRightCorner<3, 3>().setZero();
  P_.bottomLeftCorner<3, 3>().setZero();
  P_.bottomRightCorner<3, 3>() = var_v * Eigen::Matrix3d::Identity();
  P_.topLeftCorner<3, 3>().diagonal().array() += var_v * dt * dt;
}

double ConstantVelocityFilter::Update(const Eigen::Vector3d& z_in_G, const Eigen::Matrix3d& R) {
  const Eigen::Vector3d innovation = z_in_G - x_.head<3>();
  const Eigen::Matrix3d S = P_.topLeftCorner<3, 3>() + R;
  const Eigen::LLT<Eigen::Matrix3d> llt(S);
  // K = P H^T S^-1 with H = [I 0]: P H^T is the first three columns of P.
  const Eigen::Matrix<double, 6, 3> PHt = P_.leftCols<3>();
  const Eigen::Matrix<double, 6, 3> K = llt.solve(PHt.transpose()).transpose();
  x_ += K * innovation;
  P_ -= K * PHt.transpose();
  P_ = 0.5 * (P_ + P_.transpose());
  return innovation.dot(llt.solve(innovation));
}

}  // namespace swarmlio::teammate
