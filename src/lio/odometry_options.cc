#include "swarmlio/lio/odometry_options.h"

#include <algorithm>

namespace swarmlio::lio {

OdometryOptions OdometryOptionsFor(const LidarOptions& lidar) {
  OdometryOptions options;
  options.preprocess = PreprocessOptionsFor(lidar);
  switch (lidar.type) {
    case LidarType::kLivoxMid360:
      options.map.leaf_size_m = 0.3;
      break;
    case LidarType::kLivoxAvia:
      options.map.leaf_size_m = 0.25;
      break;
    case LidarType::kSpinning:
      options.map.leaf_size_m = 0.5;
      break;
  }
  // The plane fit's normal noise model (for the noisy-plane rule) uses
  // the sensor's datasheet precision (plane_fit.h, scan_association.h).
  options.association.plane.map_range_stddev_m = lidar.range_noise_stddev_m;
  options.association.plane.map_angular_stddev_deg = lidar.angular_precision_deg;
  // Keep what the sensor can see (FAST-LIO det_range), at least 20 m.
  options.map.half_extent_m = std::max(20.0, lidar.max_range_m);
  return options;
}

}  // namespace swarmlio::lio
