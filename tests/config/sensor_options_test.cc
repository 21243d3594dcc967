#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "swarmlio/sensors/imu_options.h"
#include "swarmlio/sensors/lidar_options.h"
#include "tests/config/test_options.h"

namespace swarmlio {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

TEST(ConfigSensorOptionsTest, DefaultsValidate) {
  EXPECT_EQ(LidarOptions().Validate(), "");
  EXPECT_EQ(ImuOptions().Validate(), "");
  EXPECT_EQ(config_test::TestOptions().Validate(), "");
}

TEST(ConfigSensorOptionsTest, ImuDefaultsMatchBmi055Datasheet) {
  const ImuOptions imu;
  constexpr double kDegToRad = M_PI / 180.0;
  EXPECT_NEAR(imu.gyro_noise_density_rad_s_sqrt_hz, 0.014 * kDegToRad, 1e-7);
  EXPECT_NEAR(imu.accel_noise_density_m_s2_sqrt_hz, 150e-6 * 9.80665, 1e-6);
  EXPECT_EQ(imu.gravity_m_s2, 9.81);
  EXPECT_EQ(imu.AccelerationToMetersPerSecondSquared(), 1.0);
  ImuOptions livox_imu;
  livox_imu.acceleration_unit = AccelerationUnit::kStandardGravity;
  EXPECT_EQ(livox_imu.AccelerationToMetersPerSecondSquared(), 9.81);
}

TEST(ConfigSensorOptionsTest, LidarCrossFieldChecks) {
  LidarOptions lidar;
  lidar.fov_vertical_min_deg = 10.0;
  lidar.fov_vertical_max_deg = 5.0;
  EXPECT_THAT(lidar.Validate(), StartsWith("fov_vertical_min_deg: must be below"));

  lidar = LidarOptions();
  lidar.blind_range_m = 500.0;
  EXPECT_THAT(lidar.Validate(), StartsWith("blind_range_m: must be below max_range_m"));

  lidar = LidarOptions();
  lidar.type = LidarType::kSpinning;
  EXPECT_THAT(lidar.Validate(), StartsWith("message_format: livox_custom_msg needs a Livox type"));

  lidar = LidarOptions();
  lidar.timestamp_unit = TimestampUnit::kMicrosecond;
  EXPECT_THAT(lidar.Validate(), StartsWith("timestamp_unit: must be ns for livox_custom_msg"));
  lidar.message_format = LidarMessageFormat::kPointCloud2;
  EXPECT_EQ(lidar.Validate(), "");
}

TEST(ConfigSensorOptionsTest, ExtrinsicRotationMustBeProper) {
  LidarOptions lidar;
  lidar.R_imu_lidar = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_EQ(lidar.Validate(), "");
  // Six significant digits, as calibration tools print them, still pass.
  lidar.R_imu_lidar << 0.999593, 0.015951, -0.023661, -0.015200, 0.999386, 0.031582, 0.024150,
      -0.031210, 0.999221;
  EXPECT_EQ(lidar.Validate(), "");
  EXPECT_NEAR(lidar.QuaternionImuLidar().norm(), 1.0, 1e-15);
  lidar.R_imu_lidar = 1.01 * Eigen::Matrix3d::Identity().eval();
  EXPECT_THAT(lidar.Validate(), HasSubstr("R_imu_lidar[0]: value 1.01 is out of range"));
  lidar.R_imu_lidar = Eigen::Vector3d(1, -1, 1).asDiagonal();  // a reflection
  EXPECT_THAT(lidar.Validate(), StartsWith("R_imu_lidar: not a rotation matrix"));
  lidar.R_imu_lidar << 1, 0, 0, 0, 0.9, 0, 0, 0, 1;
  EXPECT_THAT(lidar.Validate(), StartsWith("R_imu_lidar: not a rotation matrix"));
}

TEST(ConfigSensorOptionsTest, TimestampUnitScale) {
  EXPECT_EQ(TimestampUnitToSeconds(TimestampUnit::kSecond), 1.0);
  EXPECT_EQ(TimestampUnitToSeconds(TimestampUnit::kMillisecond), 1e-3);
  EXPECT_EQ(TimestampUnitToSeconds(TimestampUnit::kMicrosecond), 1e-6);
  EXPECT_EQ(TimestampUnitToSeconds(TimestampUnit::kNanosecond), 1e-9);
}

}  // namespace
}  // namespace swarmlio
