#include "swarmlio/sim/lidar_pattern.h"

#include <algorithm>
#include <cmath>

#include "swarmlio/common/check.h"
#include "swarmlio/math/angles.h"

namespace swarmlio::sim {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

// Avia: prism rates [rev/s] (incommensurate, counter-rotating) and the small
// angular offsets of the emitters (a slanted column).
constexpr double kAviaPrism1RevPerS = 97.31;
constexpr double kAviaPrism2RevPerS = -71.93;
constexpr double kAviaEmitterSpacing = 0.45 * kRadiansPerDegree;

// Mid-360: line sweep frequency [Hz] (incommensurate with the scan rate so the
// pattern precesses).
constexpr double kMidSweepHz = 1537.77;

Eigen::Vector3d FromAngles(double azimuth, double elevation) {
  const double ce = std::cos(elevation);
  return Eigen::Vector3d(ce * std::cos(azimuth), ce * std::sin(azimuth), std::sin(elevation));
}

}  // namespace

LidarPattern::LidarPattern(const LidarOptions& sensor) : sensor_(sensor) {
  CHECK(sensor_.Validate().empty()) << sensor_.Validate();
  lines_ = sensor_.num_lines;
  pulses_per_frame_ = std::max<int64_t>(
      1, std::llround(static_cast<double>(sensor_.points_per_second) / sensor_.scan_rate_hz));
  pulse_rate_hz_ = static_cast<double>(pulses_per_frame_) * sensor_.scan_rate_hz;
  columns_per_frame_ = std::max<int64_t>(1, pulses_per_frame_ / lines_);
}

void LidarPattern::Direction(int64_t k, Eigen::Vector3d* direction_l, uint8_t* line) const {
  const double t = static_cast<double>(k) / pulse_rate_hz_;
  const int l = static_cast<int>(k % lines_);
  const double fov_h = sensor_.fov_horizontal_deg * kRadiansPerDegree;
  const double el_min = sensor_.fov_vertical_min_deg * kRadiansPerDegree;
  const double el_max = sensor_.fov_vertical_max_deg * kRadiansPerDegree;
  *line = static_cast<uint8_t>(l);
  switch (sensor_.type) {
    case LidarType::kLivoxAvia: {
      // Both prisms deflect by the same angle: the sum of two unit rotating
      // vectors, halved, stays in the unit disc and passes through its centre.
      const double a1 = kTwoPi * std::fmod(kAviaPrism1RevPerS * t, 1.0);
      const double a2 = kTwoPi * std::fmod(kAviaPrism2RevPerS * t, 1.0) + 0.3;
      const double dx = 0.5 * (std::cos(a1) + std::cos(a2));
      const double dy = 0.5 * (std::sin(a1) + std::sin(a2));
      const double offset = (l - 0.5 * (lines_ - 1)) * kAviaEmitterSpacing;
      *direction_l = FromAngles(0.5 * fov_h * dx + 0.3 * offset,
                                0.5 * (el_max + el_min) + 0.5 * (el_max - el_min) * dy + offset);
      return;
    }
    case LidarType::kLivoxMid360: {
      const double turn =
          std::fmod(sensor_.scan_rate_hz * t + static_cast<double>(l) / lines_, 1.0);
      const double band = (el_max - el_min) / lines_;
      const double phase = kTwoPi * std::fmod(kMidSweepHz * t, 1.0) + l * 1.3;
      *direction_l =
          FromAngles(fov_h * (turn - 0.5), el_min + band * (l + 0.5 + 0.5 * std::sin(phase)));
      return;
    }
    case LidarType::kSpinning: {
      const int64_t column = (k / lines_) % columns_per_frame_;
      const double ring = lines_ > 1 ? static_cast<double>(l) / (lines_ - 1) : 0.5;
      *direction_l = FromAngles(fov_h * (static_cast<double>(column) / columns_per_frame_ - 0.5),
                                el_min + (el_max - el_min) * ring);
      return;
    }
  }
}

}  // namespace swarmlio::sim
