#include "swarm_report.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
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

// The simulator's truth of the returns each scan of one observer had on each
// teammate (manifest `teammate_returns`), per teammate name in scan order.
struct ScanReturns {
  double start_s = 0.0;  // first point of the scan
  double end_s = 0.0;    // last point
  int returns = 0;
};
using ReturnsByTeammate = std::map<std::string, std::vector<ScanReturns>>;

Status ReadTeammateReturns(const std::string& path, ReturnsByTeammate* out) {
  std::ifstream in(path);
  if (!in) return Status::IoError(path + ": cannot open");
  std::string line;
  std::getline(in, line);  // header
  for (int row = 2; std::getline(in, line); ++row) {
    std::istringstream fields(line);
    std::string start, end, name, returns;
    if (!std::getline(fields, start, ',') || !std::getline(fields, end, ',') ||
        !std::getline(fields, name, ',') || !std::getline(fields, returns)) {
      return Status::InvalidArgument(path + ":" + std::to_string(row) + ": expected 4 fields");
    }
    char* rest[3] = {nullptr, nullptr, nullptr};
    const ScanReturns r{std::strtod(start.c_str(), &rest[0]), std::strtod(end.c_str(), &rest[1]),
                        static_cast<int>(std::strtol(returns.c_str(), &rest[2], 10))};
    if (*rest[0] != '\0' || *rest[1] != '\0' || *rest[2] != '\0' || start.empty() ||
        returns.empty()) {
      return Status::InvalidArgument(path + ":" + std::to_string(row) + ": not a number");
    }
    (*out)[name].push_back(r);
  }
  return Status::Ok();
}

// Returns on the teammate in the observer's scan stamped t (the stamp lies
// within the scan's first and last point); 0 when the scan did not hit it.
int ReturnsAt(const std::vector<ScanReturns>& scans, double t_s) {
  constexpr double kToleranceS = 1e-3;
  auto it = std::upper_bound(scans.begin(), scans.end(), t_s + kToleranceS,
                             [](double t, const ScanReturns& s) { return t < s.start_s; });
  if (it == scans.begin()) return 0;
  --it;
  return t_s <= it->end_s + kToleranceS ? it->returns : 0;
}

// Ground truth of every drone (its TUM file or its bag's topic, in its own G).
void ReadTruth(const replay::SwarmReplay& run,
               std::vector<eval::Trajectory>* truth,
               std::vector<bool>* has_truth) {
  const int n = run.num_drones();
  truth->assign(static_cast<size_t>(n), eval::Trajectory());
  has_truth->assign(static_cast<size_t>(n), false);
  for (int j = 0; j < n; ++j) {
    const replay::DroneRunner& d = run.drone(j);
    if (!d.input().ground_truth_path.empty()) {
      (*has_truth)[j] = eval::ReadTumTrajectory(d.input().ground_truth_path,
                                                eval::TrajectoryReadOptions(), &(*truth)[j])
                            .ok();
    } else if (!d.bag_ground_truth().empty()) {
      (*truth)[j] = eval::TrajectoryFromPoses(d.bag_ground_truth());
      (*has_truth)[j] = true;
    }
  }
}

// Everything one observer's report needs besides the run.
struct ObserverContext {
  const replay::SwarmReplay* run = nullptr;
  int observer = 0;
  const std::vector<eval::Trajectory>* truth = nullptr;
  const std::vector<bool>* has_truth = nullptr;
  const ReturnsByTeammate* returns = nullptr;  // null: no truth of the returns
  const std::string& name(int drone) const { return run->drone(drone).input().name; }
};

Eigen::Isometry3d TrueExtrinsic(const replay::SwarmReplay& run, int i, int j) {
  return run.drone(i).input().T_W_G().inverse() * run.drone(j).input().T_W_G();
}

eval::ErrorSeries* SeriesFor(const std::string& label, std::vector<eval::ErrorSeries>* all) {
  for (auto& e : *all) {
    if (e.name == label) return &e;
  }
  all->push_back({label, {}, {}});
  return &all->back();
}

