#include "swarmlio/config/sensor_preset.h"

#include "swarmlio/config/config_file.h"

namespace swarmlio::config {

Status LoadSensorPreset(const std::string& path, LidarOptions* lidar, ImuOptions* imu) {
  ConfigFile file;
  SWARMLIO_RETURN_IF_ERROR(ConfigFile::Load(path, &file));
  if (!file.HasSection("lidar") && !file.HasSection("imu")) {
    return Status::InvalidArgument(path + ": not a sensor preset (no lidar or imu section)");
  }
  if (lidar != nullptr) SWARMLIO_RETURN_IF_ERROR(file.Read("lidar", lidar));
  if (imu != nullptr) SWARMLIO_RETURN_IF_ERROR(file.Read("imu", imu));
  return Status::Ok();
}

}  // namespace swarmlio::config
