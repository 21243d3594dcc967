// OdometryOptions: every setting of the single-drone LiDAR-inertial odometry
// (lio::Odometry), one YAML section `odometry:` (docs/lio.md lists the keys).
// Sensor-dependent defaults come from OdometryOptionsFor(LidarOptions).
#pragma once

#include <string>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/lio/esikf_update.h"
#include "swarmlio/lio/imu_initializer.h"
#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/lio/in_flight_init_options.h"
#include "swarmlio/lio/local_map.h"
#include "swarmlio/lio/preprocess.h"
#include "swarmlio/lio/scan_association.h"
#include "swarmlio/lio/window_options.h"
#include "swarmlio/sensors/lidar_options.h"

namespace swarmlio::lio {

struct OdometryOptions {
  /// The back end: the iterated filter update (default) or the fixed-lag
  /// window smoother (docs/window.md) over the same factors.
  EstimatorKind estimator = EstimatorKind::kFilter;
  /// static (default): the start must be at rest (docs/imu.md section 1);
  /// in_flight: velocity and gravity from LiDAR passes over the first scans
  /// (section 1b), for a drone that joins or restarts while flying.
  InitializationMode initialization = InitializationMode::kStatic;
  ImuInitializerOptions imu_init;
  InFlightInitOptions in_flight;
  ImuPropagatorOptions propagation;
  PreprocessOptions preprocess;
  LocalMapOptions map;
  ScanAssociationOptions association;
  EsikfUpdateOptions update;
  /// The window smoother (used when estimator is window).
  WindowOptions window;
  /// IMU stamps are this much later than the LiDAR's clock; subtracted from
  /// every IMU stamp (FAST-LIO time_offset_lidar_to_imu) [s].
  double imu_time_offset_s = 0.0;
  /// A scan with fewer preprocessed points is not used for an update (the
  /// state is only propagated) [points].
  int min_scan_points = 20;
  /// Scans waiting for IMU data beyond this many: the oldest is dropped
  /// (the IMU stream stopped) [scans].
  int max_queued_scans = 20;
  /// Keep the registered (posterior, G frame) downsampled scan in each output.
  bool output_registered_scan = false;
  /// Seed the map (static initialization only) with the scans that lie
  /// wholly inside the static IMU
  /// initialization window, at the initial pose (the window's static test
  /// shows the drone did not move). A narrow-FoV LiDAR's first scan alone is
  /// a sparse map whose plane fits tilt the first registrations (0.2 deg on
  /// the simulated Avia); the window's scans make it dense at no risk.
  bool seed_map_from_static_start = true;
  /// Insert also the scan points that the update matched to a map plane.
  /// FAST-LIO2 inserts every point; off (the default), only the points the
  /// map does not explain yet enter it, so that a revisit with a different
  /// pose error does not write a second copy of a surface whose streaks then
  /// fit planes facing the wrong way (docs/lio.md "Map insertion"). The
  /// window back end applies it to each scan leaving the window, with that
  /// scan's last association.
  bool insert_matched_points = false;
  /// (experimental) Threads of the per-scan work that runs in parallel (the neighbour
  /// searches and plane fits of the scan association); 0 = the machine's,
  /// capped at 4. Trajectories are bit-identical for any value (docs/lio.md
  /// "Threads").
  int threads = 0;

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("estimator", estimator,
      FieldSpec::Doc("back end: filter (iterated ESIKF) or window (fixed-lag smoother)"));
    v("initialization", initialization,
      FieldSpec::Doc("static (start at rest, default) or in_flight (velocity and gravity from "
                     "the first LiDAR scans; for a late join or a restart while flying)"));
    v("propagation", propagation);
    v("preprocess", preprocess);
    v("map", map);
    v("window", window);
    v("imu_time_offset_s", imu_time_offset_s,
      FieldSpec::InRange(-1.0, 1.0, "s", "subtracted from IMU stamps (IMU clock minus LiDAR clock)"));
    config::VisitExperimental(v, [&](auto& x) {
      x("threads", threads,
        FieldSpec::InRange(0.0, 256.0, "", "threads of the scan association; 0 = the machine's, "
                                           "at most 4 (results identical for any value)"));
      x("imu_init", imu_init);
      x("in_flight", in_flight);
      x("association", association);
      x("update", update);
      x("min_scan_points", min_scan_points,
        FieldSpec::InRange(1.0, 1e6, "", "fewer preprocessed points: propagate only, no update"));
      x("max_queued_scans", max_queued_scans,
        FieldSpec::InRange(1.0, 1000.0, "", "scans waiting for IMU data before the oldest is dropped"));
      x("output_registered_scan", output_registered_scan,
        FieldSpec::Doc("keep the registered scan (G frame) in each per-scan output"));
      x("seed_map_from_static_start", seed_map_from_static_start,
        FieldSpec::Doc("insert the scans inside the static IMU-initialization window into the map "
                       "at the initial pose"));
      x("insert_matched_points", insert_matched_points,
        FieldSpec::Doc("also insert the scan points matched to a map plane (FAST-LIO2); false: "
                       "only the points the map does not explain"));
    });
  }

  /// "" when valid, else "key: reason".
  std::string Validate() const { return config::ValidateFields(*this); }
};

/// Defaults for a sensor: preprocessing from PreprocessOptionsFor(lidar), the
/// map voxel from Swarm-LIO2's configs (filter_size_map 0.3 m Mid-360, 0.25 m
/// Avia, 0.5 m otherwise) and the map cube from the sensor's max range.
OdometryOptions OdometryOptionsFor(const LidarOptions& lidar);

}  // namespace swarmlio::lio
