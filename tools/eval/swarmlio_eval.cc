// swarmlio_eval: absolute and relative pose error of a trajectory against a
// reference, with evo's rules and defaults (docs/evaluation.md).
//
//   swarmlio_eval ape REF EST [--align=se3] [--relation=trans] [--plot_top_view=a.png] ...
//   swarmlio_eval rpe REF EST [--delta=1 --delta_unit=m --all_pairs --rpe_frame=world] ...
//   swarmlio_eval extrinsics OBSERVER_extrinsics.csv --manifest=swarm.yaml --observer=uav1
//     (T_Gi_Gj errors against a simulated manifest's true G frames, as the replay reports)
//
// REF and EST are trajectory sources: PATH (format from --format), tum:PATH,
// kitti:PATH, euroc:PATH (EuRoC ground-truth CSV, as evo's `euroc`), or
// bag:PATH[:TOPIC] for the geometry_msgs/PoseStamped or nav_msgs/Odometry
// ground truth in a ROS1 bag (default topic --ground_truth_topic; IMU and
// LiDAR topics are found by type when absent).
//
// Exit code 0 on success, 1 if the evaluation fails (unreadable input, no
// overlapping stamps, ...), 2 on bad usage.
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "swarmlio/eval/ape.h"
#include "swarmlio/eval/bag_trajectory.h"
#include "swarmlio/eval/metrics_table.h"
#include "swarmlio/eval/plots.h"
#include "swarmlio/eval/rpe.h"
#include "swarmlio/eval/trajectory_io.h"
#include "swarmlio/driver/manifest.h"
#include "extrinsic_errors.h"

DEFINE_string(format, "tum", "format of sources given as a plain path: tum, kitti or euroc");
DEFINE_string(align, "none", "alignment of the estimate onto the reference: none, se3, sim3");
DEFINE_string(relation,
              "trans",
              "pose relation: trans (m), rot, angle_deg, angle_rad, full (|E - I|_F)");
DEFINE_double(delta, 1.0, "rpe: delta between the poses of a pair");
DEFINE_string(delta_unit, "f", "rpe: unit of --delta: f (frames) or m (metres of path)");
DEFINE_bool(all_pairs, false,
            "rpe: a pair from every pose instead of consecutive ids (evo --all_pairs); with "
            "--delta_unit=m, pairs whose path length is within 10 % of --delta, and the mean "
            "error is also printed as a drift in % of --delta");
DEFINE_string(rpe_frame, "pose",
              "rpe: pose (evo: the displacement error in the start pose's frame, with its "
              "attitude error) or world (the displacement error in the reference frame after "
              "--align; translation only)");
DEFINE_double(t_max_diff, 0.01, "maximum |dt| of an associated pair [s]");
DEFINE_double(t_offset, 0.0, "offset added to the estimate's stamps [s]");
DEFINE_bool(allow_duplicate_stamps,
            false,
            "accept equal consecutive stamps in TUM files (evo keeps such poses)");
DEFINE_string(ground_truth_topic,
              "/ground_truth/pose",
              "bag sources: default pose topic (PoseStamped or Odometry; 'auto': the bag's only "
              "such topic)");
DEFINE_string(imu_topic,
              "auto",
              "bag sources: IMU topic (the bag reader needs it; 'auto': found by type)");
DEFINE_string(lidar_topic,
              "auto",
              "bag sources: LiDAR topic (the bag reader needs it; 'auto': found by type)");
DEFINE_string(plot_top_view, "", "ape: write an x-y plot of both trajectories to this PNG");
DEFINE_string(plot_errors, "", "ape: write the error over time to this PNG");
DEFINE_string(table, "", "write the statistics to TABLE.md, TABLE.csv and TABLE.json");
DEFINE_string(manifest, "", "extrinsics: the simulated swarm's manifest (true G frames)");
DEFINE_string(observer, "", "extrinsics: the drone of --manifest that wrote the CSV");
DEFINE_string(origins, "",
              "extrinsics: name=stamp_s,... drones whose estimator started late (join, restart): "
              "their G is their true body pose at that stamp (their IMU initialization)");

