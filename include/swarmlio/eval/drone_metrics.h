// Per-drone evaluation for a swarm run, and the results table built from it.
//
// Each drone's estimate (in its own global frame G_i) is compared with its
// ground truth (in the world frame W): APE on the translation after SE(3)
// alignment (which also expresses the estimate in W, for plotting) and RPE on
// the translation over a delta (1 m by default), and the drift per distance:
// the position drift in % of the distance flown, the mean displacement error
// in W over segments of drift_delta_m of path from every pose, after the SE(3)
// alignment (RpeOptions all_pairs + translation_in_world; docs/evaluation.md),
// so neither the frame G_i nor a constant attitude offset enters it. Timing or
// other numbers the caller measures go in as named extra columns.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/eval/ape.h"
#include "swarmlio/eval/metrics_table.h"
#include "swarmlio/eval/rpe.h"
#include "swarmlio/eval/trajectory.h"

namespace swarmlio::eval {

struct DroneMetricsOptions {
  TrajectoryAssociationOptions association;
  Alignment ape_alignment = Alignment::kSe3;
  double rpe_delta = 1.0;
  DeltaUnit rpe_delta_unit = DeltaUnit::kMeters;
  double drift_delta_m = 10.0;  // segment length of the drift per distance [m], > 0
};

struct DroneMetrics {
  std::string drone;
  ErrorStatistics ape_translation;  // [m], after ape_alignment
  /// False when the trajectory is too short for one RPE pair (rpe_note says
  /// why); the table then shows the RPE cells as missing.
  bool has_rpe = false;
  ErrorStatistics rpe_translation;  // [m]
  std::string rpe_note;
  /// False when no segment of drift_delta_m fits (drift_note says why).
  bool has_drift = false;
  ErrorStatistics drift_translation;  // [m] over drift_delta_m of path
  std::string drift_note;
  /// Caller-supplied values (numbers or text), by column key (e.g.
  /// {"update_ms_mean", 3.1}, {"nees_position", std::string("n/a (frames differ)")}).
  std::vector<std::pair<std::string, MetricsValue>> extra;
};

/// Evaluates one drone. `ape` (optional) receives the full APE result, e.g.
/// for TopViewSeriesFromApe / ErrorSeriesFromApe. Errors: those of
/// ComputeApe (no overlap, too few poses to align, ...), a drift_delta_m that
/// is not > 0; an RPE or drift that finds no pair is not an error (has_rpe /
/// has_drift = false).
Status EvaluateDrone(const std::string& drone,
                     const Trajectory& reference,
                     const Trajectory& estimate,
                     const DroneMetricsOptions& options,
                     DroneMetrics* metrics,
                     ApeResult* ape = nullptr);

/// A table with one row per drone and the columns
///   drone, ape_pairs, ape_rmse_m, ape_mean_m, ape_median_m, ape_std_m,
///   ape_max_m, rpe_pairs, rpe_rmse_m, rpe_mean_m, drift_pairs, drift_percent
///   (100 x drift mean / drift_delta_m), then `extra_columns`.
/// Errors: a drone's extra key that is not among extra_columns, a bad column.
Status MakeDroneMetricsTable(const std::vector<DroneMetrics>& drones,
                             const DroneMetricsOptions& options,
                             const std::vector<MetricsColumn>& extra_columns,
                             MetricsTable* table);

}  // namespace swarmlio::eval
