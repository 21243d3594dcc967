// Active observations (docs/swarm.md section 4): this scan's LiDAR
// detections of identified teammates, against their newest broadcast state
// predicted to the scan end. Internal to src/swarm.
#pragma once

#include <vector>

#include "measurement_updater.h"
#include "swarmlio/swarm/drone_estimator.h"
#include "swarmlio/swarm/swarm_options.h"
#include "swarmlio/teammate/observation.h"
#include "teammate_registry.h"

namespace swarmlio::swarm::internal {

class ActiveObservationUpdater final : public MeasurementUpdater {
 public:
  /// `observations`: the detector's of the current scan; the pointers outlive the updater.
  ActiveObservationUpdater(const SwarmOptions& options, TeammateRegistry* registry,
                           const std::vector<teammate::TeammateObservation>* observations,
                           DroneEstimatorCounters* counters)
      : options_(options), registry_(registry), observations_(observations), counters_(counters) {}
  const char* name() const override { return "active_observation"; }
  void AddTerms(const UpdaterScan& scan, ObservationGate* gate, ScanReport* report) override;

 private:
  SwarmOptions options_;
  TeammateRegistry* registry_;
  const std::vector<teammate::TeammateObservation>* observations_;
  DroneEstimatorCounters* counters_;
};

}  // namespace swarmlio::swarm::internal
