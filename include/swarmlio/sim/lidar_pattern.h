// Scan patterns: the direction (LiDAR frame: x forward, z up) and line of
// pulse number k, fired at time k / pulse_rate_hz() after the sensor started.
// The geometry comes from the shared sensor description (LidarOptions): type,
// scan_rate_hz, points_per_second (pulses fired), num_lines,
// fov_horizontal_deg and fov_vertical_min/max_deg.
//
//  - livox_avia: two counter-rotating Risley prisms deflect each of the
//    num_lines emitters; the sum of two rotating deflection vectors traces a
//    rosette through the centre of the FoV, non-repetitive because the prism
//    rates are incommensurate.
//  - livox_mid360: a head spinning at the scan rate over the horizontal FoV;
//    each line sweeps its own share of the vertical FoV with a fast sinusoid
//    of incommensurate frequency.
//  - spinning: num_lines rings evenly spaced over the vertical FoV, one column
//    per num_lines pulses, one sweep of the horizontal FoV per frame.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "swarmlio/sensors/lidar_options.h"

namespace swarmlio::sim {

class LidarPattern {
 public:
  /// `sensor` must be valid (LidarOptions::Validate()).
  explicit LidarPattern(const LidarOptions& sensor);

  /// Unit direction in the LiDAR frame and line index of pulse `k`.
  void Direction(int64_t k, Eigen::Vector3d* direction_l, uint8_t* line) const;
  int lines() const { return lines_; }
  /// Pulses per frame: points_per_second / scan_rate_hz, rounded (at least 1).
  int64_t pulses_per_frame() const { return pulses_per_frame_; }
  /// Exact pulse rate, pulses_per_frame() * scan_rate_hz [Hz].
  double pulse_rate_hz() const { return pulse_rate_hz_; }

 private:
  LidarOptions sensor_;
  int lines_ = 1;
  int64_t pulses_per_frame_ = 1;
  double pulse_rate_hz_ = 1.0;
  int64_t columns_per_frame_ = 1;  // spinning
};

}  // namespace swarmlio::sim
