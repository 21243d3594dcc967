// lio::Odometry: the single-drone LiDAR-inertial odometry (paper Sec. III-D,
// ego part; FAST-LIO2's pipeline), a pure core fed with IMU samples and LiDAR
// scans in stamp order. docs/lio.md describes the pipeline and its figures.
//
// Inputs are queued (AddImu, AddScan); the component that owns the odometry
// drives each scan through its stages once IMU data cover it
// (scan_stages.h):
//   NextScan  1. preprocess (filters, stride, range gate, voxel) -> points in
//                b with times;
//             2. propagate the state over the scan's IMU samples to its end
//                t_e (eq. (2)-(3));
//             3. undistort every point to the body frame at t_e;
//   (the component's front end: teammate detection, extra models)
//   Update    4. iterated update (EsikfUpdate: prior + point-to-plane on
//                Ceres + the component's models), every model re-linearized
//                at each iteration;
//   Commit    5. insert the registered points but those in the excluded
//                regions (teammates) into the local map, move the map box;
//                the scan's output.
// The first scan after IMU initialization only builds the map.
// With `estimator: window` steps 4-5 are the fixed-lag window smoother's
// (docs/window.md): the scan's state joins the window, the state that leaves
// it is marginalized and its scan inserted into the map, then the window is
// solved; the output is the newest state and its marginal covariance.
// ProcessReadyScans runs the stages without a front end (a single drone).
//
// Before the first scan can be used the IMU must initialize from a static
// window (ImuInitializer); scans before that are dropped and counted. With
// `initialization: in_flight` the drone may be moving: after the IMU window,
// LiDAR passes over the first in_flight.probe_duration_s of scans fit the
// initial velocity and gravity (in_flight_alignment.h); NextScan runs those
// passes itself (no front end, no outputs); initialized() turns true, and
// scans reach the caller, once the last pass has started the odometry.
// Threading: none inside; one instance per drone, not thread-safe.
#pragma once

#include <Eigen/Core>
#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/lio/odometry_options.h"
#include "swarmlio/lio/scan_stages.h"
#include "swarmlio/sensors/lidar_options.h"
#include "swarmlio/sensors/measurements.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::lio {
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
  bool updated = false;           // false: map initialisation, too few points, failed update
  // The scan arrived while the in-flight initialization's passes ran and was
  // processed when they ended (docs/imu.md section 1b): its output came that
  // much later, which is the initialization's delay, not the pipeline's.
  bool held_by_initialization = false;
  std::string update_error;       // why an attempted update failed ("" otherwise)
  int num_raw_points = 0;         // points in the message
  int num_points = 0;             // after preprocessing
  int num_correspondences = 0;    // at the last iteration
  int num_measurement_blocks = 0; // residual blocks of all models at the last iteration
  int num_excluded_points = 0;    // kept out of the map (teammates)
  std::string front_end_error;    // the component's front-end or models' error ("" otherwise)
  int iterations = 0;
  bool converged = false;
  /// Smallest eigenvalue of sum n n^T over the last correspondences, and
  /// whether it is below association.degeneracy_threshold.
  double min_normal_information = 0.0;
  bool degenerate = false;
  size_t map_size = 0;            // map points after the insertion
  ScanTimings timings;
  std::vector<Eigen::Vector3d> registered_in_G;  // when output_registered_scan
};

/// One scan between the stages (NextScan -> the caller's front end ->
/// Update -> Commit). Reused from scan to scan.
struct ScanContext {
  LidarScan raw;            // as received (LiDAR frame), reflectivity kept
  int64_t end_ns = 0;       // its last point's time
  int64_t stamp_ns = 0;     // the state's time: end_ns, or the last IMU time when flushing past it
  bool flush = false;       // taken at the end of a log (IMU may not cover it)
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
  std::vector<ExcludedRegion> excluded;  // set by the front end before Update
  ScanOutput out;                        // filled by the stages
  std::chrono::steady_clock::time_point started;  // for timings.total_s
};

