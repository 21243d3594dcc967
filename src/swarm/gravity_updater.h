// Gravity alignment (docs/swarm.md "Gravity"): a teammate's gravity in its
// frame G_j, from its extrinsic broadcasts, against this drone's gravity
// rotated by T_Gi_Gj; one term per received broadcast, not while the
// extrinsics are frozen. The worked example of docs/architecture.md
// "Adding a measurement". Internal to src/swarm.
#pragma once

#include <Eigen/Core>
#include <map>

#include "measurement_updater.h"
#include "swarmlio/swarm/drone_estimator.h"
#include "swarmlio/swarm/swarm_options.h"

namespace swarmlio::swarm::internal {

class GravityUpdater final : public MeasurementUpdater {
 public:
  GravityUpdater(const SwarmOptions& options, DroneEstimatorCounters* counters)
      : options_(options), counters_(counters) {}
  const char* name() const override { return "gravity_alignment"; }

  /// Teammate `sender`'s gravity in its G_j (the newest replaces an unused one).
  void Queue(int sender, const Eigen::Vector3d& g_in_Gj, const Eigen::Matrix3d& covariance);

  void AddTerms(const UpdaterScan& scan, ObservationGate* gate, ScanReport* report) override;

 private:
  struct Pending {
    Eigen::Vector3d g_in_Gj = Eigen::Vector3d::Zero();
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  };
  SwarmOptions options_;
  DroneEstimatorCounters* counters_;
  std::map<int, Pending> pending_;  // by sender, until its block exists
};

}  // namespace swarmlio::swarm::internal
