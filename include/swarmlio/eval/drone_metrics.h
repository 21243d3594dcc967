// Per-drone evaluation for a swarm run, and the results table built from it.
//
// Each drone's estimate (in its own global frame G_i) is compared with its
// ground truth (in the world frame W): APE on the translation after SE(3)
// alignment (which also expresses the estimate in W, for plotting) and RPE on
// the translation over a delta (1 m by default). Timing or other numbers the
// caller measures go in as named extra columns.
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
  AssociationOptions association;
  Alignment ape_alignment = Alignment::kSe3;
  double rpe_delta = 1.0;
  DeltaUnit rpe_delta_unit = DeltaUnit::kMeters;
};

struct DroneMetrics {
  std::string drone;
  ErrorStatistics ape_translation;  // [m], after ape_alignment
  /// False when the trajectory is too short for one RPE pair (rpe_note says
  /// why); the table then shows the RPE cells as missing.
  bool has_rpe = false;
  ErrorStatistics rpe_translation;  // [m]
  std::string rpe_note;
  /// Caller-supplied values (numbers or text), by column key (e.g.
  /// {"update_ms_mean", 3.1}, {"nees_position", std::string("n/a (frames differ)")}).
  std::vector<std::pair<std::string, MetricsValue>> extra;
};

/// Evaluates one drone. `ape` (optional) receives the full APE result, e.g.
/// for TopViewSeriesFromApe / ErrorSeriesFromApe. Errors: those of
/// ComputeApe (no overlap, too few poses to align, ...); an RPE that finds no
/// pair is not an error (has_rpe = false).
Status EvaluateDrone(const std::string& drone,
                     const Trajectory& reference,
                     const Trajectory& estimate,
                     const DroneMetricsOptions& options,
                     DroneMetrics* metrics,
                     ApeResult* ape = nullptr);

/// A table with one row per drone and the columns
///   drone, ape_pairs, ape_rmse_m, ape_mean_m, ape_median_m, ape_std_m,
///   ape_max_m, rpe_pairs, rpe_rmse_m, rpe_mean_m, then `extra_columns`.
/// Errors: a drone's extra key that is not among extra_columns, a bad column.
Status MakeDroneMetricsTable(const std::vector<DroneMetrics>& drones,
                             const DroneMetricsOptions& options,
                             const std::vector<MetricsColumn>& extra_columns,
                             MetricsTable* table);

}  // namespace swarmlio::eval
