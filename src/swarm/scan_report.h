// What the per-drone component records of one scan beside the odometry's
// output (swarm::DroneOutput's swarm part). Internal to src/swarm.
#pragma once

#include <map>
#include <utility>
#include <vector>

#include "swarmlio/swarm/drone_estimator.h"

namespace swarmlio::swarm::internal {

struct ScanReport {
  std::vector<IdentificationEvent> identifications;
  std::vector<int> removed;
  int active = 0;
  int passive = 0;
  int gravity = 0;
  int rejected = 0;
  int skipped_degenerate = 0;
  bool frozen = false;
  int detector_points = 0;
  std::map<int, std::pair<int, int>> fused_by_teammate;  // id -> active, passive
};

}  // namespace swarmlio::swarm::internal
