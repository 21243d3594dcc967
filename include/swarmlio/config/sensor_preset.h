// Sensor presets: configs/*.yaml files with a `lidar:` and an `imu:` section.
#pragma once

#include <string>

#include "swarmlio/common/status.h"
#include "swarmlio/sensors/imu_options.h"
#include "swarmlio/sensors/lidar_options.h"

namespace swarmlio::config {

/// Reads the `lidar` and `imu` sections of a sensor preset file over
/// `*lidar` and `*imu` (either may be null to skip it), validated. A file
/// with neither section is an error.
Status LoadSensorPreset(const std::string& path, LidarOptions* lidar, ImuOptions* imu);

}  // namespace swarmlio::config