// One teammate estimate of one scan of the observer: the extrinsics CSV row,
// j's pose in G_i, and the errors against the truth into `m`.
void AddEstimate(const ObserverContext& c,
                 double t,
                 const swarm::TeammateEstimate& r,
                 int64_t stamp_ns,
                 std::ostream& ext,
                 eval::Trajectory* teammate_tum,
                 PairMetrics* m) {
  const replay::DroneRunner& d = c.run->drone(c.observer);
  const Eigen::Quaterniond& q = r.T_Gi_Gj.q_Ga_Gb;
  const Eigen::Vector3d& p = r.T_Gi_Gj.p_Gb_in_Ga;
  ext << std::setprecision(9) << t << "," << c.name(r.drone_id) << "," << q.x() << "," << q.y()
      << "," << q.z() << "," << q.w() << "," << p.x() << "," << p.y() << "," << p.z();
  for (int k = 0; k < 6; ++k) ext << "," << r.extrinsic_covariance(k, k);
  ext << "," << r.active_observations << "," << r.passive_observations << "\n";
  m->active_fused += r.active_observations;
  m->passive_fused += r.passive_observations;
  if (c.returns != nullptr) {
    const auto it = c.returns->find(c.name(r.drone_id));
    const int returns = it == c.returns->end() ? 0 : ReturnsAt(it->second, t);
    if (m->scans_in_view < 0) m->scans_in_view = 0;
    if (returns >= kInViewReturns) {
      ++m->scans_in_view;
      if (r.active_observations > 0) ++m->fused_in_view;
    }
  }
  if (r.have_pose) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = r.q_Gi_bj.normalized().toRotationMatrix();
    T.translation() = r.p_bj_in_Gi;
    teammate_tum->stamps_s.push_back(t);
    teammate_tum->T_G_b.push_back(T);
  }
  // Errors against the truth (simulated runs: the manifest's G frames).
  const Eigen::Isometry3d T_true = TrueExtrinsic(*c.run, c.observer, r.drone_id);
  m->extrinsic_end_m = (p - T_true.translation()).norm();
  m->extrinsic_end_deg = RotationDeg(T_true.linear().transpose() * r.T_Gi_Gj.R_Ga_Gb());
  m->extrinsic_max_m = std::max(m->extrinsic_max_m, m->extrinsic_end_m);
  m->extrinsic_max_deg = std::max(m->extrinsic_max_deg, m->extrinsic_end_deg);
  // j's ground truth is stamped in j's clock: the same true instant.
  const driver::TrueClock& clock_j = c.run->drone(r.drone_id).input().true_clock;
  const double t_j = ToSeconds(clock_j.ToDrone(d.input().true_clock.ToTrue(stamp_ns)));
  Eigen::Isometry3d T_true_Gj_bj;
  if (r.have_pose && (*c.has_truth)[r.drone_id] &&
      (*c.truth)[r.drone_id].PoseAt(t_j, kMaxTruthGapS, &T_true_Gj_bj)) {
    const double err = (r.p_bj_in_Gi - T_true * T_true_Gj_bj.translation()).norm();
    m->relative_rmse_m += err * err;
    ++m->relative_samples;
  }
}

// The identification of j by the observer: when, how far after the
// excitation start, and how far its first T_Gi_Gj was off.
void AddIdentification(const ObserverContext& c, int j, double t0, PairMetrics* m) {
  const replay::DroneRunner& d = c.run->drone(c.observer);
  for (const swarm::IdentificationEvent& e : d.identifications()) {
    if (e.drone_id != j || m->identified) continue;
    m->identified = true;
    m->identification_s = ToSeconds(e.stamp_ns) - t0;
    const Eigen::Isometry3d T_true = TrueExtrinsic(*c.run, c.observer, j);
    m->initial_error_m = (e.initial_T_Gi_Gj.p_Gb_in_Ga - T_true.translation()).norm();
    m->initial_error_deg = RotationDeg(T_true.linear().transpose() * e.initial_T_Gi_Gj.R_Ga_Gb());
    m->wrong_identification = m->initial_error_m > kWrongIdentificationM;
    if ((*c.has_truth)[c.observer] && (*c.has_truth)[j]) {
      // Ground-truth stamps are in each drone's clock, like its bag: j's
      // excitation start moved to i's clock.
      const double start_j_s = ExcitationStart((*c.truth)[j]);
      const int64_t start_j_in_i_ns = d.input().true_clock.ToDrone(
          c.run->drone(j).input().true_clock.ToTrue(std::llround(start_j_s * 1e9)));
      m->since_excitation_s =
          ToSeconds(e.stamp_ns) -
          std::max(ExcitationStart((*c.truth)[c.observer]), ToSeconds(start_j_in_i_ns));
    }
  }
}

