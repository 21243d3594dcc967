// Swarm outputs of a replay run (docs/replay.md "Swarm outputs"): per
// observer i and teammate j, j's body pose in G_i (TUM), the T_Gi_Gj
// estimates over time (CSV), identifications (CSV), a merged map of all
// drones in G of the first drone, and the swarm metrics against the truth
// (teammate relative-position error, extrinsic error, identification time),
// plus a plot of the extrinsic error over time. Tool-side: writes files.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/replay/swarm_replay.h"

namespace swarmlio::tools {

/// A teammate is in view in a scan when its body returned at least this many
/// points (the definition of "in view").
constexpr int kInViewReturns = 10;
/// Initial T_Gi_Gj position error beyond which an identification counts as
/// wrong: the match took another drone's or a decoy's track (the drones fly
/// >= 1 m apart; a right match on a short, poorly excited track can start
/// several degrees off but within a few centimetres; docs/replay.md).
constexpr double kWrongIdentificationM = 0.5;

/// One observer-teammate pair.
struct PairMetrics {
  std::string observer;
  std::string teammate;
  bool identified = false;
  double identification_s = 0.0;   // since the observer's first scan [s]
  double since_excitation_s = 0.0; // since the later excitation start of the pair (truth) [s]
  double initial_error_m = 0.0;    // T_Gi_Gj from the trajectory match vs truth [m]
  double initial_error_deg = 0.0;  // ... [deg] (a wrong identification shows here)
  double extrinsic_end_m = 0.0;    // |p error| at the last scan [m]
  double extrinsic_end_deg = 0.0;  // rotation error at the last scan [deg]
  double extrinsic_max_m = 0.0;    // max over the scans after identification
  double extrinsic_max_deg = 0.0;
  double relative_rmse_m = 0.0;    // j's position in G_i vs truth, RMSE [m]
  int relative_samples = 0;
  int active_fused = 0;
  int passive_fused = 0;
  /// Scans after the identification in which j's body returned at least
  /// kInViewReturns points (simulator truth, manifest `teammate_returns`;
  /// -1 when the manifest has none), and how many of them fused an active
  /// observation of j.
  int scans_in_view = -1;
  int fused_in_view = 0;
  /// The identification's first T_Gi_Gj position is off the truth by more
  /// than kWrongIdentificationM: j was matched to the wrong track (another
  /// drone or a decoy).
  bool wrong_identification = false;
  /// The observer's estimate of the teammate's clock offset at its last scan
  /// minus the truth (TrueClock of the manifest) [ms]; NaN when not estimated.
  double clock_offset_error_ms = std::nan("");
  double clock_offset_true_ms = 0.0;  // teammate clock - observer clock [ms]
};

/// Writes the swarm outputs into `output_dir`; `truth_known`: the manifest
/// carries the true G frames (simulated runs) so extrinsic errors are
/// computed. `*pairs` gets the per-pair metrics, `*markdown` a table.
Status WriteSwarmReport(const replay::SwarmReplay& run, const std::string& output_dir,
                        bool save_maps, std::vector<PairMetrics>* pairs, std::string* markdown);

}  // namespace swarmlio::tools
