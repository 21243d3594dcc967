// The window back end in the swarm (docs/window.md, "Teammates"): every
// drone of a short indoor_3uav flight (static start, take-off, excitation,
// identification at about 14 s) runs the window; the mutual observations
// enter the window at their scan's state, the T_Gi_Gj blocks are shared by
// the window's scans and kept through marginalization. Simulated bags are
// replayed through the simulated network, as swarmlio_replay does.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/eval/consistency.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/replay/swarm_replay.h"
#include "test_utils/simulated_swarm.h"

namespace swarmlio::replay {
namespace {

namespace fs = std::filesystem;

// What one replay leaves of each drone.
struct DroneRun {
  std::vector<swarm::DroneOutput> scans;
  double position_rmse_m = 0.0;
  int identified = 0;
  int fused = 0;  // active + passive observations
};

class WindowSwarmTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() /
                        ("swarmlio_window_swarm_" + std::to_string(::getpid())));
    fs::create_directories(*dir_);
    manifest_ = new driver::SwarmManifest();
    ASSERT_TRUE(swarmlio::testing::SimulateSwarm(
        std::string(SWARMLIO_SOURCE_DIR) + "/configs/scenarios/indoor_3uav.yaml", "indoor_3uav",
        22.0, *dir_, manifest_));
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
    delete manifest_;
  }

  static std::vector<DroneRun> Run(lio::EstimatorKind estimator, int window_size) {
    driver::SwarmManifest manifest = *manifest_;
    for (driver::DroneInput& d : manifest.drones) {
      d.odometry.estimator = estimator;
      d.odometry.window.size = window_size;
      // Second-hand blocks would follow the teammates' estimates, which come
      // from the same back end in each run: the comparison of the back ends
      // is made without that coupling (docs/swarm.md "Second-hand blocks
      // follow their source").
      d.swarm.follow_source_until_observations = 0;
    }
    std::unique_ptr<SwarmReplay> run;
    EXPECT_TRUE(SwarmReplay::Create(manifest, &run).ok());
    EXPECT_TRUE(run->Run(ReplayOptions()).ok());
    std::vector<DroneRun> out;
    for (int i = 0; i < run->num_drones(); ++i) {
      const DroneRunner& d = run->drone(i);
      DroneRun r;
      r.scans = d.scans();
      eval::ConsistencyStats c;
      EXPECT_TRUE(eval::EvaluateConsistency(UpdatedEstimate(d.scans()),
                                            eval::TrajectoryFromPoses(d.bag_ground_truth()), 0.05,
                                            &c)
                      .ok());
      r.position_rmse_m = c.position_rmse_m;
      r.identified = static_cast<int>(d.identifications().size());
      for (const swarm::DroneOutput& s : d.scans())
        r.fused += s.active_observations + s.passive_observations;
      out.push_back(std::move(r));
    }
    return out;
  }

  static fs::path* dir_;
  static driver::SwarmManifest* manifest_;
};

fs::path* WindowSwarmTest::dir_ = nullptr;
driver::SwarmManifest* WindowSwarmTest::manifest_ = nullptr;

// Largest difference of the teammate extrinsics between two runs over the
// scans where both estimate the same teammate [m], [deg].
void ExtrinsicDifference(const DroneRun& a, const DroneRun& b, double* max_m, double* max_deg) {
  *max_m = 0.0;
  *max_deg = 0.0;
  for (size_t k = 0; k < std::min(a.scans.size(), b.scans.size()); ++k) {
    for (const swarm::TeammateEstimate& ta : a.scans[k].teammates) {
      for (const swarm::TeammateEstimate& tb : b.scans[k].teammates) {
        if (ta.drone_id != tb.drone_id) continue;
        *max_m = std::max(*max_m, (ta.T_Gi_Gj.p_Gb_in_Ga - tb.T_Gi_Gj.p_Gb_in_Ga).norm());
        *max_deg = std::max(
            *max_deg,
            so3::Log(ta.T_Gi_Gj.q_Ga_Gb.conjugate() * tb.T_Gi_Gj.q_Ga_Gb).norm() * 180.0 / M_PI);
      }
    }
  }
}