// j's clock offset as the observer estimated it at its last scan, against the truth.
void AddClockOffset(const ObserverContext& c, int j, int64_t t_last, PairMetrics* m) {
  const replay::DroneRunner& d = c.run->drone(c.observer);
  m->clock_offset_true_ms =
      1e-6 *
      static_cast<double>(
          c.run->drone(j).input().true_clock.ToDrone(d.input().true_clock.ToTrue(t_last)) - t_last);
  if (const net::ClockSync* sync = d.estimator().clock_sync()) {
    const net::ClockOffsetEstimate estimate = sync->Estimate(j, t_last);
    if (estimate.valid) {
      m->clock_offset_error_ms =
          1e-6 * static_cast<double>(estimate.offset_ns) - m->clock_offset_true_ms;
    }
  }
}

// The observer's outputs: identifications and extrinsics CSV rows, teammate
// TUM files, error series, and one PairMetrics per teammate.
Status ReportObserver(const ObserverContext& c,
                      const fs::path& dir,
                      std::ostream& ident,
                      std::vector<eval::ErrorSeries>* series,
                      std::vector<PairMetrics>* pairs) {
  const replay::DroneRunner& d = c.run->drone(c.observer);
  const std::string& name = c.name(c.observer);
  const auto& scans = d.scans();
  if (scans.empty()) return Status::Ok();
  const double t0 = ToSeconds(scans.front().ego.stamp_ns);
  for (const swarm::IdentificationEvent& e : d.identifications()) {
    ident << name << "," << c.name(e.drone_id) << "," << std::fixed << std::setprecision(6)
          << ToSeconds(e.stamp_ns) << "," << ToSeconds(e.stamp_ns) - t0 << "," << e.method << ","
          << e.mean_residual_m << "\n";
  }
  std::ofstream ext((dir / (name + "_extrinsics.csv")).string());
  ext << "stamp_s,teammate,qx,qy,qz,qw,x,y,z,var_rx,var_ry,var_rz,var_x,var_y,var_z,active,"
         "passive\n";
  std::map<int, eval::Trajectory> teammate_tum;
  std::map<int, PairMetrics> by_teammate;
  for (const swarm::DroneOutput& s : scans) {
    const double t = ToSeconds(s.ego.stamp_ns);
    for (const swarm::TeammateEstimate& r : s.teammates) {
      AddEstimate(c, t, r, s.ego.stamp_ns, ext, &teammate_tum[r.drone_id],
                  &by_teammate[r.drone_id]);
      eval::ErrorSeries* e = SeriesFor(name + "->" + c.name(r.drone_id), series);
      e->time_s.push_back(t - t0);
      e->error.push_back(by_teammate[r.drone_id].extrinsic_end_m);
    }
  }
  Status status;
  for (auto& [j, traj] : teammate_tum) {
    const Status s = eval::WriteTumTrajectory(
        (dir / (name + "_teammate_" + c.name(j) + "_tum.txt")).string(), traj);
    if (status.ok()) status = s;
  }
  for (int j = 0; j < c.run->num_drones(); ++j) {
    if (j == c.observer) continue;
    PairMetrics m = by_teammate.count(j) ? by_teammate[j] : PairMetrics();
    m.observer = name;
    m.teammate = c.name(j);
    AddIdentification(c, j, t0, &m);
    if (m.relative_samples > 0)
      m.relative_rmse_m = std::sqrt(m.relative_rmse_m / m.relative_samples);
    AddClockOffset(c, j, scans.back().ego.stamp_ns, &m);
    pairs->push_back(m);
  }
  return status;
}

// Every drone's map in G of the first drone, through drone 0's final T_G0_Gj
// estimates (drones it never identified are left out).
Status WriteMergedMap(const replay::SwarmReplay& run, const fs::path& dir) {
  std::vector<Eigen::Vector3d> merged = run.drone(0).estimator().MapPoints();
  for (const swarm::TeammateEstimate& r : run.drone(0).scans().back().teammates) {
    const Eigen::Isometry3d T = r.T_Gi_Gj.T_Ga_Gb();
    for (const Eigen::Vector3d& p : run.drone(r.drone_id).estimator().MapPoints()) {
      merged.push_back(T * p);
    }
  }
  return io::WritePcd((dir / "merged_map.pcd").string(), merged);
}

std::string InViewCell(const PairMetrics& m) {
  if (m.scans_in_view < 0) return "-";
  std::ostringstream os;
  os << m.fused_in_view << " / " << m.scans_in_view;
  if (m.scans_in_view > 0) {
    os << " (" << std::fixed << std::setprecision(0) << 100.0 * m.fused_in_view / m.scans_in_view
       << " %)";
  }
  return os.str();
}

