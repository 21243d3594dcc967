#include "report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <vector>

#include "swarmlio/eval/consistency.h"
#include "swarmlio/eval/drone_metrics.h"
#include "swarmlio/eval/error_statistics.h"
#include "swarmlio/eval/plots.h"
#include "swarmlio/eval/trajectory_io.h"
#include "swarmlio/io/pcd_writer.h"

namespace swarmlio::tools {
namespace {

namespace fs = std::filesystem;

eval::Trajectory EstimateTrajectory(const std::vector<swarm::DroneOutput>& scans) {
  eval::Trajectory t;
  for (const swarm::DroneOutput& o : scans) {
    const lio::ScanOutput& s = o.ego;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = s.state.q_G_b.normalized().toRotationMatrix();
    T.translation() = s.state.p_b_in_G;
    t.stamps_s.push_back(ToSeconds(s.stamp_ns));
    t.T_G_b.push_back(T);
  }
  return t;
}

Status WriteTiming(const std::string& path, const std::vector<swarm::DroneOutput>& scans) {
  std::ofstream out(path);
  if (!out) return Status::IoError(path + ": cannot open for writing");
  out << "stamp_s,updated,raw_points,points,correspondences,iterations,min_normal_information,"
         "degenerate,map_points,preprocess_ms,propagate_ms,undistort_ms,association_ms,solve_ms,"
         "covariance_ms,map_update_ms,total_ms,front_end_ms,active_fused,passive_fused,"
         "rejected_observations,extrinsics_frozen,build_ms,marginalize_ms\n";
  out << std::fixed;
  for (const swarm::DroneOutput& o : scans) {
    const lio::ScanOutput& s = o.ego;
    const lio::ScanTimings& t = s.timings;
    out << std::setprecision(9) << ToSeconds(s.stamp_ns) << "," << (s.updated ? 1 : 0) << ","
        << s.num_raw_points << "," << s.num_points << "," << s.num_correspondences << ","
        << s.iterations << "," << std::setprecision(2) << s.min_normal_information << ","
        << (s.degenerate ? 1 : 0) << "," << s.map_size << std::setprecision(4) << ","
        << 1e3 * t.preprocess_s << "," << 1e3 * t.propagate_s << "," << 1e3 * t.undistort_s << ","
        << 1e3 * t.association_s << "," << 1e3 * t.solve_s << "," << 1e3 * t.covariance_s << ","
        << 1e3 * t.map_update_s << "," << 1e3 * t.total_s << "," << 1e3 * t.front_end_s << ","
        << o.active_observations << "," << o.passive_observations << ","
        << o.rejected_observations << "," << (o.extrinsics_frozen ? 1 : 0) << ","
        << 1e3 * t.build_s << "," << 1e3 * t.marginalize_s << "\n";
  }
  return out ? Status::Ok() : Status::IoError(path + ": write failed");
}

Status WriteNetwork(const std::string& path, const replay::SwarmReplay& run) {
  std::ofstream out(path);
  if (!out) return Status::IoError(path + ": cannot open for writing");
  out << "from,to,sent,delivered,dropped_loss,dropped_queue,duplicated,reordered,bytes_sent,"
         "mean_latency_ms\n";
  for (int i = 0; i < run.num_drones(); ++i) {
    for (int j = 0; j < run.num_drones(); ++j) {
      if (i == j) continue;
      const net::LinkStats s = run.LinkStats(i, j);
      out << run.drone(i).input().name << "," << run.drone(j).input().name << "," << s.sent << ","
          << s.delivered << "," << s.dropped_loss << "," << s.dropped_queue << ","
          << s.duplicated << "," << s.reordered << "," << s.bytes_sent << ","
          << (s.delivered > 0 ? 1e3 * s.latency_sum_s / static_cast<double>(s.delivered) : 0.0)
          << "\n";
    }
  }
  return out ? Status::Ok() : Status::IoError(path + ": write failed");
}

// Moves plotted positions from a drone's G into the common frame W.
Eigen::Matrix3Xd ToWorld(const driver::DroneInput& d, const Eigen::Matrix3Xd& p_in_G) {
  Eigen::Matrix3Xd out = d.R_W_G * p_in_G;
  out.colwise() += d.p_G_in_W_m;
  return out;
}

}  // namespace

Status WriteReport(const replay::SwarmReplay& run, const ReportOptions& options,
                   std::string* markdown, std::string* problems) {
  const fs::path dir(options.output_dir);
  Status first_error;
  problems->clear();
  auto note = [&](const Status& s) {
    if (s.ok()) return;
    if (first_error.ok()) first_error = s;
    *problems += s.message() + "\n";
  };

  eval::DroneMetricsOptions metric_options;
  std::vector<eval::DroneMetrics> metrics;
  std::vector<eval::TopViewSeries> top_view;
  std::vector<eval::ErrorSeries> errors;
  for (int i = 0; i < run.num_drones(); ++i) {
    const replay::DroneRunner& d = run.drone(i);
    const std::string& name = d.input().name;
    const eval::Trajectory estimate = EstimateTrajectory(d.scans());
    note(eval::WriteTumTrajectory((dir / (name + "_tum.txt")).string(), estimate));
    note(WriteTiming((dir / (name + "_timing.csv")).string(), d.scans()));
    if (options.save_maps) {
      note(io::WritePcd((dir / (name + "_map.pcd")).string(), d.estimator().MapPoints()));
    }

    eval::DroneMetrics m;
    m.drone = name;
    std::vector<double> total_ms;
    double busy_s = 0.0;
    for (const swarm::DroneOutput& s : d.scans()) {
      busy_s += s.ego.timings.total_s;
      if (s.ego.updated) total_ms.push_back(1e3 * s.ego.timings.total_s);
    }
    const double log_s = d.scans().size() < 2 ? 0.0
                                              : ToSeconds(d.scans().back().ego.stamp_ns -
                                                             d.scans().front().ego.stamp_ns);
    std::vector<std::pair<std::string, eval::MetricsValue>> extra = {{"scans", static_cast<double>(d.scans().size())},
               {"time_median_ms", eval::Percentile(total_ms, 0.5)},
               {"time_p95_ms", eval::Percentile(total_ms, 0.95)},
               {"realtime_factor", busy_s > 0.0 ? log_s / busy_s : 0.0}};

    // Ground truth: the manifest's TUM file, else the bag's topic.
    eval::Trajectory reference;
    bool has_reference = false;
    if (!d.input().ground_truth_path.empty()) {
      const Status read =
          eval::ReadTumTrajectory(d.input().ground_truth_path, eval::TrajectoryReadOptions(),
                                  &reference);
      note(read.WithContext(name));
      has_reference = read.ok();
    } else if (!d.bag_ground_truth().empty()) {
      reference = eval::TrajectoryFromPoses(d.bag_ground_truth());
      has_reference = true;
    }
    if (has_reference && !estimate.empty()) {
      eval::ApeResult ape;
      const Status evaluated =
          eval::EvaluateDrone(name, reference, estimate, metric_options, &m, &ape);
      note(evaluated.WithContext(name + ": evaluation against ground truth"));
      if (evaluated.ok()) {
        eval::TopViewSeries series = eval::TopViewSeriesFromApe(name, ape);
        series.estimate_positions = ToWorld(d.input(), series.estimate_positions);
        series.reference_positions = ToWorld(d.input(), series.reference_positions);
        top_view.push_back(std::move(series));
        errors.push_back(eval::ErrorSeriesFromApe(name, ape));
        // NEES only when the ground truth is in the estimator's G (declared, or
        // starting at the estimate's first pose): in another frame it is meaningless.
        const eval::CovariantTrajectory updated = replay::UpdatedEstimate(d.scans());
        eval::FrameCheck frame;
        if (eval::CheckGroundTruthFrame(updated.poses, reference, d.input().ground_truth_frame,
                                        eval::FrameCheckOptions(), &frame)
                .ok()) {
          extra.push_back({"ground_truth_frame",
                           std::string(frame.same_frame
                                           ? "G"
                                           : "other: aligned by first pose and SE(3)")});
          eval::ConsistencyStats consistency;
          if (!frame.same_frame) {
            extra.push_back({"nees_position", std::string("n/a (frames differ)")});
            extra.push_back({"nees_position_aligned", std::string("n/a (frames differ)")});
          } else if (eval::EvaluateConsistency(updated, reference, 0.05, &consistency).ok()) {
            extra.push_back({"nees_position", consistency.mean_position_nees});
            if (std::isfinite(consistency.mean_position_nees_aligned)) {
              extra.push_back({"nees_position_aligned", consistency.mean_position_nees_aligned});
            } else {
              extra.push_back({"nees_position_aligned", std::string("n/a (no rotation fixed)")});
            }
          }
        }
      }
    }
    extra.push_back({"messages_received", static_cast<double>(run.traffic(i).received)});
    m.drone = name;  // EvaluateDrone rewrites the whole struct
    m.extra = std::move(extra);
    metrics.push_back(std::move(m));
  }

  std::vector<eval::MetricsColumn> extra_columns = {
      {"scans", "scans", 0},
      {"time_median_ms", "time median [ms]", 2},
      {"time_p95_ms", "time p95 [ms]", 2},
      {"realtime_factor", "real-time factor", 1},
      {"ground_truth_frame", "ground-truth frame", 0},
      {"nees_position", "position NEES in G (3 expected)", 2},
      {"nees_position_aligned", "position NEES, gauge-aligned", 2}};
  extra_columns.push_back({"messages_received", "msgs received", 0});
  eval::MetricsTable table;
  Status status = eval::MakeDroneMetricsTable(metrics, metric_options, extra_columns, &table);
  note(status);
  if (status.ok()) {
    note(table.WriteAll((dir / "metrics").string()));
    *markdown = table.ToMarkdown();
  }
  if (!top_view.empty()) {
    eval::PlotOptions plot;
    plot.title = run.manifest().name + ": estimate (SE(3)-aligned) vs ground truth";
    note(eval::PlotTopView(top_view, plot, (dir / "top_view.png").string()));
    plot.title = run.manifest().name + ": position error over time";
    note(eval::PlotErrorOverTime(errors, "APE translation [m]", plot,
                                 (dir / "ape_over_time.png").string()));
  }
  note(WriteNetwork((dir / "network.csv").string(), run));
  return first_error;
}

}  // namespace swarmlio::tools
