// lio::Odometry: the single-drone LiDAR-inertial odometry (paper Sec. III-D,
// ego part; FAST-LIO2's pipeline), a pure core fed with IMU samples and LiDAR
// scans in stamp order. docs/lio.md describes the pipeline and its figures.
//
// Per scan [t_s, t_e] (t_e = stamp + last point time), once IMU data reach t_e:
//   1. preprocess (filters, stride, range gate, voxel) -> points in b with times;
//   2. propagate the state over the scan's IMU samples to t_e (eq. (2)-(3));
//   3. undistort every point to the body frame at t_e;
//   3b. front end of the installed ScanStageHooks (scan_stage_hooks.h):
//      teammate detection on the full scan, extra measurement models;
//   4. iterated update (EsikfUpdate: prior + point-to-plane on Ceres + the
//      hooks' models), every model re-linearized at each iteration;
//   4b. points in the hooks' excluded regions (teammates) are removed;
//   5. insert the registered points into the local map, move the map box.
// The first scan after IMU initialization only builds the map.
// With `estimator: window` steps 4-5 are the fixed-lag window smoother's
// (docs/window.md): the scan's state joins the window, the state that leaves
// it is marginalized and its scan inserted into the map, then the window is
// solved; the output is the newest state and its marginal covariance.
//
// Before the first scan can be used the IMU must initialize from a static
// window (ImuInitializer); scans before that are dropped and counted. With
// `initialization: in_flight` the drone may be moving: after the IMU window,
// LiDAR passes over the first in_flight.probe_duration_s of scans fit the
// initial velocity and gravity (in_flight_alignment.h); initialized() turns
// true, and outputs come, once the last pass has started the odometry.
// Threading: none inside; one instance per drone, not thread-safe.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/lio/odometry_options.h"
#include "swarmlio/lio/scan_stage_hooks.h"
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
  double front_end_s = 0.0;    // the hooks' front end (teammate detection, models)
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
  Eigen::Matrix<double, ErrorStateLayout::kEgoDim, ErrorStateLayout::kEgoDim> covariance;
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
  std::string hook_error;         // the hooks' front-end error ("" otherwise)
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

  /// Feeds one IMU sample (raw units; the initializer finds the unit).
  /// Non-finite or out-of-order samples are dropped and counted: the
  /// returned Status says so (InvalidArgument), nothing else changes. May
  /// process queued scans (outputs via PopOutputs()); an error of that
  /// processing is returned too (the scan is counted and skipped).
  Status AddImu(const ImuSample& sample);

  /// Queues a scan; it is processed once IMU data cover its end. Returns a
  /// non-ok Status when the scan is dropped (empty, out of order, queue full).
  Status AddScan(const LidarScan& scan);

  /// Processes every queued scan with the IMU data at hand (the last input
  /// held up to the scan end): call at the end of a log.
  Status Flush();

  /// Moves the outputs of the scans processed so far into `*outputs`
  /// (appended) and forgets them.
  void PopOutputs(std::vector<ScanOutput>* outputs);

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

  /// Installs the scan-stage hooks (not owned; nullptr removes them).
  void SetHooks(ScanStageHooks* hooks) { hooks_ = hooks; }

  const OdometryCounters& counters() const { return counters_; }
  const OdometryOptions& options() const { return options_; }

 private:
  struct Impl;
  Odometry(const OdometryOptions& options, const LidarOptions& lidar);

  Status ProcessReadyScans(bool flush);
  void SeedMapFromStaticStart(int64_t window_start_ns);
  // In-flight initialization (odometry_in_flight.cc, docs/imu.md section 1b).
  void StartInFlightProbe(const ImuInitialization& coarse);
  // After a pass: fit v0 and g, then restart from t0 (another pass or the
  // odometry proper), or start the initialization over when the fit fails.
  void FinishInFlightPass();
  // Map, window and propagator back to `start` at t0; the buffered IMU
  // samples and scans queued again.
  Status RestartFromInFlightStart(const ImuInitialization& start);
  Status ProcessScan(const LidarScan& scan, int64_t end_ns, bool flush);
  // Steps 4-5 of ProcessScan with each back end: x, P in = the prediction,
  // out = the posterior (or the prediction when not updated).
  void UpdateWithFilter(const UpdateRequest& request, SwarmState* x, Eigen::MatrixXd* P,
                        ScanOutput* out);
  void UpdateWithWindow(const UpdateRequest& request, SwarmState* x, Eigen::MatrixXd* P,
                        ScanOutput* out);
  // Registers the points with x, inserts all but the excluded ones and those
  // listed in skip_indices into the map (moving its box to x) and returns how
  // many were excluded. registered_in_G (cleared) gets every point not
  // excluded.
  int InsertScan(const std::vector<Eigen::Vector3d>& points_in_b, const EgoState& x,
                 const std::vector<ExcludedRegion>& excluded,
                 std::vector<Eigen::Vector3d>* registered_in_G,
                 const std::vector<int>* skip_indices = nullptr);

  OdometryOptions options_;
  LidarOptions lidar_;
  std::unique_ptr<Impl> impl_;
  OdometryCounters counters_;
  ScanStageHooks* hooks_ = nullptr;
  std::string init_error_ = "no IMU data yet";
};

}  // namespace swarmlio::lio
