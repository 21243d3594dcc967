// CalibrationGaugeCovariance against a Monte Carlo of the exact geometry: a
// LiDAR-IMU calibration error (e, dt) builds the first scan's map rotated and
// shifted; a later scan registered to that map with the same calibration puts
// the IMU where the map says. The sample covariance of that position error
// must match the closed form; a transposed lever-arm term must not.
#include "swarmlio/lio/calibration_gauge.h"

#include <gtest/gtest.h>

#include <random>

#include "swarmlio/math/so3.h"

namespace swarmlio::lio {
namespace {

struct Geometry {
  Eigen::Matrix3d R_imu_lidar, R_G_b0, R_G_b;
  Eigen::Vector3d p_lidar_in_imu, p_b0_in_G, p_b_in_G;
};

// The IMU position a LIO estimates at (R_G_b, p_b_in_G) with the given
// calibration R_imu_lidar Exp(e), p_lidar_in_imu + dt, on the map its first
// scan built with the same calibration.
Eigen::Vector3d EstimatedPosition(const Geometry& g,
                                  const Eigen::Vector3d& e,
                                  const Eigen::Vector3d& dt) {
  const Eigen::Matrix3d R_given = g.R_imu_lidar * so3::Exp(e);
  const Eigen::Vector3d t_given = g.p_lidar_in_imu + dt;
  const Eigen::Vector3d p_lidar0 = g.p_b0_in_G + g.R_G_b0 * g.p_lidar_in_imu;
  const Eigen::Matrix3d R_lidar0 = g.R_G_b0 * g.R_imu_lidar;
  // A true point x, seen at y = R_lidar0^T (x - p_lidar0), enters the map at
  // p_b0 + R_G_b0 (R_given y + t_given).
  auto to_map = [&](const Eigen::Vector3d& x) -> Eigen::Vector3d {
    return g.p_b0_in_G + g.R_G_b0 * (R_given * (R_lidar0.transpose() * (x - p_lidar0)) + t_given);
  };
  const Eigen::Matrix3d D = g.R_G_b0 * R_given * g.R_imu_lidar.transpose() * g.R_G_b0.transpose();
  // Registration puts the LiDAR where the map has it.
  const Eigen::Matrix3d R_lidar_hat = D * g.R_G_b * g.R_imu_lidar;
  const Eigen::Vector3d p_lidar_hat = to_map(g.p_b_in_G + g.R_G_b * g.p_lidar_in_imu);
  const Eigen::Matrix3d R_b_hat = R_lidar_hat * R_given.transpose();
  return p_lidar_hat - R_b_hat * t_given;
}

double RelativeError(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return (a - b).norm() / b.norm();
}

// Checks the closed form against the sample; with `control`, also that the
// translation term with its factors swapped is detectably wrong (for a
// geometry where that term dominates).
void ExpectMatchesMonteCarlo(const Geometry& g,
                             const CalibrationUncertainty& c,
                             bool control = false) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  constexpr int kSamples = 20000;
  Eigen::Matrix3d sample = Eigen::Matrix3d::Zero();
  for (int k = 0; k < kSamples; ++k) {
    const Eigen::Vector3d e =
        c.rotation_sigma_rad * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    const Eigen::Vector3d dt =
        c.translation_sigma_m * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    const Eigen::Vector3d error = EstimatedPosition(g, e, dt) - g.p_b_in_G;
    sample += error * error.transpose() / kSamples;
  }
  MapAnchor anchor;
  anchor.R_G_b0 = g.R_G_b0;
  anchor.p_lidar0_in_G = g.p_b0_in_G + g.R_G_b0 * g.p_lidar_in_imu;
  anchor.p_lidar_in_imu_m = g.p_lidar_in_imu;
  const Eigen::Matrix3d model = CalibrationGaugeCovariance(c, anchor, g.R_G_b, g.p_b_in_G);
  EXPECT_LT(RelativeError(model, sample), 0.05) << "model\n" << model << "\nsample\n" << sample;
  if (!control) return;
  const Eigen::Matrix3d dR = anchor.R_G_b0 - g.R_G_b;
  const double st2 = c.translation_sigma_m * c.translation_sigma_m;
  const Eigen::Matrix3d swapped = model - st2 * (dR * dR.transpose()) + st2 * (dR.transpose() * dR);
  EXPECT_GT(RelativeError(swapped, sample), 0.2);
}

Geometry Avia() {
  Geometry g;
  g.R_imu_lidar = so3::Exp(Eigen::Vector3d(0.0, 0.1745, 0.0));  // pitched 10 deg down
  g.p_lidar_in_imu = Eigen::Vector3d(0.04165, 0.02326, -0.0284);
  g.R_G_b0 = so3::Exp(Eigen::Vector3d(0.02, -0.01, 0.3));
  g.p_b0_in_G = Eigen::Vector3d(0.1, -0.2, 0.05);
  return g;
}

TEST(CalibrationGauge, FarFromTheAnchorTheMapRotationDominates) {
  Geometry g = Avia();
  g.R_G_b = so3::Exp(Eigen::Vector3d(0.05, 0.02, 2.0));
  g.p_b_in_G = Eigen::Vector3d(30.0, -12.0, 2.5);
  CalibrationUncertainty c;
  c.rotation_sigma_rad = 0.25 * M_PI / 180.0;
  c.translation_sigma_m = 0.005;
  ExpectMatchesMonteCarlo(g, c);
}

TEST(CalibrationGauge, AtTheAnchorTurnedTheLeverArmErrorDominates) {
  Geometry g = Avia();
  // Back at the start, turned about an axis that is not vertical, so that
  // (R0 - R)(R0 - R)^T and (R0 - R)^T (R0 - R) differ.
  g.R_G_b0 = so3::Exp(Eigen::Vector3d(1.5, 0.0, 0.0));
  g.R_G_b = g.R_G_b0 * so3::Exp(Eigen::Vector3d(0.6, 0.4, 1.9));
  g.p_b_in_G = g.p_b0_in_G;
  CalibrationUncertainty c;
  c.rotation_sigma_rad = 0.001 * M_PI / 180.0;
  c.translation_sigma_m = 0.005;
  ExpectMatchesMonteCarlo(g, c, /*control=*/true);
}

TEST(CalibrationGauge, AnExactCalibrationAddsNothing) {
  const Geometry g = Avia();
  MapAnchor anchor;
  anchor.R_G_b0 = g.R_G_b0;
  EXPECT_TRUE(CalibrationGaugeCovariance(CalibrationUncertainty(), anchor,
                                         so3::Exp(Eigen::Vector3d(0.1, 0.2, 0.3)),
                                         Eigen::Vector3d(5, 6, 7))
                  .isZero(0.0));
}

}  // namespace
}  // namespace swarmlio::lio
