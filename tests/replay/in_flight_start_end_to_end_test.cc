// A drone that starts its estimator in flight (issue #13, faults B: a late
// join or a restart mid-flight), offline and deterministic: indoor_3uav
// (realistic imperfections, the scenario's seed) is simulated for 36 s and
// replayed, with the calibration the simulator reports as given, with uav3
// (the Avia) starting 20 s into its log, during its excitation flight
// (manifest start_offset_s). With the static initialization it assumes rest
// while moving: its trajectory, in its G (the IMU frame at its
// initialization), is several centimetres off and its teammates' extrinsics
// of it are tilted by degrees. With initialization: in_flight (velocity and
// gravity from LiDAR passes over its first scans) it tracks like a drone that
// started at rest, and both teammates identify it within 15 s of its start
// with a correct extrinsic (measured with the given calibration: 5.6 and
// 5.7 s, 2.4 cm / 0.52 deg and 4.5 cm / 0.32 deg at the end; with the true
// calibration 6.2 s, 1.3 cm / 0.70 deg and 2.6 cm / 0.43 deg).
// SWARMLIO_IN_FLIGHT_REFERENCE=1 also prints uav3 from rest with each method.
// docs/imu.md section 1b, results.md.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/replay/swarm_replay.h"
#include "test_utils/simulated_swarm.h"

