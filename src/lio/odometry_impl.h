// Internal: the state of lio::Odometry (odometry.cc) and of its in-flight
// initialization (odometry_in_flight.cc). Not installed.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include "swarmlio/lio/calibration_gauge.h"
#include "swarmlio/lio/imu_initializer.h"
#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/lio/in_flight_alignment.h"
#include "swarmlio/lio/input_synchronizer.h"
#include "swarmlio/lio/local_map.h"
#include "swarmlio/lio/parallel_for.h"
#include "swarmlio/lio/odometry.h"
#include "swarmlio/lio/preprocess.h"
#include "src/lio/back_end.h"

namespace swarmlio::lio {
namespace internal {

// An in-flight initialization in progress (docs/imu.md section 1b): the data
// since the start t0 are kept, and each pass runs the odometry over them
// without a front end and without outputs; its scan positions fit v0 and g.
struct InFlightProbe {
  bool active = false;
  int pass = 0;                                         // passes finished
  ImuInitialization start;                              // the current pass's initial state (at t0)
  std::vector<ImuSample> imu;                           // every sample after t0
  std::vector<PendingScan> scans;                       // every queued scan since t0
  std::vector<StampedPose> positions;                   // the current pass's updated scans
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();  // its last posterior b_g
  OdometryCounters counters;                            // the counters when the probe started
};

}  // namespace internal

struct Odometry::Impl {
  std::unique_ptr<ImuInitializer> initializer;
  ImuInitialization initialization;
  bool initialized = false;
  std::unique_ptr<ImuPropagator> propagator;
  std::unique_ptr<Preprocess> preprocess;
  LocalMap map;
  ParallelFor parallel;  // the back end's parallel loops (options.threads)
  std::unique_ptr<internal::BackEnd> back_end;  // filter or window (options.estimator)
  std::deque<ImuSample> imu_queue;                   // after initialization, not yet propagated
  InputSynchronizer input;  // scans waiting for the IMU, the IMU stamps' order
  std::deque<PendingScan> static_start_scans;  // before initialization (map seeding)
  // Static start: initialized, the map not seeded yet. The seed waits for the
  // first scan to process, so that a scan of the static window that arrives
  // after the IMU sample completing the initialization (a live input
  // releasing IMU ahead of the LiDAR, live/push_source.h) still seeds it, as
  // it does in stamp order.
  bool seed_pending = false;
  int64_t seed_window_start_ns = 0;
  internal::InFlightProbe probe;
  bool previous_degenerate = false;  // the last updated scan's flag (front end)
  // Where the map was anchored (the first commit with a map), for the
  // calibration's share of the position covariance in G.
  bool have_anchor = false;
  MapAnchor anchor;
  ScanContext probe_scan;            // scratch of ProcessReadyScans
  // Scratch reused between scans.
  std::vector<PointXYZT> points_in_b;
  std::vector<Eigen::Vector3d> undistorted;

  Impl(const OdometryOptions& options)
      : map(options.map), parallel(options.threads), input(options.max_queued_scans) {}
};

}  // namespace swarmlio::lio
