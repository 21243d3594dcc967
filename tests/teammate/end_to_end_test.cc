// End to end on simulated indoor_3uav flight (18 s): uav2 (a Mid-360) must
// identify both teammates from its own scans, with true ego poses as input,
// and observe them accurately. The full 60 s acceptance runs in
// tools/teammate/teammate_eval.cc (docs/teammate.md).
#include <gtest/gtest.h>

#include <algorithm>

#include "sim_harness.h"
#include "swarmlio/sim/scenario.h"

namespace swarmlio::teammate {
namespace {

TEST(TeammateEndToEnd, Uav2IdentifiesBothTeammatesInIndoor3uavGivenTrueEgoPoses) {
  sim::Scenario scenario;
  ASSERT_TRUE(sim::LoadScenario(std::string(SWARMLIO_SOURCE_DIR) +
                                    "/configs/scenarios/indoor_3uav.yaml",
                                &scenario)
                  .ok());
  scenario.options.duration_s = 18.0;
  const sim::Simulator sim(std::move(scenario.scene), scenario.drones, scenario.objects,
                           scenario.simulation_config());
  harness::ObserverReport report;
  ASSERT_TRUE(harness::EvaluateObserver(sim, /*observer=*/1, TeammateDetectorOptions(),
                                        harness::HarnessOptions(), &report)
                  .ok());
  EXPECT_EQ(report.scans, 180);
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

  std::vector<double> errors;
  for (const harness::ObservationRecord& o : report.observations) {
    if (o.range_m >= 2.0 && o.range_m <= 10.0) errors.push_back(o.error_m);
  }
  ASSERT_GT(errors.size(), 20u);
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.05);
  EXPECT_EQ(report.wrong_observations, 0);
  EXPECT_EQ(report.temporary_elsewhere, 0);
}

}  // namespace
}  // namespace swarmlio::teammate
