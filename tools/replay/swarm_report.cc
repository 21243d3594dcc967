#include "swarm_report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>

#include "swarmlio/eval/plots.h"
#include "swarmlio/eval/trajectory_io.h"
#include "swarmlio/io/pcd_writer.h"

namespace swarmlio::tools {
namespace {

namespace fs = std::filesystem;

// A teammate's true position is interpolated between ground-truth poses at
// most this far apart [s].
constexpr double kMaxTruthGapS = 0.5;

// Start of the excitation flight from the ground truth: the first time the
// horizontal speed exceeds 0.05 m/s (the plans hover, take off vertically,
// then excite); NaN when unknown.
double ExcitationStart(const eval::Trajectory& t) {
  for (size_t k = 1; k < t.size(); ++k) {
    const double dt = t.stamps_s[k] - t.stamps_s[k - 1];
    if (dt <= 0.0) continue;
    const Eigen::Vector3d v = (t.T_G_b[k].translation() - t.T_G_b[k - 1].translation()) / dt;
    if (v.head<2>().norm() > 0.05) return t.stamps_s[k];
  }
  return std::nan("");
}

double RotationDeg(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle() * 180.0 / M_PI; }

}  // namespace

Status WriteSwarmReport(const replay::SwarmReplay& run, const std::string& output_dir,
                        bool save_maps, std::vector<PairMetrics>* pairs, std::string* markdown) {
  const fs::path dir(output_dir);
  Status first_error;
  auto note = [&](const Status& s) {
    if (!s.ok() && first_error.ok()) first_error = s;
  };
  pairs->clear();
  const int n = run.num_drones();
  // Ground truth of every drone (its TUM file, in its own G).
  std::vector<eval::Trajectory> truth(static_cast<size_t>(n));
  std::vector<bool> has_truth(static_cast<size_t>(n), false);
  for (int j = 0; j < n; ++j) {
    const replay::DroneRunner& d = run.drone(j);
    if (!d.input().ground_truth_path.empty()) {
      has_truth[j] = eval::ReadTumTrajectory(d.input().ground_truth_path,
                                             eval::TrajectoryReadOptions(), &truth[j])
                         .ok();
    } else if (!d.bag_ground_truth().empty()) {
      truth[j] = eval::TrajectoryFromPoses(d.bag_ground_truth());
      has_truth[j] = true;
    }
  }
  std::vector<eval::ErrorSeries> extrinsic_series;
  std::ofstream ident((dir / "identifications.csv").string());
  ident << "observer,teammate,stamp_s,since_first_scan_s,method,mean_residual_m\n";
  for (int i = 0; i < n; ++i) {
    const replay::DroneRunner& d = run.drone(i);
    const std::string& name = d.input().name;
    const auto& scans = d.scans();
    if (scans.empty()) continue;
    const double t0 = ToSeconds(scans.front().ego.stamp_ns);
    for (const swarm::IdentificationEvent& e : d.identifications()) {
      ident << name << "," << run.drone(e.drone_id).input().name << "," << std::fixed
            << std::setprecision(6) << ToSeconds(e.stamp_ns) << ","
            << ToSeconds(e.stamp_ns) - t0 << "," << e.method << "," << e.mean_residual_m << "\n";
    }
    // Extrinsics over time, and j's pose in G_i.
    std::ofstream ext((dir / (name + "_extrinsics.csv")).string());
    ext << "stamp_s,teammate,qx,qy,qz,qw,x,y,z,var_rx,var_ry,var_rz,var_x,var_y,var_z,active,"
           "passive\n";
    std::map<int, eval::Trajectory> teammate_tum;
    std::map<int, PairMetrics> by_teammate;
    for (const swarm::DroneOutput& s : scans) {
      const double t = ToSeconds(s.ego.stamp_ns);
      for (const swarm::TeammateEstimate& r : s.teammates) {
        const Eigen::Quaterniond& q = r.T_Gi_Gj.q_Ga_Gb;
        const Eigen::Vector3d& p = r.T_Gi_Gj.p_Gb_in_Ga;
        ext << std::setprecision(9) << t << "," << run.drone(r.drone_id).input().name << ","
            << q.x() << "," << q.y() << "," << q.z() << "," << q.w() << "," << p.x() << ","
            << p.y() << "," << p.z();
        for (int k = 0; k < 6; ++k) ext << "," << r.extrinsic_covariance(k, k);
        ext << "," << r.active_observations << "," << r.passive_observations << "\n";
        PairMetrics& m = by_teammate[r.drone_id];
        m.active_fused += r.active_observations;
        m.passive_fused += r.passive_observations;
        if (r.have_pose) {
          Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
          T.linear() = r.q_Gi_bj.normalized().toRotationMatrix();
          T.translation() = r.p_bj_in_Gi;
          teammate_tum[r.drone_id].stamps_s.push_back(t);
          teammate_tum[r.drone_id].T_G_b.push_back(T);
        }
        // Errors against the truth (simulated runs: the manifest's G frames).
        const Eigen::Isometry3d T_true = d.input().T_W_G().inverse() * run.drone(r.drone_id).input().T_W_G();
        const double e_m = (p - T_true.translation()).norm();
        const double e_deg = RotationDeg(T_true.linear().transpose() * r.T_Gi_Gj.R_Ga_Gb());
        m.extrinsic_end_m = e_m;
        m.extrinsic_end_deg = e_deg;
        m.extrinsic_max_m = std::max(m.extrinsic_max_m, e_m);
        m.extrinsic_max_deg = std::max(m.extrinsic_max_deg, e_deg);
        // j's ground truth is stamped in j's clock: the same true instant.
        const driver::TrueClock& clock_j = run.drone(r.drone_id).input().true_clock;
        const double t_j = ToSeconds(clock_j.ToDrone(d.input().true_clock.ToTrue(s.ego.stamp_ns)));
        Eigen::Isometry3d T_true_Gj_bj;
        if (r.have_pose && has_truth[r.drone_id] &&
            truth[r.drone_id].PoseAt(t_j, kMaxTruthGapS, &T_true_Gj_bj)) {
          const double err = (r.p_bj_in_Gi - T_true * T_true_Gj_bj.translation()).norm();
          m.relative_rmse_m += err * err;
          ++m.relative_samples;
        }
        eval::ErrorSeries* series = nullptr;
        const std::string label = name + "->" + run.drone(r.drone_id).input().name;
        for (auto& e : extrinsic_series) {
          if (e.name == label) series = &e;
        }
        if (series == nullptr) {
          extrinsic_series.push_back({label, {}, {}});
          series = &extrinsic_series.back();
        }
        series->time_s.push_back(t - t0);
        series->error.push_back(e_m);
      }
    }
    for (auto& [j, traj] : teammate_tum) {
      note(eval::WriteTumTrajectory(
          (dir / (name + "_teammate_" + run.drone(j).input().name + "_tum.txt")).string(), traj));
    }
    for (int j = 0; j < n; ++j) {
      if (j == i) continue;
      PairMetrics m = by_teammate.count(j) ? by_teammate[j] : PairMetrics();
      m.observer = name;
      m.teammate = run.drone(j).input().name;
      for (const swarm::IdentificationEvent& e : d.identifications()) {
        if (e.drone_id == j && !m.identified) {
          m.identified = true;
          m.identification_s = ToSeconds(e.stamp_ns) - t0;
          const Eigen::Isometry3d T_true =
              d.input().T_W_G().inverse() * run.drone(j).input().T_W_G();
          m.initial_error_m = (e.initial_T_Gi_Gj.p_Gb_in_Ga - T_true.translation()).norm();
          m.initial_error_deg =
              RotationDeg(T_true.linear().transpose() * e.initial_T_Gi_Gj.R_Ga_Gb());
          if (has_truth[i] && has_truth[j]) {
            // Ground-truth stamps are in each drone's clock, like its bag:
            // j's excitation start moved to i's clock.
            const double start_j_s = ExcitationStart(truth[j]);
            const int64_t start_j_in_i_ns = d.input().true_clock.ToDrone(
                run.drone(j).input().true_clock.ToTrue(std::llround(start_j_s * 1e9)));
            m.since_excitation_s = ToSeconds(e.stamp_ns) -
                                   std::max(ExcitationStart(truth[i]), ToSeconds(start_j_in_i_ns));
          }
        }
      }
      if (m.relative_samples > 0) m.relative_rmse_m = std::sqrt(m.relative_rmse_m / m.relative_samples);
      // Clock offset of j as i estimated it at its last scan, against the truth.
      const int64_t t_last = scans.back().ego.stamp_ns;
      m.clock_offset_true_ms =
          1e-6 * static_cast<double>(run.drone(j).input().true_clock.ToDrone(
                                         d.input().true_clock.ToTrue(t_last)) -
                                     t_last);
      if (const net::ClockSync* sync = d.estimator().clock_sync()) {
        const net::ClockOffsetEstimate estimate = sync->Estimate(j, t_last);
        if (estimate.valid) {
          m.clock_offset_error_ms =
              1e-6 * static_cast<double>(estimate.offset_ns) - m.clock_offset_true_ms;
        }
      }
      pairs->push_back(m);
    }
  }
  if (!extrinsic_series.empty()) {
    eval::PlotOptions plot;
    plot.title = run.manifest().name + ": T_Gi_Gj translation error over time";
    note(eval::PlotErrorOverTime(extrinsic_series, "extrinsic error [m]", plot,
                                 (dir / "extrinsic_error.png").string()));
  }
  // Merged map: every drone's map in G of the first drone, through drone 0's
  // final T_G0_Gj estimates (drones it never identified are left out).
  if (save_maps && n > 0 && !run.drone(0).scans().empty()) {
    std::vector<Eigen::Vector3d> merged = run.drone(0).estimator().MapPoints();
    for (const swarm::TeammateEstimate& r : run.drone(0).scans().back().teammates) {
      const Eigen::Isometry3d T = r.T_Gi_Gj.T_Ga_Gb();
      for (const Eigen::Vector3d& p : run.drone(r.drone_id).estimator().MapPoints()) {
        merged.push_back(T * p);
      }
    }
    note(io::WritePcd((dir / "merged_map.pcd").string(), merged));
  }
  std::ostringstream md;
  md << "| observer | teammate | identified [s] | after excitation start [s] | extrinsic end [m / deg] | extrinsic max [m / deg] "
        "| teammate rel. RMSE [m] | active / passive fused |\n|---|---|---|---|---|---|---|---|\n";
  md << std::fixed;
  for (const PairMetrics& m : *pairs) {
    md << "| " << m.observer << " | " << m.teammate << " | ";
    if (!m.identified) {
      md << "never | - | - | - | - | - |\n";
      continue;
    }
    md << std::setprecision(1) << m.identification_s << " | " << m.since_excitation_s << " | "
       << std::setprecision(3)
       << m.extrinsic_end_m << " / " << std::setprecision(2) << m.extrinsic_end_deg << " | "
       << std::setprecision(3) << m.extrinsic_max_m << " / " << std::setprecision(2)
       << m.extrinsic_max_deg << " | " << std::setprecision(3) << m.relative_rmse_m << " | "
       << m.active_fused << " / " << m.passive_fused << " |\n";
  }
  *markdown = md.str();
  std::ofstream csv((dir / "swarm_pairs.csv").string());
  csv << "observer,teammate,identified,identification_s,since_excitation_s,extrinsic_end_m,"
         "extrinsic_end_deg,extrinsic_max_m,extrinsic_max_deg,relative_rmse_m,active_fused,"
         "passive_fused,initial_error_m,initial_error_deg,clock_offset_true_ms,"
         "clock_offset_error_ms\n";
  for (const PairMetrics& m : *pairs) {
    csv << m.observer << "," << m.teammate << "," << (m.identified ? 1 : 0) << ","
        << std::setprecision(6) << m.identification_s << "," << m.since_excitation_s << ","
        << m.extrinsic_end_m << "," << m.extrinsic_end_deg << "," << m.extrinsic_max_m << ","
        << m.extrinsic_max_deg << "," << m.relative_rmse_m << "," << m.active_fused << ","
        << m.passive_fused << "," << m.initial_error_m << "," << m.initial_error_deg << ","
        << m.clock_offset_true_ms << "," << m.clock_offset_error_ms << "\n";
  }
  std::ofstream mdfile((dir / "swarm.md").string());
  mdfile << *markdown;
  return first_error;
}

}  // namespace swarmlio::tools
