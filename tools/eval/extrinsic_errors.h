// Extrinsic error of an observer's T_Gi_Gj estimates over time against the
// true global frames of a simulated swarm (`swarmlio_eval extrinsics`): reads
// an `<observer>_extrinsics.csv` written by swarmlio_replay or swarmlio_live
// and the manifest whose drones carry their G frames in the simulation world
// (p_G_in_W_m, q_W_G_xyzw). The same definitions as the replay's swarm
// report (docs/replay.md "Swarm outputs"). Tool-side: reads files.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/driver/manifest.h"

namespace swarmlio::tools {

struct ExtrinsicErrorRow {
  std::string teammate;
  int estimates = 0;       // rows of the CSV for this teammate
  double first_s = 0.0;    // stamp of the first estimate (identification) [s]
  double last_s = 0.0;     // stamp of the last estimate [s]
  double end_m = 0.0;      // |p_Gj_in_Gi - truth| at the last estimate [m]
  double end_deg = 0.0;    // rotation error at the last estimate [deg]
  double max_m = 0.0;      // over all estimates
  double max_deg = 0.0;
};

/// One row per teammate in the file, in order of first appearance. Errors
/// name the file and line; a teammate not in the manifest is an error.
/// `origins`: drones whose estimator started later than the simulation (a
/// late join, a restart) have their global frame at their body pose at that
/// stamp (the IMU initialization, docs/conventions.md), taken from their
/// ground-truth TUM file: name -> stamp [s, the drone's clock].
Status EvaluateExtrinsicErrors(const std::string& csv_path,
                               const driver::SwarmManifest& manifest,
                               const std::string& observer,
                               const std::map<std::string, double>& origins,
                               std::vector<ExtrinsicErrorRow>* rows);

}  // namespace swarmlio::tools
