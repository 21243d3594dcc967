#include "swarmlio/lio/calibration_gauge.h"

#include "swarmlio/math/so3.h"

namespace swarmlio::lio {

Eigen::Matrix3d CalibrationGaugeCovariance(const CalibrationUncertainty& calibration,
                                           const MapAnchor& anchor,
                                           const Eigen::Matrix3d& R_G_b,
                                           const Eigen::Vector3d& p_b_in_G) {
  const Eigen::Matrix3d M = so3::Hat(p_b_in_G - anchor.p_lidar0_in_G) * anchor.R_G_b0 +
                            R_G_b * so3::Hat(anchor.p_lidar_in_imu_m);
  const Eigen::Matrix3d dR = anchor.R_G_b0 - R_G_b;
  const double sr = calibration.rotation_sigma_rad;
  const double st = calibration.translation_sigma_m;
  return sr * sr * M * M.transpose() + st * st * dR * dR.transpose();
}

}  // namespace swarmlio::lio
