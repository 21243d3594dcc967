// Every configs/*.yaml with a `lidar` or `imu` section must load and validate.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "swarmlio/config/config_file.h"
#include "swarmlio/sensors/imu_options.h"
#include "swarmlio/sensors/lidar_options.h"

namespace swarmlio::config {
namespace {

const std::string kConfigDir = std::string(SWARMLIO_SOURCE_DIR) + "/configs";

std::vector<std::string> SensorConfigFiles() {
  std::vector<std::string> paths;
  for (const auto& entry : std::filesystem::directory_iterator(kConfigDir)) {
    if (entry.path().extension() != ".yaml") continue;
    ConfigFile file;
    if (!ConfigFile::Load(entry.path().string(), &file).ok()) {
      paths.push_back(entry.path().string());  // a broken file must fail below
      continue;
    }
    if (file.HasSection("lidar") || file.HasSection("imu")) paths.push_back(entry.path().string());
  }
  std::sort(paths.begin(), paths.end());
  return paths;
}

TEST(ConfigPresetTest, EverySensorConfigLoadsAndValidates) {
  const std::vector<std::string> paths = SensorConfigFiles();
  EXPECT_GE(paths.size(), 3u);
  for (const std::string& path : paths) {
    SCOPED_TRACE(path);
    ConfigFile file;
    const Status load = ConfigFile::Load(path, &file);
    ASSERT_TRUE(load.ok()) << load.message();
    LidarOptions lidar;
    ImuOptions imu;
    const Status read_lidar = file.Read("lidar", &lidar);
    EXPECT_TRUE(read_lidar.ok()) << read_lidar.message();
    const Status read_imu = file.Read("imu", &imu);
    EXPECT_TRUE(read_imu.ok()) << read_imu.message();
  }
}

template <class Options>
Options ReadPreset(const std::string& name, const std::string& section) {
  ConfigFile file;
  Options options;
  EXPECT_TRUE(ConfigFile::Load(kConfigDir + "/" + name, &file).ok());
  const Status status = file.Read(section, &options);
  EXPECT_TRUE(status.ok()) << status.message();
  return options;
}

TEST(ConfigPresetTest, LivoxAvia) {
  const auto lidar = ReadPreset<LidarOptions>("livox_avia.yaml", "lidar");
  EXPECT_EQ(lidar.type, LidarType::kLivoxAvia);
  EXPECT_EQ(lidar.fov_horizontal_deg, 70.4);
  EXPECT_EQ(lidar.fov_vertical_max_deg - lidar.fov_vertical_min_deg, 77.2);
  EXPECT_EQ(lidar.num_lines, 6);
  EXPECT_EQ(lidar.blind_range_m, 0.5);  // Swarm-LIO2 avia.yaml
  EXPECT_EQ(lidar.p_lidar_in_imu_m, Eigen::Vector3d(0.027709, 0.013624, 0.101131));
  EXPECT_EQ(lidar.R_imu_lidar(0, 1), 0.015951);
}

TEST(ConfigPresetTest, LivoxMid360) {
  const auto lidar = ReadPreset<LidarOptions>("livox_mid360.yaml", "lidar");
  EXPECT_EQ(lidar.type, LidarType::kLivoxMid360);
  EXPECT_EQ(lidar.fov_horizontal_deg, 360.0);
  EXPECT_EQ(lidar.fov_vertical_min_deg, -7.0);
  EXPECT_EQ(lidar.fov_vertical_max_deg, 52.0);
  EXPECT_EQ(lidar.num_lines, 4);
  EXPECT_EQ(lidar.blind_range_m, 0.2);
  // Swarm-LIO2 mid360.yaml LI_extrinsic_T: the LiDAR origin in the IMU frame.
  EXPECT_EQ(lidar.p_lidar_in_imu_m, Eigen::Vector3d(-0.019391, -0.000278, 0.080926));
  EXPECT_TRUE(lidar.R_imu_lidar.isIdentity(0.0));
}

TEST(ConfigPresetTest, Spinning32) {
  const auto lidar = ReadPreset<LidarOptions>("spinning_32.yaml", "lidar");
  EXPECT_EQ(lidar.type, LidarType::kSpinning);
  EXPECT_EQ(lidar.message_format, LidarMessageFormat::kPointCloud2);
  EXPECT_EQ(lidar.num_lines, 32);
  EXPECT_EQ(lidar.scan_rate_hz, 10.0);
  EXPECT_EQ(lidar.fov_horizontal_deg, 360.0);
}

}  // namespace
}  // namespace swarmlio::config
