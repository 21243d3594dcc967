// Options of a simulated LiDAR: the project's sensor description
// (swarmlio::LidarOptions, the `lidar` section of configs/*.yaml) plus what
// only the simulator needs. See docs/simulator.md for the models.
#pragma once

#include <string>

#include "swarmlio/common/option_fields.h"
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

/// LiDAR imperfections beyond white range noise and random dropouts
/// (docs/simulator.md, "Imperfections"). Every default is off: the `ideal`
/// preset; RealisticLidarImperfections() (imperfections.h) gives the
/// `realistic` values of each LiDAR type. With all of them off a LiDAR
/// produces the same points as before they existed.
///
///   beam:   the beam leaves along the nominal direction rotated by
///           N(0, angular_noise) about two axes normal to it; the point is
///           reported along the nominal direction (encoder error).
///   range:  r_meas = r + bias(reflectivity) + N(0, sigma(r, inc)),
///           sigma^2 = range_noise_stddev_m^2 + (range_noise_per_m * r)^2
///                     + [incidence_noise] (r * div * tan(inc) / 4)^2,
///           div = RMS of the two divergences, inc clamped to 85 deg (the depth
///           spread of a uniform footprint on a slanted surface);
///           bias = low_reflectivity_bias_m * max(0, 1 - refl / low_reflectivity_threshold).
///   edges:  a second sample uniform in the elliptic footprint (full angles
///           beam_divergence_*_deg); if it hits another surface (primitive or
///           object) more than edge_min_separation_m away in range, the
///           footprint straddles a depth edge: with mixed_pixel_probability
///           the return is placed at r + w (r_other - r), w ~ U(0, 1) (a mixed
///           pixel); with multi_return the sensor reports both surfaces
///           instead (Livox tag return bits 5:4 = 01 near, 10 far).
///   loss:   a return is also lost with probability
///           range_dropout_at_max_range * (r / max_range_m)^range_dropout_exponent.
struct LidarImperfectionOptions {
  double angular_noise_deg = 0.0;               // 1-sigma per axis of the beam direction [deg]
  double range_noise_per_m = 0.0;               // range-proportional noise [m per m]
  bool incidence_noise = false;                 // footprint depth spread on slanted surfaces
  double beam_divergence_horizontal_deg = 0.0;  // full angle, in the LiDAR's x-y plane [deg]
  double beam_divergence_vertical_deg = 0.0;    // full angle, normal to it [deg]
  double mixed_pixel_probability = 0.0;         // a return straddling a depth edge is mixed
  double edge_min_separation_m = 0.1;           // closer surfaces in one footprint are one [m]
  bool multi_return = false;                    // report both surfaces of a straddling footprint
  double low_reflectivity_bias_m = 0.0;         // range walk at reflectivity 0, + = long [m]
  double low_reflectivity_threshold = 20.0;     // no walk at or above this (Livox 0-255)
  double range_dropout_at_max_range = 0.0;      // loss probability at max_range_m
  double range_dropout_exponent = 2.0;          // growth of the loss probability with range

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    using config::FieldSpec;
    v("angular_noise_deg", angular_noise_deg,
      FieldSpec::InRange(0.0, 5.0, "deg", "1-sigma beam direction error per axis"));
    v("range_noise_per_m", range_noise_per_m,
      FieldSpec::InRange(0.0, 0.1, "m/m", "range noise growing with range (in quadrature)"));
    v("incidence_noise", incidence_noise,
      FieldSpec::Doc("add the footprint's depth spread on slanted surfaces to the range noise"));
    v("beam_divergence_horizontal_deg", beam_divergence_horizontal_deg,
      FieldSpec::InRange(0.0, 5.0, "deg", "beam divergence (full angle) in the LiDAR x-y plane"));
    v("beam_divergence_vertical_deg", beam_divergence_vertical_deg,
      FieldSpec::InRange(0.0, 5.0, "deg", "beam divergence (full angle) normal to the x-y plane"));
    v("mixed_pixel_probability", mixed_pixel_probability,
      FieldSpec::InRange(0.0, 1.0, "", "a return whose footprint straddles a depth edge is mixed"));
    v("edge_min_separation_m", edge_min_separation_m,
      FieldSpec::Positive("m", "range gap that makes two surfaces in one footprint an edge"));
    v("multi_return", multi_return,
      FieldSpec::Doc("dual return: report both surfaces of a straddling footprint (tag bits)"));
    v("low_reflectivity_bias_m", low_reflectivity_bias_m,
      FieldSpec::InRange(-1.0, 1.0, "m", "range walk of a return with reflectivity 0 (+ = long)"));
    v("low_reflectivity_threshold", low_reflectivity_threshold,
      FieldSpec::Positive("", "reflectivity (0-255) at and above which there is no walk")
          .WithMax(255.0));
    v("range_dropout_at_max_range", range_dropout_at_max_range,
      FieldSpec::InRange(0.0, 1.0, "", "probability that a return at max_range_m is lost"));
    v("range_dropout_exponent", range_dropout_exponent,
      FieldSpec::InRange(0.0, 10.0, "", "loss probability grows as (range / max_range_m)^this"));
  }
  /// "" when valid, else "key: reason".
  std::string Validate() const;
  /// True when the footprint is sampled (mixed pixels or multiple returns).
  bool SamplesFootprint() const { return mixed_pixel_probability > 0.0 || multi_return; }
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
  LidarImperfectionOptions imperfections;  // all off by default (the `ideal` preset)

  template <class Visitor>
  void VisitFields(Visitor&& v) {
    using config::FieldSpec;
    sensor.VisitFields(v);
    v("dropout_probability", dropout_probability,
      FieldSpec::InRange(0.0, 1.0, "", "simulator: probability that a return is lost"));
    v("start_time_s", start_time_s,
      FieldSpec::InRange(0.0, 1.0, "s", "simulator: true time of the first frame"));
    v("reflectivity", reflectivity);
    v("imperfections", imperfections,
      FieldSpec::Doc("simulator: LiDAR imperfections (over the scenario's `imperfections:`)"));
  }
  /// "" when valid, else "key: reason" (keys as in YAML: "blind_range_m").
  std::string Validate() const;
};

}  // namespace swarmlio::sim
