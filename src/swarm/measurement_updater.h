// One updater per measurement type of the per-drone component
// (docs/architecture.md "Adding a measurement"): each keeps its own pending
// inputs (fed by the component's inbox or front end) and, once per scan,
// turns them into residual terms through the observation gate. The
// component calls the registered updaters in their order; each input is used
// in one scan at most. Internal to src/swarm.
#pragma once

#include <cstdint>
#include <vector>

#include "observation_gate.h"
#include "scan_report.h"
#include "swarmlio/lio/imu_propagator.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::swarm::internal {

/// What an updater sees of the scan being updated.
struct UpdaterScan {
  int64_t t_k = 0;                        // the state time (scan end, own clock)
  const SwarmState* x = nullptr;          // the prediction, teammate blocks current
  const Eigen::MatrixXd* P = nullptr;     // its covariance (layout of x)
  const std::vector<lio::ImuPose>* poses = nullptr;  // the propagated poses over the scan
  bool fusion_enabled = true;             // DroneEstimator::SetFusion
  bool previous_scan_degenerate = false;  // the own last updated scan
  /// Leave out observations involving teammates that report degenerate
  /// scans (SwarmOptions::skip_degenerate_teammates while this drone is
  /// mostly well localized).
  bool skip_degenerate = false;
};

class MeasurementUpdater {
 public:
  virtual ~MeasurementUpdater() = default;
  virtual const char* name() const = 0;
  /// Turns the pending inputs into terms through `gate`; counts in `report`.
  virtual void AddTerms(const UpdaterScan& scan, ObservationGate* gate, ScanReport* report) = 0;
};

}  // namespace swarmlio::swarm::internal