/// Counters of everything the odometry skipped or dropped.
struct OdometryCounters {
  int64_t imu_samples = 0;
  int64_t imu_rejected = 0;          // non-finite samples (dropped)
  int64_t imu_out_of_order = 0;      // stamp not after the previous one (dropped)
  int64_t imu_gaps = 0;              // intervals > propagation.max_gap_s (state held)
  int64_t scans = 0;
  int64_t scans_before_init = 0;     // not tracked: IMU not initialized yet
  int64_t scans_seeding_map = 0;     // of those: inserted at the initial pose (static start)
  int64_t scans_out_of_order = 0;    // dropped: started before the previous scan ended
  int64_t scans_empty = 0;           // dropped: no points
  int64_t scans_dropped_queue = 0;   // dropped: waited too long for IMU data
  int64_t scans_processed = 0;
  int64_t scans_updated = 0;
  int64_t scans_degenerate = 0;      // updated scans flagged degenerate
  int64_t updates_failed = 0;        // update refused (prediction kept)
  // The window back end only:
  int64_t window_restarts = 0;       // restarted from the propagator (IMU gap, failed factor)
  int64_t window_reintegrations = 0; // IMU factors preintegrated again at new biases
  // initialization: in_flight only:
  int64_t in_flight_passes = 0;      // alignment passes over the first scans
  int64_t in_flight_restarts = 0;    // fits refused: the initialization started over
};

class Odometry {
 public:
  /// InvalidArgument when the options or the LiDAR extrinsic do not validate.
  static Status Create(const OdometryOptions& options, const LidarOptions& lidar,
                       std::unique_ptr<Odometry>* odometry);
  ~Odometry();

  /// Queues one IMU sample (raw units; the initializer finds the unit).
  /// Non-finite or out-of-order samples are dropped and counted: the
  /// returned Status says so (InvalidArgument), nothing else changes.
  Status AddImu(const ImuSample& sample);

  /// Queues a scan; NextScan hands it out once IMU data cover its end.
  /// Returns a non-ok Status when a scan is dropped (empty, out of order,
  /// queue full).
  Status AddScan(const LidarScan& scan);

  /// Steps 1-3 of the next scan whose end the IMU data cover (with `flush`:
  /// the next queued scan, the last input held up to its end). False when no
  /// scan is ready. True: `scan` holds it; when scan->predicted the caller
  /// runs its front end, then Update and Commit; otherwise scan->status says
  /// why it was dropped. Runs the in-flight initialization's passes itself.
  bool NextScan(bool flush, ScanContext* scan);

  /// Step 4 with the request's models (filter or window back end).
  void Update(const UpdateRequest& request, ScanContext* scan);

  /// Step 5 and the scan's output (moved into *output). Returns scan->status.
  Status Commit(ScanContext* scan, ScanOutput* output);

  /// The end of a log, after the last NextScan(flush = true): a pending map
  /// seed is made, and the scans still in the window enter the map.
  void FinishLog();

  /// A single drone without a front end: every ready scan through the stages
  /// (outputs appended); with `flush`, every queued scan and FinishLog().
  /// Returns the first error of a scan (the scan is counted and skipped).
  Status ProcessReadyScans(bool flush, std::vector<ScanOutput>* outputs);

  bool initialized() const;
  /// Why the IMU has not initialized yet ("" once it has).
  const std::string& initialization_error() const { return init_error_; }
  /// The initialization result (valid once initialized()).
  const ImuInitialization& initialization() const;

  /// Current full state and covariance (the last update or propagation).
  const SwarmState& state() const;
  const Eigen::MatrixXd& covariance() const;

  /// Every map point (G frame), e.g. to save the map at the end.
  std::vector<Eigen::Vector3d> MapPoints() const;
  size_t map_size() const;
  size_t MapMemoryBytes() const;

  const OdometryCounters& counters() const { return counters_; }
  const OdometryOptions& options() const { return options_; }

 private:
  struct Impl;
  Odometry(const OdometryOptions& options, const LidarOptions& lidar);

  void SeedMapFromStaticStart(int64_t window_start_ns);
  // In-flight initialization (odometry_in_flight.cc, docs/imu.md section 1b).
  void StartInFlightProbe(const ImuInitialization& coarse);
  // After a pass: fit v0 and g, then restart from t0 (another pass or the
  // odometry proper), or start the initialization over when the fit fails.
  void FinishInFlightPass();
  // Map, window and propagator back to `start` at t0; the buffered IMU
  // samples and scans queued again.
  Status RestartFromInFlightStart(const ImuInitialization& start);
  // Steps 1-3 of scan->raw (NextScan).
  void Predict(ScanContext* scan);
  // Step 2: the state over the scan's IMU samples to its end; false (and
  // scan->status) when the scan cannot be used.
  bool Propagate(ScanContext* scan);
  // A scan of an in-flight probe pass: the stages without front end and
  // output; its position feeds the pass's fit.
  void ProcessProbeScan(ScanContext* scan);
  // The back end options_.estimator names (filter or window), on the map
  // and the propagator; replaces any previous one.
  Status CreateBackEnd();

  OdometryOptions options_;
  LidarOptions lidar_;
  std::unique_ptr<Impl> impl_;
  OdometryCounters counters_;
  std::string init_error_ = "no IMU data yet";
};

}  // namespace swarmlio::lio
