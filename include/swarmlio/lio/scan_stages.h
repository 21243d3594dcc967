// What the stages of lio::Odometry's scan pipeline exchange with the
// component that drives them (swarm::DroneEstimator, or
// Odometry::ProcessReadyScans for a single drone). The component calls the
// stages top-down, once per scan:
//
//   odometry.NextScan(flush, &scan)    preprocess, propagate, undistort
//   ... the component's front end: teammate detection on scan.raw with
//       scan.poses, teammate blocks added to / removed from scan.x, scan.P,
//       measurement models built, scan.excluded filled ...
//   odometry.Update(request, &scan)    prior + point-to-plane + the request's
//                                      models (filter or window back end)
//   odometry.Commit(&scan, &output)    map insertion without scan.excluded,
//                                      the scan's output
//
// The scan between the stages (ScanContext), its output (ScanOutput, with
// ScanTimings) and the odometry's counters live here, so a back end needs
// this header and not the odometry's.
#pragma once

#include <Eigen/Core>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/lio/measurement_model.h"
#include "swarmlio/sensors/measurements.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::lio {

/// A ball in the body frame at the scan end whose points stay out of the map.
struct ExcludedRegion {
  Eigen::Vector3d center_in_b = Eigen::Vector3d::Zero();  // [m]
  double radius_m = 0.0;
};

/// The measurement models a component adds to the scan's update.
struct UpdateRequest {
  std::vector<MeasurementModel*> models;  // not owned; valid until Update returns
  /// true: only `estimated_teammates` are corrected (the other blocks are
  /// held, or considered); false: every teammate block not considered is.
  bool select_teammates = false;
  /// Teammate blocks the update estimates (the others: Schmidt "consider").
  std::vector<int> estimated_teammates;
  /// Teammate blocks the models' residuals name that the update does not
  /// correct (EsikfUpdate::Run, "considered teammates").
  std::vector<int> considered_teammates;
};

/// Wall time of each stage of one scan [s].
struct ScanTimings {
  double preprocess_s = 0.0;   // filters + voxel downsampling
  double propagate_s = 0.0;    // IMU propagation over the scan
  double undistort_s = 0.0;    // motion compensation
  double association_s = 0.0;  // kNN + plane fits, all iterations (window: all its scans)
  double solve_s = 0.0;        // ceres::Solve, all iterations
  double covariance_s = 0.0;   // posterior covariance (window: the newest state's marginal)
  double front_end_s = 0.0;    // the component's front end (teammate detection, models)
  double map_update_s = 0.0;   // registration into G + map insertion + box move
  // The window back end only (0 with the filter; docs/window.md):
  double build_s = 0.0;        // IMU re-integration + problem construction
  double marginalize_s = 0.0;  // adding the state, marginalizing the states that leave
  double total_s = 0.0;        // whole scan, including everything above
};

/// What the odometry reports for one processed scan.
struct ScanOutput {
  int64_t scan_stamp_ns = 0;  // the scan's stamp (its first point time)
  int64_t stamp_ns = 0;       // the state's time: the scan end
  EgoState state;             // posterior (or prediction when not updated)
  Eigen::Matrix<double, ErrorStateLayout::kEgoDim, ErrorStateLayout::kEgoDim> covariance =
      Eigen::Matrix<double, ErrorStateLayout::kEgoDim, ErrorStateLayout::kEgoDim>::Zero();
  /// The position block of `covariance` plus the LiDAR-IMU calibration's
  /// uncertainty, which moves the whole map (lio/calibration_gauge.h): the
  /// covariance of p_b_in_G against the true G [m^2].
  Eigen::Matrix3d position_covariance_in_G = Eigen::Matrix3d::Zero();
  bool updated = false;  // false: map initialisation, too few points, failed update
  // The scan arrived while the in-flight initialization's passes ran and was
  // processed when they ended (docs/imu.md section 1b): its output came that
  // much later, which is the initialization's delay, not the pipeline's.
  bool held_by_initialization = false;
  std::string update_error;        // why an attempted update failed ("" otherwise)
  int num_raw_points = 0;          // points in the message
  int num_points = 0;              // after preprocessing
  int num_correspondences = 0;     // at the last iteration
  int num_measurement_blocks = 0;  // residual blocks of all models at the last iteration
  int num_excluded_points = 0;     // kept out of the map (teammates)
  std::string front_end_error;     // the component's front-end or models' error ("" otherwise)
  int iterations = 0;
  bool converged = false;
  /// Smallest eigenvalue of sum n n^T over the last correspondences, and
  /// whether it is below association.degeneracy_threshold.
  double min_normal_information = 0.0;
  bool degenerate = false;
  size_t map_size = 0;  // map points after the insertion
  ScanTimings timings;
  std::vector<Eigen::Vector3d> registered_in_G;  // when output_registered_scan
};

/// One scan between the stages (NextScan -> the caller's front end ->
/// Update -> Commit). Reused from scan to scan.
struct ScanContext {
  LidarScan raw;         // as received (LiDAR frame), reflectivity kept
  int64_t end_ns = 0;    // its last point's time
  int64_t stamp_ns = 0;  // the state's time: end_ns, or the last IMU time when flushing past it
  bool flush = false;    // taken at the end of a log (IMU may not cover it)
  /// Steps 1-3 succeeded; false: `status` says why and the scan is dropped.
  bool predicted = false;
  /// The scan's first error (an IMU gap, a propagation error); the scan is
  /// still processed when `predicted`.
  Status status;
  /// The propagated poses over the scan (undistortion); valid until the
  /// next NextScan.
  const std::vector<ImuPose>* poses = nullptr;
  bool previous_scan_degenerate = false;  // the last updated scan's degeneracy flag
  /// The prediction at the scan end; the front end may add or remove
  /// teammate blocks (layout and covariance together). After Update: the
  /// posterior (or the prediction when not updated).
  SwarmState x;
  Eigen::MatrixXd P;
  std::vector<ExcludedRegion> excluded;           // set by the front end before Update
  ScanOutput out;                                 // filled by the stages
  std::chrono::steady_clock::time_point started;  // for timings.total_s
};

/// Counters of everything the odometry skipped or dropped.
struct OdometryCounters {
  int64_t imu_samples = 0;
  int64_t imu_rejected = 0;      // non-finite samples (dropped)
  int64_t imu_out_of_order = 0;  // stamp not after the previous one (dropped)
  int64_t imu_gaps = 0;          // intervals > propagation.max_gap_s (state held)
  int64_t scans = 0;
  int64_t scans_before_init = 0;    // not tracked: IMU not initialized yet
  int64_t scans_seeding_map = 0;    // of those: inserted at the initial pose (static start)
  int64_t scans_out_of_order = 0;   // dropped: started before the previous scan ended
  int64_t scans_empty = 0;          // dropped: no points
  int64_t scans_dropped_queue = 0;  // dropped: waited too long for IMU data
  int64_t scans_processed = 0;
  int64_t scans_updated = 0;
  int64_t scans_degenerate = 0;  // updated scans flagged degenerate
  int64_t updates_failed = 0;    // update refused (prediction kept)
  // The window back end only:
  int64_t window_restarts = 0;        // restarted from the propagator (IMU gap, failed factor)
  int64_t window_reintegrations = 0;  // IMU factors preintegrated again at new biases
  // initialization: in_flight only:
  int64_t in_flight_passes = 0;    // alignment passes over the first scans
  int64_t in_flight_restarts = 0;  // fits refused: the initialization started over
};

}  // namespace swarmlio::lio