namespace swarmlio::replay {
namespace {

namespace fs = std::filesystem;

constexpr int kLateJoiner = 2;  // uav3, the Avia
constexpr double kStartOffsetS = 20.0;
constexpr double kDurationS = 36.0;

// T_G_b of a ground-truth track at `stamp_ns` (linear position, slerp).
bool PoseAt(const std::vector<PoseStamped>& track, int64_t stamp_ns, Eigen::Isometry3d* T) {
  const auto it = std::lower_bound(track.begin(), track.end(), stamp_ns,
                                   [](const PoseStamped& p, int64_t t) { return p.stamp_ns < t; });
  if (it == track.begin() || it == track.end()) return false;
  const PoseStamped& a = *(it - 1);
  const PoseStamped& b = *it;
  const double s =
      static_cast<double>(stamp_ns - a.stamp_ns) / static_cast<double>(b.stamp_ns - a.stamp_ns);
  T->setIdentity();
  T->linear() = a.q_G_b.slerp(s, b.q_G_b).toRotationMatrix();
  T->translation() = (1.0 - s) * a.p_b_in_G + s * b.p_b_in_G;
  return true;
}

struct LateDroneFigures {
  double position_rmse_m = 0.0;  // in its true G, no alignment
  double init_delay_s = 0.0;     // from its first record to its initialization (t0)
  double first_output_s = 0.0;   // from its first record to its first output
  double init_tilt_deg = 0.0;    // initial gravity direction error
  double init_velocity_error_m_s = 0.0;
  double reference_rmse_m = 0.0;  // uav1, from a static start, same measure
  int held_scans = 0;             // its outputs flagged held_by_initialization
  bool held_first = true;         // ... all of them before its other outputs
  int reference_held_scans = 0;   // the teammate from rest's flagged outputs
  // Per teammate (manifest order, the late drone's entry unused):
  std::vector<double> identified_after_s;          // since its first record; < 0: never
  std::vector<double> end_error_m, end_error_deg;  // the extrinsic at the end of the run
};

class InFlightStartTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() /
                        ("swarmlio_in_flight_" + std::to_string(::getpid())));
    fs::create_directories(*dir_);
    manifest_ = new driver::SwarmManifest();
    ASSERT_TRUE(swarmlio::testing::SimulateSwarm(
        std::string(SWARMLIO_SOURCE_DIR) + "/configs/scenarios/indoor_3uav.yaml", "indoor_3uav",
        kDurationS, *dir_, manifest_, nullptr, /*true_G_in_W=*/true));
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
    delete manifest_;
  }

  // The drone `late` starts `offset_s` into its log with `mode`; with
  // `restart` it starts at rest and is restarted there instead (down 1 s).
  static LateDroneFigures Run(lio::InitializationMode mode,
                              double offset_s = kStartOffsetS,
                              int late = kLateJoiner,
                              bool restart = false) {
    driver::SwarmManifest manifest = *manifest_;
    driver::DroneInput& input = manifest.drones[late];
    if (restart) {
      input.restart_at_s = offset_s;
      input.restart_initialization = mode;
    } else {
      input.start_offset_s = offset_s;
      input.odometry.initialization = mode;
    }
    std::unique_ptr<SwarmReplay> run;
    EXPECT_TRUE(SwarmReplay::Create(manifest, &run).ok());
    EXPECT_TRUE(run->Run(ReplayOptions()).ok());
    LateDroneFigures f;
    const DroneRunner& d = run->drone(late);
    EXPECT_TRUE(d.estimator().initialized());
    const std::vector<PoseStamped>& gt = d.bag_ground_truth();  // T_G0_b, G0 at the log start
    const int64_t t0 = d.estimator().initialization().stamp_ns;
    EXPECT_FALSE(gt.empty());
    if (gt.empty()) return f;
    // Its start: its first record, or its return after the restart.
    const int64_t start_ns =
        gt.front().stamp_ns +
        (restart ? static_cast<int64_t>(std::llround((offset_s + input.restart_down_s) * 1e9)) : 0);
    f.init_delay_s = 1e-9 * static_cast<double>(t0 - start_ns);
    if (!d.scans().empty()) {
      f.first_output_s = 1e-9 * static_cast<double>(d.scans().front().ego.stamp_ns - start_ns);
    }
    bool unheld_seen = false;
    for (const swarm::DroneOutput& s : d.scans()) {
      if (s.ego.held_by_initialization) {
        ++f.held_scans;
        if (unheld_seen) f.held_first = false;
      } else {
        unheld_seen = true;
      }
    }
    Eigen::Isometry3d T_G0_G;  // its true G: the IMU pose at the initialization
    EXPECT_TRUE(PoseAt(gt, t0, &T_G0_G));
    {
      // G0 is gravity-aligned (the log starts at rest, level).
      const Eigen::Vector3d g_true = T_G0_G.linear().transpose() * Eigen::Vector3d(0, 0, -1);
      const Eigen::Vector3d g_est = d.estimator().initialization().state.g_in_G.normalized();
      f.init_tilt_deg = std::acos(std::clamp(g_true.dot(g_est), -1.0, 1.0)) * 180.0 / M_PI;
      Eigen::Isometry3d a, b;
      if (PoseAt(gt, t0 - 5'000'000, &a) && PoseAt(gt, t0 + 5'000'000, &b)) {
        const Eigen::Vector3d v_true =
            T_G0_G.linear().transpose() * (b.translation() - a.translation()) / 0.01;
        f.init_velocity_error_m_s = (d.estimator().initialization().state.v_b_in_G - v_true).norm();
      }
    }
    {
      const DroneRunner& ref = run->drone(late == 0 ? 1 : 0);
      double sse0 = 0.0;
      int n0 = 0;
      for (const swarm::DroneOutput& s : ref.scans()) {
        if (s.ego.held_by_initialization) ++f.reference_held_scans;
        Eigen::Isometry3d T;
        if (!PoseAt(ref.bag_ground_truth(), s.ego.stamp_ns, &T)) continue;
        sse0 += (s.ego.state.p_b_in_G - T.translation()).squaredNorm();
        ++n0;
      }
      f.reference_rmse_m = std::sqrt(sse0 / std::max(n0, 1));
    }
    double sse = 0.0;
    int n = 0;
    for (const swarm::DroneOutput& s : d.scans()) {
      Eigen::Isometry3d T_G0_b;
      if (!PoseAt(gt, s.ego.stamp_ns, &T_G0_b)) continue;
      sse += (s.ego.state.p_b_in_G - (T_G0_G.inverse() * T_G0_b).translation()).squaredNorm();
      ++n;
    }
    EXPECT_GT(n, 50);
    f.position_rmse_m = std::sqrt(sse / std::max(n, 1));
    // True T_Gi_Gj with the late drone's G.
    const Eigen::Isometry3d T_W_Gj = manifest.drones[late].T_W_G() * T_G0_G;
    f.identified_after_s.assign(manifest.drones.size(), -1.0);
    f.end_error_m.assign(manifest.drones.size(), -1.0);
    f.end_error_deg.assign(manifest.drones.size(), -1.0);
    for (int i = 0; i < run->num_drones(); ++i) {
      if (i == late) continue;
      const DroneRunner& observer = run->drone(i);
      for (const swarm::IdentificationEvent& e : observer.identifications()) {
        // (after a restart: the identification of its new session)
        const double after_s = 1e-9 * static_cast<double>(e.stamp_ns - start_ns);
        if (e.drone_id == late && f.identified_after_s[i] < 0.0 && after_s > 0.0) {
          f.identified_after_s[i] = after_s;
        }
      }
      const Eigen::Isometry3d T_true = manifest.drones[i].T_W_G().inverse() * T_W_Gj;
      for (auto s = observer.scans().rbegin(); s != observer.scans().rend(); ++s) {
        const auto t = std::find_if(s->teammates.begin(), s->teammates.end(),
                                    [&](const swarm::TeammateEstimate& r) { return r.drone_id == late; });
        if (t == s->teammates.end()) continue;
        const Eigen::Isometry3d E = T_true.inverse() * t->T_Gi_Gj.T_Ga_Gb();
        f.end_error_m[i] = E.translation().norm();
        f.end_error_deg[i] = Eigen::AngleAxisd(E.linear()).angle() * 180.0 / M_PI;
        break;
      }
    }
    return f;
  }

  static fs::path* dir_;
  static driver::SwarmManifest* manifest_;
};