std::string PairsMarkdown(const std::vector<PairMetrics>& pairs) {
  std::ostringstream md;
  md << "| observer | teammate | identified [s] | after excitation start [s] | extrinsic end [m / "
        "deg] | extrinsic max [m / deg] | teammate rel. RMSE [m] | active / passive fused | "
        "active fused / scans in view | wrong identification |\n"
        "|---|---|---|---|---|---|---|---|---|---|\n";
  md << std::fixed;
  for (const PairMetrics& m : pairs) {
    md << "| " << m.observer << " | " << m.teammate << " | ";
    if (!m.identified) {
      md << "never | - | - | - | - | - | - | - |\n";
      continue;
    }
    md << std::setprecision(1) << m.identification_s << " | " << m.since_excitation_s << " | "
       << std::setprecision(3) << m.extrinsic_end_m << " / " << std::setprecision(2)
       << m.extrinsic_end_deg << " | " << std::setprecision(3) << m.extrinsic_max_m << " / "
       << std::setprecision(2) << m.extrinsic_max_deg << " | " << std::setprecision(3)
       << m.relative_rmse_m << " | " << m.active_fused << " / " << m.passive_fused << " | "
       << InViewCell(m) << " | " << (m.wrong_identification ? "yes" : "no") << " |\n";
  }
  return md.str();
}

void WritePairsCsv(const std::vector<PairMetrics>& pairs, const fs::path& path) {
  std::ofstream csv(path.string());
  csv << "observer,teammate,identified,identification_s,since_excitation_s,extrinsic_end_m,"
         "extrinsic_end_deg,extrinsic_max_m,extrinsic_max_deg,relative_rmse_m,active_fused,"
         "passive_fused,initial_error_m,initial_error_deg,clock_offset_true_ms,"
         "clock_offset_error_ms,scans_in_view,fused_in_view,wrong_identification\n";
  for (const PairMetrics& m : pairs) {
    csv << m.observer << "," << m.teammate << "," << (m.identified ? 1 : 0) << ","
        << std::setprecision(6) << m.identification_s << "," << m.since_excitation_s << ","
        << m.extrinsic_end_m << "," << m.extrinsic_end_deg << "," << m.extrinsic_max_m << ","
        << m.extrinsic_max_deg << "," << m.relative_rmse_m << "," << m.active_fused << ","
        << m.passive_fused << "," << m.initial_error_m << "," << m.initial_error_deg << ","
        << m.clock_offset_true_ms << "," << m.clock_offset_error_ms << "," << m.scans_in_view << ","
        << m.fused_in_view << "," << (m.wrong_identification ? 1 : 0) << "\n";
  }
}

}  // namespace

Status WriteSwarmReport(const replay::SwarmReplay& run,
                        const std::string& output_dir,
                        bool save_maps,
                        std::vector<PairMetrics>* pairs,
                        std::string* markdown) {
  const fs::path dir(output_dir);
  Status first_error;
  auto note = [&](const Status& s) {
    if (!s.ok() && first_error.ok()) first_error = s;
  };
  pairs->clear();
  std::vector<eval::Trajectory> truth;
  std::vector<bool> has_truth;
  ReadTruth(run, &truth, &has_truth);
  std::vector<eval::ErrorSeries> extrinsic_series;
  std::ofstream ident((dir / "identifications.csv").string());
  ident << "observer,teammate,stamp_s,since_first_scan_s,method,mean_residual_m\n";
  for (int i = 0; i < run.num_drones(); ++i) {
    ReturnsByTeammate returns;
    const std::string& returns_path = run.drone(i).input().teammate_returns_path;
    const bool have_returns = !returns_path.empty();
    if (have_returns) note(ReadTeammateReturns(returns_path, &returns));
    const ObserverContext c{&run, i, &truth, &has_truth, have_returns ? &returns : nullptr};
    note(ReportObserver(c, dir, ident, &extrinsic_series, pairs));
  }
  if (!extrinsic_series.empty()) {
    eval::PlotOptions plot;
    plot.title = run.manifest().name + ": T_Gi_Gj translation error over time";
    note(eval::PlotErrorOverTime(extrinsic_series, "extrinsic error [m]", plot,
                                 (dir / "extrinsic_error.png").string()));
  }
  if (save_maps && run.num_drones() > 0 && !run.drone(0).scans().empty()) {
    note(WriteMergedMap(run, dir));
  }
  *markdown = PairsMarkdown(*pairs);
  WritePairsCsv(*pairs, dir / "swarm_pairs.csv");
  std::ofstream mdfile((dir / "swarm.md").string());
  mdfile << *markdown;
  return first_error;
}

}  // namespace swarmlio::tools
