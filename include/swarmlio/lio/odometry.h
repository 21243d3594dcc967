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

class Odometry {
 public:
  /// InvalidArgument when the options or the LiDAR extrinsic do not validate.
  static Status Create(const OdometryOptions& options,
                       const LidarOptions& lidar,
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
  // The position covariance in G of a committed scan: the filter's plus the
  // calibration's share about the map anchor (set at the first commit with a
  // map; ScanOutput::position_covariance_in_G).
  Eigen::Matrix3d PositionCovarianceInG(const ScanOutput& out);
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