namespace {

using swarmlio::Status;
namespace eval = swarmlio::eval;

constexpr int kExitError = 1;
constexpr int kExitUsage = 2;

int Fail(const std::string& message) {
  std::fprintf(stderr, "swarmlio_eval: error: %s\n", message.c_str());
  return kExitError;
}

int Usage(const std::string& message) {
  std::fprintf(stderr, "swarmlio_eval: %s\n%s\n", message.c_str(), gflags::ProgramUsage());
  return kExitUsage;
}

bool StartsWith(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

/// Reads a trajectory source (see the file comment).
Status ReadSource(const std::string& source, eval::Trajectory* trajectory) {
  eval::TrajectoryReadOptions read_options;
  read_options.allow_duplicate_stamps = FLAGS_allow_duplicate_stamps;
  if (StartsWith(source, "bag:")) {
    swarmlio::io::BagReaderOptions options;
    options.imu_topic = FLAGS_imu_topic;
    options.lidar_topic = FLAGS_lidar_topic;
    options.ground_truth_topic = FLAGS_ground_truth_topic;
    std::string path = source.substr(4);
    const size_t topic_at = path.rfind(":/");
    if (topic_at != std::string::npos) {
      options.ground_truth_topic = path.substr(topic_at + 1);
      path = path.substr(0, topic_at);
    }
    return eval::ReadBagGroundTruth(path, options, trajectory);
  }
  eval::TrajectoryFormat format;
  std::string path = source;
  if (StartsWith(source, "tum:")) {
    format = eval::TrajectoryFormat::kTum;
    path = source.substr(4);
  } else if (StartsWith(source, "kitti:")) {
    format = eval::TrajectoryFormat::kKitti;
    path = source.substr(6);
  } else if (StartsWith(source, "euroc:")) {
    format = eval::TrajectoryFormat::kEuroc;
    path = source.substr(6);
  } else if (!eval::TrajectoryFormatFromString(FLAGS_format, &format)) {
    return Status::InvalidArgument("--format '" + FLAGS_format + "' is not tum, kitti or euroc");
  }
  return eval::ReadTrajectory(path, format, read_options, trajectory);
}

void PrintStatistics(const eval::ErrorStatistics& s, const char* unit) {
  std::printf("pairs   %zu\n", s.count);
  std::printf("max     %.9g %s\n", s.max, unit);
  std::printf("mean    %.9g %s\n", s.mean, unit);
  std::printf("median  %.9g %s\n", s.median, unit);
  std::printf("min     %.9g %s\n", s.min, unit);
  std::printf("rmse    %.9g %s\n", s.rmse, unit);
  std::printf("sse     %.9g\n", s.sse);
  std::printf("std     %.9g %s\n", s.std, unit);
}

Status WriteTable(const std::string& stem,
                  const std::string& metric,
                  const eval::ErrorStatistics& s,
                  eval::PoseRelation relation) {
  eval::MetricsTable table;
  const std::string unit = eval::PoseRelationUnit(relation);
  const std::string suffix = unit.empty() ? "" : " [" + unit + "]";
  const int decimals = 6;
  SWARMLIO_RETURN_IF_ERROR(table.AddColumn({"metric", "metric", 0}));
  SWARMLIO_RETURN_IF_ERROR(table.AddColumn({"pairs", "pairs", 0}));
  for (const char* name : {"rmse", "mean", "median", "std", "min", "max"}) {
    SWARMLIO_RETURN_IF_ERROR(table.AddColumn({name, name + suffix, decimals}));
  }
  SWARMLIO_RETURN_IF_ERROR(table.AddRow({{"metric", metric},
                                         {"pairs", static_cast<double>(s.count)},
                                         {"rmse", s.rmse},
                                         {"mean", s.mean},
                                         {"median", s.median},
                                         {"std", s.std},
                                         {"min", s.min},
                                         {"max", s.max}}));
  return table.WriteAll(stem);
}

}  // namespace

int main(int argc, char** argv) {
  gflags::SetUsageMessage(
      "evo-compatible trajectory errors\n"
      "  usage: swarmlio_eval {ape|rpe} REFERENCE ESTIMATE [flags]\n"
      "         swarmlio_eval extrinsics EXTRINSICS_CSV --manifest=M --observer=NAME\n"
      "  sources: PATH (--format), tum:PATH, kitti:PATH, euroc:PATH, bag:PATH[:TOPIC]");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;

  if (argc == 3 && std::string(argv[1]) == "extrinsics") {
    if (FLAGS_manifest.empty() || FLAGS_observer.empty()) {
      return Usage("extrinsics needs --manifest and --observer");
    }
    swarmlio::driver::SwarmManifest manifest;
    Status status = swarmlio::driver::LoadManifest(FLAGS_manifest, &manifest);
    if (!status.ok()) return Fail(status.message());
    std::map<std::string, double> origins;
    std::stringstream list(FLAGS_origins);
    std::string item;
    while (std::getline(list, item, ',')) {
      const size_t eq = item.find('=');
      char* end = nullptr;
      const double stamp_s = eq == std::string::npos ? 0.0 : std::strtod(item.c_str() + eq + 1, &end);
      if (eq == std::string::npos || end == item.c_str() + eq + 1 || *end != '\0') {
        return Usage("--origins: '" + item + "' is not name=stamp_s");
      }
      origins[item.substr(0, eq)] = stamp_s;
    }
    std::vector<swarmlio::tools::ExtrinsicErrorRow> rows;
    status = swarmlio::tools::EvaluateExtrinsicErrors(argv[2], manifest, FLAGS_observer, origins,
                                                      &rows);
    if (!status.ok()) return Fail(status.message());
    std::printf("observer,teammate,estimates,first_s,last_s,end_m,end_deg,max_m,max_deg\n");
    for (const auto& r : rows) {
      std::printf("%s,%s,%d,%.3f,%.3f,%.4f,%.3f,%.4f,%.3f\n", FLAGS_observer.c_str(),
                  r.teammate.c_str(), r.estimates, r.first_s, r.last_s, r.end_m, r.end_deg,
                  r.max_m, r.max_deg);
    }
    return 0;
  }
  if (argc != 4) return Usage("give a mode (ape or rpe), a reference and an estimate");
  const std::string mode = argv[1];
  if (mode != "ape" && mode != "rpe") return Usage("unknown mode '" + mode + "'");
  eval::Alignment alignment;
  if (!eval::AlignmentFromString(FLAGS_align, &alignment)) {
    return Usage("--align '" + FLAGS_align + "' is not none, se3 or sim3");
  }
  eval::PoseRelation relation;
  if (!eval::PoseRelationFromString(FLAGS_relation, &relation)) {
    return Usage("--relation '" + FLAGS_relation +
                 "' is not trans, rot, angle_deg, angle_rad or full");
  }
  eval::DeltaUnit delta_unit;
  if (!eval::DeltaUnitFromString(FLAGS_delta_unit, &delta_unit)) {
    return Usage("--delta_unit '" + FLAGS_delta_unit + "' is not f or m");
  }
  eval::TrajectoryAssociationOptions association;
  association.max_time_diff_s = FLAGS_t_max_diff;
  association.time_offset_s = FLAGS_t_offset;

  eval::Trajectory reference;
  eval::Trajectory estimate;
  Status status = ReadSource(argv[2], &reference);
  if (!status.ok()) return Fail("reference: " + status.message());
  status = ReadSource(argv[3], &estimate);
  if (!status.ok()) return Fail("estimate: " + status.message());
  const char* unit = eval::PoseRelationUnit(relation);

  if (mode == "ape") {
    eval::ApeOptions options;
    options.relation = relation;
    options.alignment = alignment;
    options.association = association;
    eval::ApeResult result;
    status = eval::ComputeApe(reference, estimate, options, &result);
    if (!status.ok()) return Fail(status.message());
    std::printf("APE w.r.t. %s%s%s\n", eval::PoseRelationName(relation), *unit ? " in " : "", unit);
    std::printf("alignment %s", eval::AlignmentName(alignment));
    if (alignment == eval::Alignment::kSim3) {
      std::printf(", scale %.10g", result.alignment_transform.scale);
    }
    std::printf("; %zu of at most %zu poses associated\n", result.statistics.count,
                result.associated.max_pairs);
    PrintStatistics(result.statistics, unit);
    if (!FLAGS_plot_top_view.empty()) {
      status = eval::PlotTopView({eval::TopViewSeriesFromApe("trajectory", result)}, {},
                                 FLAGS_plot_top_view);
      if (!status.ok()) return Fail(status.message());
    }
    if (!FLAGS_plot_errors.empty()) {
      const std::string label = std::string("APE ") + eval::PoseRelationName(relation) +
                                (*unit ? " [" : "") + unit + (*unit ? "]" : "");
      status = eval::PlotErrorOverTime({eval::ErrorSeriesFromApe("trajectory", result)}, label, {},
                                       FLAGS_plot_errors);
      if (!status.ok()) return Fail(status.message());
    }
    if (!FLAGS_table.empty()) {
      status = WriteTable(FLAGS_table, "ape", result.statistics, relation);
      if (!status.ok()) return Fail(status.message());
    }
    return 0;
  }

  eval::RpeOptions options;
  options.relation = relation;
  options.alignment = alignment;
  options.association = association;
  options.delta = FLAGS_delta;
  options.delta_unit = delta_unit;
  options.all_pairs = FLAGS_all_pairs;
  if (FLAGS_rpe_frame != "pose" && FLAGS_rpe_frame != "world") {
    return Usage("--rpe_frame '" + FLAGS_rpe_frame + "' is not pose or world");
  }
  options.translation_in_world = FLAGS_rpe_frame == "world";
  eval::RpeResult result;
  status = eval::ComputeRpe(reference, estimate, options, &result);
  if (!status.ok()) return Fail(status.message());
  std::printf("RPE w.r.t. %s%s%s for delta = %g %s (%s pairs, %s)\n",
              eval::PoseRelationName(relation), *unit ? " in " : "", unit, FLAGS_delta,
              eval::DeltaUnitName(delta_unit), FLAGS_all_pairs ? "all" : "consecutive",
              options.translation_in_world ? "displacement in the world frame"
                                           : "in the start pose's frame");
  std::printf("alignment %s; %zu of at most %zu poses associated\n", eval::AlignmentName(alignment),
              result.associated.reference.size(), result.associated.max_pairs);
  PrintStatistics(result.statistics, unit);
  if (FLAGS_all_pairs && delta_unit == eval::DeltaUnit::kMeters &&
      relation == eval::PoseRelation::kTranslation) {
    std::printf("drift   %.3f %% of the distance (mean / delta)\n",
                100.0 * result.statistics.mean / FLAGS_delta);
  }
  if (!FLAGS_table.empty()) {
    status = WriteTable(FLAGS_table, "rpe", result.statistics, relation);
    if (!status.ok()) return Fail(status.message());
  }
  return 0;
}
