#include "swarmlio/eval/drone_metrics.h"

#include <cstdio>
#include <limits>
#include <string>

namespace swarmlio::eval {

namespace {

constexpr double kMissing = std::numeric_limits<double>::quiet_NaN();

std::string DeltaText(const DroneMetricsOptions& options) {
  char text[64];
  std::snprintf(text, sizeof(text), "%g %s", options.rpe_delta,
                options.rpe_delta_unit == DeltaUnit::kMeters ? "m" : "frames");
  return text;
}

}  // namespace

Status EvaluateDrone(const std::string& drone,
                     const Trajectory& reference,
                     const Trajectory& estimate,
                     const DroneMetricsOptions& options,
                     DroneMetrics* metrics,
                     ApeResult* ape) {
  if (!(options.drift_delta_m > 0.0)) {
    return Status::InvalidArgument(drone + ": drift_delta_m must be > 0, got " +
                                   std::to_string(options.drift_delta_m));
  }
  DroneMetrics out;
  out.drone = drone;
  ApeOptions ape_options;
  ape_options.alignment = options.ape_alignment;
  ape_options.association = options.association;
  ApeResult ape_result;
  SWARMLIO_RETURN_IF_ERROR(
      ComputeApe(reference, estimate, ape_options, &ape_result).WithContext(drone));
  out.ape_translation = ape_result.statistics;

  RpeOptions rpe_options;
  rpe_options.delta = options.rpe_delta;
  rpe_options.delta_unit = options.rpe_delta_unit;
  rpe_options.association = options.association;
  RpeResult rpe_result;
  const Status rpe_status = ComputeRpe(reference, estimate, rpe_options, &rpe_result);
  if (rpe_status.ok()) {
    out.has_rpe = true;
    out.rpe_translation = rpe_result.statistics;
  } else if (rpe_status.code() == Status::Code::kFailedPrecondition) {
    out.rpe_note = rpe_status.message();
  } else {
    return rpe_status.WithContext(drone);
  }

  RpeOptions drift_options;
  drift_options.delta = options.drift_delta_m;
  drift_options.delta_unit = DeltaUnit::kMeters;
  drift_options.all_pairs = true;
  drift_options.alignment = Alignment::kSe3;
  drift_options.translation_in_world = true;
  drift_options.association = options.association;
  RpeResult drift_result;
  const Status drift_status = ComputeRpe(reference, estimate, drift_options, &drift_result);
  if (drift_status.ok()) {
    out.has_drift = true;
    out.drift_translation = drift_result.statistics;
  } else if (drift_status.code() == Status::Code::kFailedPrecondition) {
    out.drift_note = drift_status.message();
  } else {
    return drift_status.WithContext(drone);
  }
  *metrics = std::move(out);
  if (ape != nullptr) *ape = std::move(ape_result);
  return Status::Ok();
}

Status MakeDroneMetricsTable(const std::vector<DroneMetrics>& drones,
                             const DroneMetricsOptions& options,
                             const std::vector<MetricsColumn>& extra_columns,
                             MetricsTable* table) {
  const std::string ape_suffix = std::string(" [m] (") + AlignmentName(options.ape_alignment) + ")";
  const std::string rpe_suffix = " [m] (delta " + DeltaText(options) + ")";
  char drift_text[64];
  std::snprintf(drift_text, sizeof(drift_text), "%g m", options.drift_delta_m);
  MetricsTable out;
  const std::vector<MetricsColumn> columns = {
      {"drone", "drone", 0},
      {"ape_pairs", "APE pairs", 0},
      {"ape_rmse_m", "APE rmse" + ape_suffix, 4},
      {"ape_mean_m", "APE mean" + ape_suffix, 4},
      {"ape_median_m", "APE median" + ape_suffix, 4},
      {"ape_std_m", "APE std" + ape_suffix, 4},
      {"ape_max_m", "APE max" + ape_suffix, 4},
      {"rpe_pairs", "RPE pairs", 0},
      {"rpe_rmse_m", "RPE rmse" + rpe_suffix, 4},
      {"rpe_mean_m", "RPE mean" + rpe_suffix, 4},
      {"drift_pairs", "drift pairs", 0},
      {"drift_percent", std::string("drift [%] (") + drift_text + " segments, W, SE(3))", 3},
  };
  for (const MetricsColumn& column : columns) SWARMLIO_RETURN_IF_ERROR(out.AddColumn(column));
  for (const MetricsColumn& column : extra_columns) {
    SWARMLIO_RETURN_IF_ERROR(out.AddColumn(column));
  }
  for (const DroneMetrics& d : drones) {
    const ErrorStatistics& a = d.ape_translation;
    const ErrorStatistics& r = d.rpe_translation;
    std::vector<std::pair<std::string, MetricsValue>> cells = {
        {"drone", d.drone},
        {"ape_pairs", static_cast<double>(a.count)},
        {"ape_rmse_m", a.rmse},
        {"ape_mean_m", a.mean},
        {"ape_median_m", a.median},
        {"ape_std_m", a.std},
        {"ape_max_m", a.max},
        {"rpe_pairs", d.has_rpe ? static_cast<double>(r.count) : 0.0},
        {"rpe_rmse_m", d.has_rpe ? r.rmse : kMissing},
        {"rpe_mean_m", d.has_rpe ? r.mean : kMissing},
        {"drift_pairs", d.has_drift ? static_cast<double>(d.drift_translation.count) : 0.0},
        {"drift_percent",
         d.has_drift ? 100.0 * d.drift_translation.mean / options.drift_delta_m : kMissing},
    };
    for (const auto& [key, value] : d.extra) {
      bool known = false;
      for (const MetricsColumn& column : extra_columns) known = known || column.key == key;
      if (!known) {
        return Status::InvalidArgument("drone " + d.drone + ": extra value '" + key +
                                       "' has no column in extra_columns");
      }
      cells.emplace_back(key, value);
    }
    SWARMLIO_RETURN_IF_ERROR(out.AddRow(cells));
  }
  *table = std::move(out);
  return Status::Ok();
}

}  // namespace swarmlio::eval
