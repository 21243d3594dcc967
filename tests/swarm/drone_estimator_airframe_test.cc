// A drone's airframe on the swarm's messages (docs/network.md "Airframe",
// docs/swarm.md): a teammate's announcement reaches the detector through the
// component's own entry (DroneEstimator::Add), and the component announces
// its own airframe with its first scan's messages and then every
// swarm.experimental.airframe_period_s (one simulated drone of indoor_3uav,
// fed straight into two components, one of them never announcing).
#include <gtest/gtest.h>

#include <memory>
#include <utility>
#include <variant>
#include <vector>

#include "observer_run.h"
#include "swarmlio/net/wire_format.h"
#include "swarmlio/swarm/drone_estimator.h"

namespace swarmlio::swarm {
namespace {

using test_support::IndoorScenario;
using test_support::OptionsFor;

net::AirframeMessage TeammateAirframe(int sender, double min_intensity) {
  net::AirframeMessage m;
  m.sender_id = sender;
  m.stamp_ns = 5'000'000'000;
  m.reflector_shape = 1;  // box
  m.reflector_half_extents_m = {0.15, 0.15, 0.05};
  m.depth_offset_m = 0.05;
  m.size_m = 0.6;
  m.min_intensity = min_intensity;
  m.centroid_sigma_m = 0.01;
  return m;
}

net::ReceivedMessage Received(const net::AirframeMessage& m) {
  net::ReceivedMessage r;
  r.arrival_ns = m.stamp_ns;
  r.message = m;
  return r;
}

TEST(DroneEstimatorAirframe, ATeammatesAnnouncementLowersTheReflectivityGate) {
  sim::Scenario scenario = IndoorScenario();
  ASSERT_FALSE(scenario.drones.empty());
  const sim::DroneConfig& d = scenario.drones[0];
  DroneEstimatorOptions o = OptionsFor(d);
  o.teammate.clustering.min_reflectivity = 200.0;
  std::unique_ptr<DroneEstimator> e;
  ASSERT_TRUE(DroneEstimator::Create(0, o, sim::GivenLidarOptions(d), &e).ok());
  EXPECT_EQ(e->detector().min_reflectivity(), 200.0);

  // Ignored: its own airframe, an unknown shape, an invalid description.
  ASSERT_TRUE(e->Add(Received(TeammateAirframe(0, 100.0))).ok());
  net::AirframeMessage unknown = TeammateAirframe(1, 100.0);
  unknown.reflector_shape = 3;
  ASSERT_TRUE(e->Add(Received(unknown)).ok());
  net::AirframeMessage invalid = TeammateAirframe(1, 100.0);
  invalid.size_m = 0.0;  // below AirframeDescription's 0.05 m
  ASSERT_TRUE(e->Add(Received(invalid)).ok());
  EXPECT_EQ(e->counters().messages_ignored, 3);
  EXPECT_EQ(e->detector().min_reflectivity(), 200.0);

  ASSERT_TRUE(e->Add(Received(TeammateAirframe(1, 100.0))).ok());
  EXPECT_EQ(e->counters().messages_received, 4);
  EXPECT_EQ(e->counters().messages_ignored, 3);
  EXPECT_EQ(e->detector().min_reflectivity(), 100.0);
  // A brighter body never raises the gate above the lowest announced.
  ASSERT_TRUE(e->Add(Received(TeammateAirframe(2, 230.0))).ok());
  EXPECT_EQ(e->detector().min_reflectivity(), 100.0);
}

// Feeds one simulated drone's IMU and scans to components and keeps what
// each hands out (PopMessages after every record).
class TwoComponents : public sim::DroneSink {
 public:
  explicit TwoComponents(std::vector<std::unique_ptr<DroneEstimator>>* estimators)
      : sent(estimators->size()), estimators_(estimators) {}
  Status OnImu(const ImuSample& imu) override { return Feed(imu); }
  Status OnScan(const LidarScan& scan, int64_t /*record_time_ns*/) override { return Feed(scan); }
  Status OnGroundTruth(const PoseStamped& /*pose*/) override { return Status::Ok(); }

  std::vector<std::vector<std::vector<net::SwarmMessage>>> sent;  // per component, per batch