// K = 1 in the swarm: the same observation factors at the newest state, the
// teammate blocks random-walking over each interval as in the filter. What
// differs: the filter estimates only the teammate blocks observed in a scan
// (the others are Schmidt "consider" states, docs/esikf.md), the window
// estimates all of them; after a degenerate scan the filter takes the
// observed blocks into its gain as considered states (their covariance in
// the innovation, not corrected), the window holds them at the prediction
// (docs/window.md). The drones' broadcasts then differ slightly, so the
// differences compound through the messages. Measured (Release, the given
// calibration): positions 3.0e-3 m apart (uav3, the Avia with degenerate
// scans; 1.5e-4 and 3.5e-5 m for uav1, uav2), extrinsics 7.0 mm / 0.18 deg
// (uav3), 2.8 and 3.1 mm / 0.09 and 0.10 deg (uav1, uav2); with the true
// calibration 2.5-3.0 mm / 0.08-0.11 deg. Earlier: 1.1 mm for uav3 while the
// filter also held them exact; with the filter estimating every teammate
// block and holding them exact (a throwaway change) the runs agreed to
// 4.4e-7 m and 5.5e-7 m in T_Gi_Gj.
// K = 5: both teammates identified and fused, accuracy within the filter's.
// Its extrinsics differ from the filter's by up to 0.034 m / 2.0 deg (uav1's
// of uav2, 1.9 s after the identification: the window's is 1.9 deg off the
// truth there, the filter's 0.17 deg; both 0.26 deg at the end); with the
// true calibration they agreed within 7 mm / 0.17 deg.
// (One test: the simulation and the filter's run are shared.)
TEST_F(WindowSwarmTest, WindowFusesTheTeammatesAndEqualsTheFilterAtOneState) {
  const std::vector<DroneRun> filter = Run(lio::EstimatorKind::kFilter, 1);
  const std::vector<DroneRun> one = Run(lio::EstimatorKind::kWindow, 1);
  const std::vector<DroneRun> five = Run(lio::EstimatorKind::kWindow, 5);
  ASSERT_EQ(filter.size(), 3u);
  ASSERT_EQ(one.size(), 3u);
  ASSERT_EQ(five.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    SCOPED_TRACE(manifest_->drones[i].name);
    ASSERT_EQ(filter[i].scans.size(), one[i].scans.size());
    double max_dp = 0.0;
    for (size_t k = 0; k < filter[i].scans.size(); ++k) {
      max_dp = std::max(
          max_dp,
          (filter[i].scans[k].ego.state.p_b_in_G - one[i].scans[k].ego.state.p_b_in_G).norm());
    }
    double max_dT_m = 0.0, max_dT_deg = 0.0;
    ExtrinsicDifference(filter[i], one[i], &max_dT_m, &max_dT_deg);
    std::printf(
        "[ figures  ] %s: K = 1 vs filter in the swarm: max |dp| %.2e m, extrinsics max "
        "%.2e m / %.3f deg; observations fused %d / %d\n",
        manifest_->drones[i].name.c_str(), max_dp, max_dT_m, max_dT_deg, one[i].fused,
        filter[i].fused);
    EXPECT_EQ(one[i].identified, 2);
    EXPECT_GT(one[i].fused, 100);
    EXPECT_LT(max_dp, 7e-3);
    // 0.017 m measured (uav3; 0.007 m before the teammates' announced band
    // model moved the observations with the relative attitude, which each back
    // end predicts a little differently).
    EXPECT_LT(max_dT_m, 0.035);
    EXPECT_LT(max_dT_deg, 0.4);

    ExtrinsicDifference(filter[i], five[i], &max_dT_m, &max_dT_deg);
    std::printf(
        "[ figures  ] %s: K = 5: position RMSE %.4f m (filter %.4f m), extrinsics vs "
        "the filter's max %.3f m / %.2f deg, observations fused %d\n",
        manifest_->drones[i].name.c_str(), five[i].position_rmse_m, filter[i].position_rmse_m,
        max_dT_m, max_dT_deg, five[i].fused);
    EXPECT_EQ(five[i].identified, 2);
    EXPECT_GT(five[i].fused, 100);
    EXPECT_LT(five[i].position_rmse_m, 1.5 * filter[i].position_rmse_m + 0.002);
    EXPECT_LT(max_dT_m, 0.08);
    // Every teammate block has a covariance (the marginal of the window's information).
    const swarm::DroneOutput& last = five[i].scans.back();
    ASSERT_EQ(last.teammates.size(), 2u);
    for (const swarm::TeammateEstimate& t : last.teammates) {
      EXPECT_GT(t.extrinsic_covariance.diagonal().minCoeff(), 0.0);
      EXPECT_TRUE(t.extrinsic_covariance.diagonal().allFinite());
    }
  }
}

}  // namespace
}  // namespace swarmlio::replay
