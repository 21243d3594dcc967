// Test helper: a simulated drone as its estimator is told it, the way
// swarmlio_sim's swarm.yaml describes it (sim::ReplayManifestYaml, read back
// by driver::ParseManifest): its sensors with the calibration the simulator
// reports as given (sim::GivenCalibration: the truth with the scenario's
// calibration error), never the truth. Header-only; the test executable
// links swarmlio_sim and swarmlio_driver.
#pragma once

#include "swarmlio/driver/manifest.h"
#include "swarmlio/sim/airframe_description.h"
#include "swarmlio/sim/simulator.h"

namespace swarmlio::testing {

/// Drone `d`'s name, LiDAR (the given extrinsic), IMU, bag reading options
/// and odometry options (the defaults for those sensors with the given IMU
/// time offset) and its airframe as described; no bag, ground truth or clock.
inline driver::DroneInput GivenDroneInput(const sim::DroneConfig& d) {
  driver::DroneInput input;
  input.name = d.name;
  input.lidar = sim::GivenLidarOptions(d);
  input.imu = d.imu.sensor;
  input.bag.point_time_unit = input.lidar.timestamp_unit;
  input.bag.spinning_lidar = input.lidar.type == LidarType::kSpinning;
  input.odometry = driver::DefaultOdometryOptions(input.lidar, input.imu);
  input.odometry.imu_time_offset_s = sim::GivenCalibration(d).imu_time_offset_s;
  input.airframe = sim::DescribeAirframe(d.body);
  return input;
}

}  // namespace swarmlio::testing