fs::path* InFlightStartTest::dir_ = nullptr;
driver::SwarmManifest* InFlightStartTest::manifest_ = nullptr;

void Print(const char* label, const LateDroneFigures& f, int late = kLateJoiner) {
  std::printf(
      "[ figures  ] %s: uav%d initialized %.2f s after its start (first output %.2f s; "
      "tilt %.3f deg, velocity %.3f m/s off), position RMSE in its true G %.4f m (a "
      "teammate from rest: %.4f m)",
      label, late + 1, f.init_delay_s, f.first_output_s, f.init_tilt_deg, f.init_velocity_error_m_s,
      f.position_rmse_m, f.reference_rmse_m);
  for (size_t i = 0; i < f.identified_after_s.size(); ++i) {
    if (static_cast<int>(i) == late) continue;
    std::printf("; uav%zu identified it after %.1f s (extrinsic at the end %.4f m / %.3f deg)",
                i + 1, f.identified_after_s[i], f.end_error_m[i], f.end_error_deg[i]);
  }
  std::printf("\n");
}

TEST_F(InFlightStartTest, LateJoinerInitializedInFlightTracksAndIsIdentified) {
  const LateDroneFigures at_rest = Run(lio::InitializationMode::kStatic);
  const LateDroneFigures in_flight = Run(lio::InitializationMode::kInFlight);
  Print("static", at_rest);
  Print("in_flight", in_flight);
  if (std::getenv("SWARMLIO_IN_FLIGHT_REFERENCE") != nullptr) {
    Print("from rest, static", Run(lio::InitializationMode::kStatic, 0.0));
    Print("from rest, in_flight", Run(lio::InitializationMode::kInFlight, 0.0));
  }
  // Measured (Release, the given calibration): static 0.182 m (it
  // initializes 8.9 s late, 0.18 m/s off), in_flight 0.018 m (with the true
  // calibration 0.146 and 0.020 m).
  EXPECT_GT(at_rest.position_rmse_m, 0.05);
  EXPECT_LT(in_flight.position_rmse_m, 0.045);
  EXPECT_LT(in_flight.first_output_s, 1.5);  // the IMU window (1 s), then from its first scan
  // The scans its passes held (the probe window, 1.5 s at 10 Hz, and those
  // that came while the passes ran) are flagged, and only those: the live
  // latency figures leave them out.
  std::printf("[ figures  ] in_flight: %d scans held by the initialization\n", in_flight.held_scans);
  EXPECT_GE(in_flight.held_scans, 10);
  EXPECT_LE(in_flight.held_scans, 60);
  EXPECT_TRUE(in_flight.held_first);
  EXPECT_EQ(in_flight.reference_held_scans, 0);
  EXPECT_EQ(at_rest.held_scans, 0);
  for (int i = 0; i < 2; ++i) {
    EXPECT_GE(in_flight.identified_after_s[i], 0.0) << i;
    EXPECT_LE(in_flight.identified_after_s[i], 15.0) << i;
    EXPECT_LT(in_flight.end_error_m[i], 0.1) << i;
    EXPECT_LT(in_flight.end_error_deg[i], 1.2) << i;
  }
}

// A restart mid-flight (the faults-B restart, offline): uav2 starts at rest,
// is killed 18 s into its log (its estimator dropped, down 1 s) and starts a
// new session in flight. Its teammates drop it and identify it again. Before
// the fix, they also took each other's T_Gk_G2 of its OLD session (broadcast
// until the sender hears the new session) as a graph identification: uav3's
// extrinsic of it was then off by its motion since its first start (1.9 m /
// 11 deg on the 60 s run, restart at 30 s), with either initialization.
TEST_F(InFlightStartTest, RestartedDroneIsIdentifiedAgainWithItsNewG) {
  constexpr int kRestarted = 1;  // uav2 (Mid-360)
  const LateDroneFigures f =
      Run(lio::InitializationMode::kInFlight, 18.0, kRestarted, /*restart=*/true);
  Print("restart, in_flight", f, kRestarted);
  // Measured (Release, the given calibration): 0.0122 m; extrinsics at the
  // end 0.0081 m / 0.195 deg and 0.0077 m / 0.428 deg (uav3's was 0.0292 m /
  // 0.910 deg with the airframes before second-hand blocks followed their
  // source; with the true calibration 0.0037 m; 0.0103 m / 0.081 deg and
  // 0.0067 m / 0.341 deg).
  EXPECT_LT(f.position_rmse_m, 0.03);
  for (int i : {0, 2}) {
    EXPECT_GE(f.identified_after_s[i], 0.0) << i;
    EXPECT_LE(f.identified_after_s[i], 15.0) << i;
    EXPECT_LT(f.end_error_m[i], 0.025) << i;
    EXPECT_LT(f.end_error_deg[i], 1.0) << i;
  }
}

}  // namespace
}  // namespace swarmlio::replay
