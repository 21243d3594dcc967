// Options of a simulated LiDAR: the project's sensor description
// (swarmlio::LidarOptions, the `lidar` section of configs/*.yaml) plus what
// only the simulator needs. See docs/simulator.md for the models.
#pragma once

#include <string>

#include "swarmlio/config/option_fields.h"
#include "swarmlio/sensors/lidar_options.h"

namespace swarmlio::sim {

/// Reflectivity on the Livox 0-255 scale: 0-150 diffuse, 151-255 retro-reflective.
struct ReflectivityOptions {
  double diffuse_range_falloff_m = 80.0;  // diffuse value *= 1 / (1 + (r / this)^2)
  double diffuse_noise_sigma = 2.0;       // [reflectivity units]
  double retro_range_scale_m = 25.0;      // retro excess *= exp(-r / this)
  double retro_incidence_exponent = 0.5;  // retro excess *= cos(incidence)^this
  double retro_noise_sigma = 8.0;         // [reflectivity units]

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    using config::FieldSpec;
    v("diffuse_range_falloff_m", diffuse_range_falloff_m,
      FieldSpec::Positive("m", "range at which diffuse reflectivity halves"));
    v("diffuse_noise_sigma", diffuse_noise_sigma, FieldSpec::AtLeast(0.0, "", "diffuse noise"));
    v("retro_range_scale_m", retro_range_scale_m,
      FieldSpec::Positive("m", "e-folding range of the retro-reflective excess"));
    v("retro_incidence_exponent", retro_incidence_exponent,
      FieldSpec::AtLeast(0.0, "", "exponent of cos(incidence) for retro-reflectors"));
    v("retro_noise_sigma", retro_noise_sigma, FieldSpec::AtLeast(0.0, "", "retro noise"));
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

/// A simulated LiDAR. `sensor` says what it is (pattern from `type`, FoV,
/// scan rate, points per second = pulses fired, lines, blind/max range, range
/// noise, extrinsic, message format); its keys sit directly in the YAML
/// section next to the simulation-only ones below.
struct SimulatedLidarOptions {
  LidarOptions sensor;
  double dropout_probability = 0.01;  // random missing returns
  double start_time_s = 0.0;          // true time of the first pulse of frame 0 [s]
  ReflectivityOptions reflectivity;

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    using config::FieldSpec;
    sensor.VisitFields(v);
    v("dropout_probability", dropout_probability,
      FieldSpec::InRange(0.0, 1.0, "", "simulator: probability that a return is lost"));
    v("start_time_s", start_time_s,
      FieldSpec::InRange(0.0, 1.0, "s", "simulator: true time of the first frame"));
    v("reflectivity", reflectivity);
  }
  /// "" when valid, else "key: reason" (keys as in YAML: "blind_range_m").
  std::string Validate() const;
};

}  // namespace swarmlio::sim
