#include "swarmlio/config/dump_options.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "swarmlio/config/config_file.h"
#include "swarmlio/sensors/imu_options.h"
#include "swarmlio/sensors/lidar_options.h"
#include "tests/config/test_options.h"

namespace swarmlio::config {
namespace {

using ::testing::HasSubstr;

template <class Options>
Options RoundTrip(const Options& options, const std::string& section) {
  const std::string yaml = DumpOptions(options, section);
  ConfigFile file;
  EXPECT_TRUE(ConfigFile::Parse(yaml, "dump.yaml", &file).ok()) << yaml;
  Options loaded;  // defaults, overwritten by every key of the dump
  const Status status = file.Read(section, &loaded);
  EXPECT_TRUE(status.ok()) << status.message() << "\n" << yaml;
  EXPECT_TRUE(file.CheckNoUnusedSections().ok());
  return loaded;
}

TEST(ConfigDumpTest, LidarRoundTripIsExact) {
  LidarOptions lidar;
  lidar.type = LidarType::kSpinning;
  lidar.message_format = LidarMessageFormat::kPointCloud2;
  lidar.timestamp_unit = TimestampUnit::kMicrosecond;
  lidar.scan_rate_hz = 0.1 + 0.2;  // not representable in few digits
  lidar.blind_range_m = 1.0 / 3.0;
  lidar.points_per_second = 576000;
  lidar.R_imu_lidar =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  lidar.p_lidar_in_imu_m = Eigen::Vector3d(-0.019391, -0.000278, 0.080926);
  const LidarOptions loaded = RoundTrip(lidar, "lidar");
  EXPECT_EQ(DumpOptions(loaded), DumpOptions(lidar));
  EXPECT_EQ(loaded.scan_rate_hz, lidar.scan_rate_hz);
  EXPECT_EQ(loaded.blind_range_m, lidar.blind_range_m);
  EXPECT_EQ(loaded.R_imu_lidar, lidar.R_imu_lidar);
  EXPECT_EQ(loaded.p_lidar_in_imu_m, lidar.p_lidar_in_imu_m);
  EXPECT_EQ(loaded.type, lidar.type);
  EXPECT_EQ(loaded.timestamp_unit, lidar.timestamp_unit);
}

TEST(ConfigDumpTest, ImuRoundTripIsExact) {
  ImuOptions imu;
  imu.acceleration_unit = AccelerationUnit::kStandardGravity;
  imu.gyro_noise_density_rad_s_sqrt_hz = 1.2345678901234567e-4;
  imu.gravity_m_s2 = 9.80665;
  const ImuOptions loaded = RoundTrip(imu, "imu");
  EXPECT_EQ(DumpOptions(loaded), DumpOptions(imu));
  EXPECT_EQ(loaded.gyro_noise_density_rad_s_sqrt_hz, imu.gyro_noise_density_rad_s_sqrt_hz);
  EXPECT_EQ(loaded.acceleration_unit, imu.acceleration_unit);
}

TEST(ConfigDumpTest, EveryFieldTypeRoundTrips) {
  config_test::TestOptions options;
  options.enabled = false;
  options.count = 0;
  options.small = 255;
  options.big = -9000000000LL;
  options.ratio = 0.1f;
  options.distance_m = 1e-300;
  options.name = "quote \" backslash \\ colon: # hash\nnewline\ttab";
  options.color = config_test::Color::kGreen;
  options.rotation << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  options.weights = {};
  options.tags = {"true", "1.5", "", "null", "a b"};
  options.inner.gain = 1e10;
  const config_test::TestOptions loaded = RoundTrip(options, "drone.test");
  EXPECT_TRUE(loaded == options) << DumpOptions(loaded) << "\nvs\n" << DumpOptions(options);
}

TEST(ConfigDumpTest, CommentsCarryDocUnitAndRange) {
  const std::string yaml = DumpOptions(LidarOptions(), "lidar");
  EXPECT_THAT(yaml, HasSubstr("lidar:\n"));
  EXPECT_THAT(yaml, HasSubstr("  # points closer are dropped [m]; >= 0\n  blind_range_m: 0.5\n"));
  EXPECT_THAT(yaml, HasSubstr("  # sensor model; one of: livox_avia, livox_mid360, spinning\n"
                              "  type: livox_avia\n"));
  EXPECT_THAT(yaml, HasSubstr("R_imu_lidar: [1, 0, 0,  0, 1, 0,  0, 0, 1]\n"));
  EXPECT_THAT(yaml, HasSubstr("[Hz]; in (0, 200]\n  scan_rate_hz: 10\n"));
  const std::string nested = DumpOptions(config_test::TestOptions());
  EXPECT_THAT(nested, HasSubstr("\ninner:\n  # a gain; > 0\n  gain: 2\n"));
}

}  // namespace
}  // namespace swarmlio::config