 private:
  Status Feed(const SensorRecord& record) {
    for (size_t i = 0; i < estimators_->size(); ++i) {
      SWARMLIO_RETURN_IF_ERROR((*estimators_)[i]->Add(record));
      std::vector<net::SwarmMessage> batch;
      (*estimators_)[i]->PopMessages(&batch);
      if (!batch.empty()) sent[i].push_back(std::move(batch));
    }
    return Status::Ok();
  }

  std::vector<std::unique_ptr<DroneEstimator>>* estimators_;
};

TEST(DroneEstimatorAirframe, AnnouncesItsOwnWithTheFirstScanAndThenEveryPeriod) {
  sim::Scenario scenario = IndoorScenario();
  ASSERT_FALSE(scenario.drones.empty());
  constexpr double kPeriodS = 0.5;
  sim::SimulationConfig config = scenario.simulation_config();
  config.duration_s = 2.3;
  config.num_threads = 1;
  const std::vector<sim::DroneConfig> drones = scenario.drones;
  const sim::Simulator simulator(std::move(scenario.scene), drones, scenario.objects, config);

  DroneEstimatorOptions o = OptionsFor(drones[0]);
  o.airframe.reflector_shape = teammate::ReflectorShape::kBox;
  o.airframe.min_intensity = 120.0;
  o.airframe.size_m = 0.62;
  o.swarm.airframe_period_s = kPeriodS;
  std::vector<std::unique_ptr<DroneEstimator>> estimators(2);
  for (int i = 0; i < 2; ++i) {
    if (i == 1) o.swarm.airframe_period_s = 0.0;  // never
    ASSERT_TRUE(
        DroneEstimator::Create(0, o, sim::GivenLidarOptions(drones[0]), &estimators[i]).ok());
  }
  TwoComponents sink(&estimators);
  sim::DroneStats stats;
  ASSERT_TRUE(simulator.RunDrone(0, &sink, &stats).ok());

  // The announcing component: which state stamps came with an announcement.
  std::vector<int64_t> state_stamps, airframe_stamps;
  bool first_with_first_state = false;
  for (const std::vector<net::SwarmMessage>& batch : sink.sent[0]) {
    int64_t state_ns = -1, airframe_ns = -1;
    for (const net::SwarmMessage& m : batch) {
      if (const auto* s = std::get_if<net::EgoStateMessage>(&m)) state_ns = s->stamp_ns;
      if (const auto* a = std::get_if<net::AirframeMessage>(&m)) {
        airframe_ns = a->stamp_ns;
        EXPECT_EQ(a->sender_id, 0);
        EXPECT_EQ(a->reflector_shape, 1);
        EXPECT_EQ(a->min_intensity, 120.0);
        EXPECT_EQ(a->size_m, 0.62);
        EXPECT_EQ(a->reflector_half_extents_m, o.airframe.reflector_half_extents_m);
      }
    }
    if (state_ns >= 0) state_stamps.push_back(state_ns);
    if (airframe_ns >= 0) {
      EXPECT_EQ(airframe_ns, state_ns) << "announced with a scan's messages";
      if (airframe_stamps.empty()) first_with_first_state = state_stamps.size() == 1;
      airframe_stamps.push_back(airframe_ns);
    }
  }
  ASSERT_GE(state_stamps.size(), 8u);
  EXPECT_TRUE(first_with_first_state);
  // The rule on the scan stamps: the first, then the first scan at least a
  // period after the previous announcement.
  std::vector<int64_t> expected;
  for (int64_t t : state_stamps) {
    if (expected.empty() || t - expected.back() >= static_cast<int64_t>(kPeriodS * 1e9)) {
      expected.push_back(t);
    }
  }
  EXPECT_EQ(airframe_stamps, expected);
  EXPECT_GE(airframe_stamps.size(), 2u);
  const int64_t wire_bytes = static_cast<int64_t>(net::AirframePacketBytes() +
                                                  o.swarm.broadcast_budget.ip_udp_header_bytes);
  EXPECT_EQ(estimators[0]->counters().sent_airframe_bytes,
            wire_bytes * static_cast<int64_t>(airframe_stamps.size()));

  // The other never announces.
  for (const std::vector<net::SwarmMessage>& batch : sink.sent[1]) {
    for (const net::SwarmMessage& m : batch) {
      EXPECT_FALSE(std::holds_alternative<net::AirframeMessage>(m));
    }
  }
  EXPECT_EQ(estimators[1]->counters().sent_airframe_bytes, 0);
}

}  // namespace
}  // namespace swarmlio::swarm
