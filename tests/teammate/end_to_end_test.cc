// End to end on simulated indoor_3uav flight (18 s, realistic preset): uav2
// (a Mid-360) must identify both teammates from its own scans and observe
// them accurately, twice:
//  - GivenTrueEgoPoses: the observer's pose (scan end and motion
//    compensation) and the teammates' broadcast states are the truth, the
//    points go into the body with the true extrinsic (the protocol);
//  - OnEstimatedPoses: all of them come from each drone's lio::Odometry run
//    over its simulated data with the calibration handed to the estimator
//    (with its error), as on a real drone.
// The full 60 s acceptance runs in tools/teammate/teammate_eval.cc
// (docs/teammate.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "sim_harness.h"
#include "swarmlio/sim/scenario.h"

namespace swarmlio::teammate {
namespace {

constexpr int kObserver = 1;  // uav2

void LoadIndoor3uav(sim::Scenario* scenario) {
  ASSERT_TRUE(sim::LoadScenario(std::string(SWARMLIO_SOURCE_DIR) +
                                    "/configs/scenarios/indoor_3uav.yaml",
                                scenario)
                  .ok());
  scenario->options.duration_s = 18.0;
}

// Median observation error at 2-10 m range (-1 without observations there)
// and the number of those observations.
double MedianErrorAt2To10m(const harness::ObserverReport& report, size_t* count) {
  std::vector<double> errors;
  for (const harness::ObservationRecord& o : report.observations) {
    if (o.range_m >= 2.0 && o.range_m <= 10.0) errors.push_back(o.error_m);
  }
  *count = errors.size();
  if (errors.empty()) return -1.0;
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  return errors[errors.size() / 2];
}

void PrintFigures(const char* poses, const harness::ObserverReport& report) {
  for (const harness::IdentificationRecord& r : report.identifications) {
    std::printf("[ figures  ] %s poses: uav2 -> uav%d identified %.2f s after the excitation "
                "start, dT %.4f m, dR %.3f deg, mean residual %.4f m, %d pairs%s\n",
                poses, r.teammate + 1, r.since_excitation_s, r.translation_error_m,
                r.rotation_error_deg, r.mean_residual_m, r.num_pairs,
                r.correct ? "" : " (WRONG tracker)");
  }
  size_t count = 0;
  const double median = MedianErrorAt2To10m(report, &count);
  std::printf("[ figures  ] %s poses: median observation error at 2-10 m %.4f m (%zu of %zu), "
              "%d wrong observations, %d temporary trackers off the teammates, %d scans without "
              "a pose\n",
              poses, median, count, report.observations.size(), report.wrong_observations,
              report.temporary_elsewhere, report.scans_without_pose);
}

TEST(TeammateEndToEnd, Uav2IdentifiesBothTeammatesInIndoor3uavGivenTrueEgoPoses) {
  sim::Scenario scenario;
  LoadIndoor3uav(&scenario);
  if (HasFatalFailure()) return;
  const sim::Simulator sim(std::move(scenario.scene), scenario.drones, scenario.objects,
                           scenario.simulation_config());
  harness::ObserverReport report;
  ASSERT_TRUE(harness::EvaluateObserver(sim, kObserver, TeammateDetectorOptions(),
                                        harness::HarnessOptions(), &report)
                  .ok());
  PrintFigures("true", report);
  EXPECT_EQ(report.scans_without_pose, 0);  // the truth covers every scan
  std::vector<int> identified;
  for (const harness::IdentificationRecord& r : report.identifications) {
    identified.push_back(r.teammate);
    EXPECT_TRUE(r.correct) << "teammate " << r.teammate;
    EXPECT_LT(r.translation_error_m, 0.1) << "teammate " << r.teammate;
    EXPECT_LT(r.rotation_error_deg, 2.0) << "teammate " << r.teammate;
    EXPECT_LT(r.since_excitation_s, 11.0) << "teammate " << r.teammate;
  }
  std::sort(identified.begin(), identified.end());
  EXPECT_EQ(identified, (std::vector<int>{0, 2}));

  size_t count = 0;
  const double median_error_m = MedianErrorAt2To10m(report, &count);
  ASSERT_GT(count, 20u);
  EXPECT_LT(median_error_m, 0.05);
  EXPECT_EQ(report.wrong_observations, 0);
  EXPECT_EQ(report.temporary_elsewhere, 0);
}

// Bounds at 2-3x the figures measured on this run (in the comments), but the
// identification latency: this run ends 10.1-10.4 s after the pairs'
// excitation starts, so it is bounded by the acceptance criterion (10 s).
TEST(TeammateEndToEnd, Uav2IdentifiesBothTeammatesInIndoor3uavOnEstimatedPoses) {
  sim::Scenario scenario;
  LoadIndoor3uav(&scenario);
  if (HasFatalFailure()) return;
  const sim::Simulator sim(std::move(scenario.scene), scenario.drones, scenario.objects,
                           scenario.simulation_config());
  std::vector<harness::EstimatedTrajectory> estimates;
  ASSERT_TRUE(harness::EstimateEgoTrajectories(sim, &estimates).ok());
  for (size_t j = 0; j < estimates.size(); ++j) {
    const harness::EstimatedTrajectory& estimate = estimates[j];
    ASSERT_FALSE(estimate.states.empty()) << sim.drones()[j].name;
    // Broadcasts and the observer's poses cover the whole excitation.
    const int drone = static_cast<int>(j);
    EXPECT_LT(estimate.states.front().stamp_ns,
              sim.StampNs(drone, harness::ExcitationStartTime(sim, drone)))
        << sim.drones()[j].name;
    double position_error_m = 0.0, rotation_error_deg = 0.0;
    harness::EstimateErrors(sim, drone, estimate, &position_error_m, &rotation_error_deg);
    std::printf("[ figures  ] %s odometry: max error %.4f m, %.3f deg over %zu scan ends\n",
                sim.drones()[j].name.c_str(), position_error_m, rotation_error_deg,
                estimate.states.size());
  }

  harness::HarnessOptions options;
  options.ego_estimates = &estimates;
  harness::ObserverReport report;
  ASSERT_TRUE(harness::EvaluateObserver(sim, kObserver, TeammateDetectorOptions(), options,
                                        &report)
                  .ok());
  PrintFigures("estimated", report);
  std::vector<int> identified;
  for (const harness::IdentificationRecord& r : report.identifications) {
    identified.push_back(r.teammate);
    EXPECT_TRUE(r.correct) << "teammate " << r.teammate;
    EXPECT_LT(r.translation_error_m, 0.08) << "teammate " << r.teammate;  // 0.019, 0.031 m
    EXPECT_LT(r.rotation_error_deg, 1.5) << "teammate " << r.teammate;    // 0.62, 0.68 deg
    EXPECT_LT(r.since_excitation_s, 10.0) << "teammate " << r.teammate;   // 7.52, 7.54 s
  }
  std::sort(identified.begin(), identified.end());
  EXPECT_EQ(identified, (std::vector<int>{0, 2}));

  size_t count = 0;
  const double median_error_m = MedianErrorAt2To10m(report, &count);
  ASSERT_GT(count, 10u);                // 25 observations at 2-10 m
  EXPECT_LT(median_error_m, 0.1);       // 0.040 m
  EXPECT_EQ(report.wrong_observations, 0);
  EXPECT_EQ(report.temporary_elsewhere, 0);
}

}  // namespace
}  // namespace swarmlio::teammate
