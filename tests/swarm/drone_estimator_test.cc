// swarm::DroneEstimator without a bag or the replay: one simulated drone of
// indoor_3uav feeds the component with its IMU and LiDAR through
// driver::DroneDriver, and a teammate's broadcasts are made from the
// simulator's truth (its state in its own G_j, stamps in the observer's
// clock, 20 ms latency, every scan; each with the teammate's observation of
// the observer, 2 cm noise). The component must identify the teammate, add
// its T_Gi_Gj block, fuse active and passive observations, estimate T_Gi_Gj
// to a few centimetres, keep the ego estimate accurate, and drop the block
// when the teammate reboots (new session). Plus the input checks, which call
// the component's own entry (DroneEstimator::Add, PopMessages) without a
// driver. The byte budget's test is in broadcast_budget_test.cc, the restart
// chain's in drone_estimator_graph_test.cc; the drone and the teammate's
// broadcasts are observer_run.h's.
#include "swarmlio/swarm/drone_estimator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <cstdio>
#include <deque>
#include <random>
#include <string>
#include <variant>
#include <vector>

#include "observer_run.h"

namespace swarmlio::swarm {
namespace {

using test_support::IndoorScenario;
using test_support::ObserverRun;
using test_support::ObserverSink;
using test_support::OptionsFor;
using test_support::ToIsometry;

TEST(DroneEstimator, RejectsInvalidOptionsAndIds) {
  sim::Scenario scenario = IndoorScenario();
  ASSERT_FALSE(scenario.drones.empty());
  const sim::DroneConfig& d = scenario.drones[0];
  std::unique_ptr<DroneEstimator> e;
  DroneEstimatorOptions o = OptionsFor(d);
  EXPECT_EQ(DroneEstimator::Create(-1, o, sim::GivenLidarOptions(d), &e).code(),
            Status::Code::kInvalidArgument);
  o.swarm.max_message_age_s = -1.0;
  const Status status = DroneEstimator::Create(0, o, sim::GivenLidarOptions(d), &e);
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(status.message().find("swarm.max_message_age_s"), std::string::npos)
      << status.message();
}

// The component's own entry, DroneEstimator::Add, on purpose (no driver):
// its answer to each bad message.
TEST(DroneEstimator, IgnoresOwnForeignTypedAndNonFiniteMessages) {
  sim::Scenario scenario = IndoorScenario();
  ASSERT_FALSE(scenario.drones.empty());
  const sim::DroneConfig& d = scenario.drones[0];
  std::unique_ptr<DroneEstimator> e;
  ASSERT_TRUE(DroneEstimator::Create(0, OptionsFor(d), sim::GivenLidarOptions(d), &e).ok());
  net::ReceivedMessage own;
  net::EgoStateMessage m;
  m.sender_id = 0;
  own.message = m;
  EXPECT_TRUE(e->Add(own).ok());
  net::ReceivedMessage nan;
  m.sender_id = 1;
  m.p_bj_in_Gj.x() = std::nan("");
  nan.message = m;
  EXPECT_TRUE(e->Add(nan).ok());
  net::ReceivedMessage sync;
  sync.message = net::TimeSyncMessage();
  EXPECT_TRUE(e->Add(sync).ok());
  EXPECT_EQ(e->counters().messages_received, 3);
  EXPECT_EQ(e->counters().messages_ignored, 3);
}

// A teammate's states wait for its clock offset; with exchange = requests the
// TimeSync requests and answers leave with the send time (the newest sensor
// stamp). (The default state echo is tested end to end: SwarmClockTest.)
// The component's own entry, DroneEstimator::Add and PopMessages, on purpose
// (no driver): the test is of what PopMessages hands out and when.
TEST(DroneEstimator, SynchronizesTeammateClocksBeforeUsingTheirStamps) {
  sim::Scenario scenario = IndoorScenario();
  ASSERT_FALSE(scenario.drones.empty());
  const sim::DroneConfig& d = scenario.drones[0];
  DroneEstimatorOptions o = OptionsFor(d);
  o.swarm.synchronize_clocks = true;
  o.swarm.clock_sync.exchange = net::ClockExchange::kRequests;
  std::unique_ptr<DroneEstimator> e;
  ASSERT_TRUE(DroneEstimator::Create(0, o, sim::GivenLidarOptions(d), &e).ok());
  const int64_t t0 = 1'000'000'000'000;  // 1000 s on the own clock
  const int64_t offset = 500'000'000;    // the teammate's clock is 0.5 s ahead
  ImuSample imu;
  imu.stamp_ns = t0;
  imu.linear_acceleration = Eigen::Vector3d(0, 0, 9.81);
  ASSERT_TRUE(e->Add(imu).ok());

  net::EgoStateMessage state;
  state.sender_id = 1;
  state.stamp_ns = t0 + offset;
  net::ReceivedMessage received;
  received.arrival_ns = t0;
  received.message = state;
  ASSERT_TRUE(e->Add(received).ok());
  EXPECT_EQ(e->counters().messages_unsynchronized, 1);

  std::vector<net::SwarmMessage> out;
  e->PopMessages(&out);
  ASSERT_EQ(out.size(), 1u);
  const auto* request = std::get_if<net::TimeSyncMessage>(&out[0]);
  ASSERT_NE(request, nullptr);
  EXPECT_FALSE(request->is_response);
  EXPECT_EQ(request->target_id, 1);
  EXPECT_EQ(request->t1_ns, t0);

  // The teammate answers after 1 ms each way and 0.1 ms of turnaround.
  net::TimeSyncMessage response = *request;
  response.sender_id = 1;
  response.target_id = 0;
  response.is_response = true;
  response.t2_ns = request->t1_ns + 1'000'000 + offset;
  response.t3_ns = response.t2_ns + 100'000;
  received.arrival_ns = t0 + 2'100'000;
  received.message = response;
  ASSERT_TRUE(e->Add(received).ok());
  ASSERT_NE(e->clock_sync(), nullptr);
  const net::ClockOffsetEstimate estimate = e->clock_sync()->Estimate(1, t0);
  ASSERT_TRUE(estimate.valid);
  EXPECT_EQ(estimate.offset_ns, offset);

  // Now the state is used (its stamp mapped onto the own clock).
  state.stamp_ns = t0 + offset + 100'000'000;
  received.arrival_ns = t0 + 100'000'000;
  received.message = state;
  ASSERT_TRUE(e->Add(received).ok());
  EXPECT_EQ(e->counters().messages_unsynchronized, 1);

  // A request from the teammate is answered when the messages are taken:
  // t2 = its arrival, t3 = the newest sensor stamp.
  net::TimeSyncMessage theirs;
  theirs.sender_id = 1;
  theirs.target_id = 0;
  theirs.t1_ns = t0 + offset + 200'000'000;
  received.arrival_ns = t0 + 201'000'000;
  received.message = theirs;
  ASSERT_TRUE(e->Add(received).ok());
  imu.stamp_ns = t0 + 205'000'000;
  ASSERT_TRUE(e->Add(imu).ok());
  out.clear();
  e->PopMessages(&out);
  const net::TimeSyncMessage* reply = nullptr;
  for (const net::SwarmMessage& m : out) {
    const auto* t = std::get_if<net::TimeSyncMessage>(&m);
    if (t != nullptr && t->is_response) reply = t;
  }
  ASSERT_NE(reply, nullptr);
  EXPECT_EQ(reply->target_id, 1);
  EXPECT_EQ(reply->t1_ns, theirs.t1_ns);
  EXPECT_EQ(reply->t2_ns, t0 + 201'000'000);
  EXPECT_EQ(reply->t3_ns, t0 + 205'000'000);
}

TEST(DroneEstimator, IdentifiesATeammateFusesItsObservationsAndDropsItOnReboot) {
  sim::Scenario scenario = IndoorScenario();
  ASSERT_FALSE(scenario.drones.empty());
  const int observer = 0, teammate = 1;  // two Mid-360 drones
  ObserverRun run(std::move(scenario), 22.0, observer, teammate);  // identification ~14 s
  ObserverSink& sink = *run.sink;
  const sim::Simulator& simulator = *run.simulator;
  sink.restart_at_s = 21.0;
  sink.indefinite_every_k = 7;  // bad covariances must be absorbed, not crash or poison P
  ASSERT_TRUE(run.Run());
  const DroneEstimator& estimator = run.estimator();

  ASSERT_GE(sink.outputs.size(), 180u);
  EXPECT_EQ(sink.ego_states_sent, static_cast<int>(sink.outputs.size()));
  int identified_at = -1, removed_at = -1, active = 0, passive = 0;
  for (size_t k = 0; k < sink.outputs.size(); ++k) {
    const DroneOutput& o = sink.outputs[k];
    ASSERT_TRUE(o.ego.state.p_b_in_G.allFinite());
    for (const IdentificationEvent& e : o.identifications) {
      EXPECT_EQ(e.drone_id, teammate);
      if (identified_at < 0) identified_at = static_cast<int>(k);
    }
    if (!o.removed_teammates.empty() && removed_at < 0) removed_at = static_cast<int>(k);
    active += o.active_observations;
    passive += o.passive_observations;
  }
  ASSERT_GE(identified_at, 0) << "teammate never identified";
  EXPECT_GT(active, 20);
  EXPECT_GT(passive, 20);
  // The reboot at 21 s (new session_start) removes the block within a scan
  // or two of the first new message; the state is ego-only again.
  ASSERT_GT(removed_at, identified_at) << "restarted teammate not removed";
  // Broadcast right after the identification, then every second until the reboot.
  EXPECT_GE(sink.extrinsic_messages_sent, (removed_at - identified_at) / 10);
  EXPECT_LE(sink.extrinsic_messages_sent, (removed_at - identified_at) / 10 + 2);
  EXPECT_EQ(estimator.counters().teammate_restarts, 1);
  // The component's own test: its odometry's state layout (no driver reads it).
  EXPECT_TRUE(estimator.odometry().state().layout().teammate_ids().empty());
  EXPECT_NEAR(ToSeconds(sink.outputs[static_cast<size_t>(removed_at)].ego.stamp_ns) -
                  ToSeconds(sink.outputs.front().ego.stamp_ns),
              21.0 - ToSeconds(sink.outputs.front().ego.stamp_ns - simulator.StampNs(observer, 0.0)),
              0.25);

  // T_Gi_Gj just before the reboot against the truth.
  const DroneOutput& last = sink.outputs[static_cast<size_t>(removed_at) - 1];
  ASSERT_EQ(last.teammates.size(), 1u);
  const Eigen::Isometry3d T_true =
      ToIsometry(simulator.T_W_G(observer)).inverse() * ToIsometry(simulator.T_W_G(teammate));
  const double p_err = (last.teammates[0].T_Gi_Gj.p_Gb_in_Ga - T_true.translation()).norm();
  const double r_err =
      Eigen::AngleAxisd(T_true.linear().transpose() * last.teammates[0].T_Gi_Gj.R_Ga_Gb()).angle() *
      180.0 / M_PI;
  const Eigen::Vector3d sigma = last.teammates[0].extrinsic_covariance.diagonal().tail<3>().cwiseSqrt();
  std::printf("[ figures  ] identified at scan %d, removed at scan %d, %d active / %d passive "
              "fused, T_Gi_Gj error %.4f m %.3f deg (1-sigma %.4f %.4f %.4f m)\n",
              identified_at, removed_at, active, passive, p_err, r_err, sigma.x(), sigma.y(),
              sigma.z());
  // Measured 0.0105 m / 0.348 deg (Release, the given calibration).
  EXPECT_LT(p_err, 0.03);
  EXPECT_LT(r_err, 1.0);
  // The reported uncertainty is neither absurdly small nor large.
  EXPECT_LT(sigma.maxCoeff(), 0.05);
  EXPECT_GT(sigma.minCoeff(), 1e-4);
  // Teammate points stayed out of the map in some scans.
  int excluded = 0;
  for (const DroneOutput& o : sink.outputs) excluded += o.ego.num_excluded_points;
  EXPECT_GT(excluded, 0);
  // Ego accuracy (same frame, no alignment).
  double se = 0.0;
  int n = 0;
  for (const DroneOutput& o : sink.outputs) {
    for (const PoseStamped& g : sink.ground_truth) {
      if (std::abs(g.stamp_ns - o.ego.stamp_ns) < 2'000'000) {
        se += (o.ego.state.p_b_in_G - g.p_b_in_G).squaredNorm();
        ++n;
        break;
      }
    }
  }
  ASSERT_GT(n, 100);
  std::printf("[ figures  ] ego position RMSE %.4f m\n", std::sqrt(se / n));
  EXPECT_LT(std::sqrt(se / n), 0.012);  // measured 0.0044 m
}

// The teammate identified this drone first and sends T_Gj_Gi: the component
// adds the teammate with the inverse (mutual identification) before its own
// trajectory match would (~14 s), and tracks and fuses it from then on.
TEST(DroneEstimator, AddsATeammateThatIdentifiedItFromItsExtrinsic) {
  sim::Scenario scenario = IndoorScenario();
  ASSERT_FALSE(scenario.drones.empty());
  const int observer = 0, teammate = 1;
  ObserverRun run(std::move(scenario), 13.0, observer, teammate);
  ObserverSink& sink = *run.sink;
  const sim::Simulator& simulator = *run.simulator;
  sink.mutual_at_s = 10.0;
  ASSERT_TRUE(run.Run());

  std::string method;
  double identified_s = -1.0;
  int active = 0;
  for (const DroneOutput& o : sink.outputs) {
    for (const IdentificationEvent& e : o.identifications) {
      if (identified_s < 0.0) {
        identified_s = ToSeconds(e.stamp_ns) - ToSeconds(simulator.StampNs(observer, 0.0));
        method = e.method;
      }
    }
    active += o.active_observations;
  }
  ASSERT_GE(identified_s, 0.0) << "never identified";
  EXPECT_EQ(method, "teammate_match");
  EXPECT_NEAR(identified_s, 10.0, 0.3);
  EXPECT_GT(active, 5);  // the tracker started at the broadcast position finds the clusters
  // The teammate's gravity (with every GlobalExtrinsic, 10 Hz here) is fused
  // once per message, and only once the block exists (from 10 s on).
  int gravity = 0;
  for (const DroneOutput& o : sink.outputs) gravity += o.gravity_alignments;
  EXPECT_EQ(gravity, run.estimator().counters().gravity_fused);
  EXPECT_GT(gravity, 20);
  EXPECT_LE(gravity, sink.gravity_messages_delivered);
  const DroneOutput& last = sink.outputs.back();
  ASSERT_EQ(last.teammates.size(), 1u);
  const Eigen::Isometry3d T_true =
      ToIsometry(simulator.T_W_G(observer)).inverse() * ToIsometry(simulator.T_W_G(teammate));
  const double p_err = (last.teammates[0].T_Gi_Gj.p_Gb_in_Ga - T_true.translation()).norm();
  std::printf("[ figures  ] identified at %.2f s, T_Gi_Gj error at the end %.4f m\n", identified_s,
              p_err);
  EXPECT_LT(p_err, 0.015);  // measured 0.0058 m
  EXPECT_EQ(run.estimator().counters().extrinsics_stale, 0);
}

// After a restart, teammates still broadcast their T_Gj_Gi of the previous
// session for a moment: an entry naming this drone that was made before its
// session began (by max_message_age_s) is not a mutual identification.
// The component's own entry, DroneEstimator::Add, on purpose (no driver): the
// counter after each message.
TEST(DroneEstimator, IgnoresTeammatesExtrinsicsOfItsPreviousSession) {
  sim::Scenario scenario = IndoorScenario();
  const sim::DroneConfig& d = scenario.drones[0];
  DroneEstimatorOptions o = OptionsFor(d);
  o.swarm.synchronize_clocks = false;  // stamps taken as own-clock stamps
  std::unique_ptr<DroneEstimator> e;
  ASSERT_TRUE(DroneEstimator::Create(0, o, sim::GivenLidarOptions(d), &e).ok());
  const int64_t t0 = 1'000'000'000'000;
  ImuSample imu;
  imu.linear_acceleration = Eigen::Vector3d(0, 0, 9.81);
  for (int k = 0; k < 400 && !e->initialized(); ++k) {
    imu.stamp_ns = t0 + k * 5'000'000;
    ASSERT_TRUE(e->Add(imu).ok());
  }
  ASSERT_TRUE(e->initialized());
  const int64_t session_ns = e->initialization().stamp_ns;
  net::GlobalExtrinsicMessage g;
  g.sender_id = 1;
  net::GlobalExtrinsicEntry entry;
  entry.teammate_id = 0;
  entry.covariance = 1e-4 * Eigen::Matrix<double, 6, 6>::Identity();
  g.entries.push_back(entry);
  net::ReceivedMessage received;
  received.arrival_ns = session_ns + 100'000'000;
  g.stamp_ns = session_ns + 100'000'000;  // within max_message_age_s of the session start
  received.message = g;
  ASSERT_TRUE(e->Add(received).ok());
  EXPECT_EQ(e->counters().extrinsics_stale, 1);
  g.stamp_ns = session_ns + 600'000'000;  // after it: this session's
  received.arrival_ns = g.stamp_ns;
  received.message = g;
  ASSERT_TRUE(e->Add(received).ok());
  EXPECT_EQ(e->counters().extrinsics_stale, 1);
}

// Identification through teammates: teammate 1 identifies the observer (its
// T_G1_G0) and drone 2 (its own match T_G1_G2) from 10 s on; drone 2 never
// sends anything and the observer never matches it. The observer adds 1 by
// the mutual identification and 2 through 1 in the same scan, with
// T_G0_G2 = T_G0_G1 T_G1_G2 near the truth, a covariance at least the
// composed one, and broadcasts it as derived (kGraph), never as its own match.
TEST(DroneEstimator, AddsATeammateThroughAnIdentifiedTeammate) {
  sim::Scenario scenario = IndoorScenario();
  ASSERT_GE(scenario.drones.size(), 3u);
  const int observer = 0, teammate = 1, relayed = 2;
  ObserverRun run(std::move(scenario), 12.0, observer, teammate);
  ObserverSink& sink = *run.sink;
  const sim::Simulator& simulator = *run.simulator;
  sink.mutual_at_s = 10.0;
  sink.relayed_id = relayed;
  ASSERT_TRUE(run.Run());

  int64_t mutual_ns = -1, graph_ns = -1;
  int via = -1;
  for (const DroneOutput& o : sink.outputs) {
    for (const IdentificationEvent& e : o.identifications) {
      if (e.drone_id == teammate && e.method == "teammate_match") mutual_ns = e.stamp_ns;
      if (e.drone_id == relayed) {
        EXPECT_EQ(e.method, "graph");
        graph_ns = e.stamp_ns;
        via = e.via_drone_id;
      }
    }
  }
  ASSERT_GE(mutual_ns, 0);
  ASSERT_GE(graph_ns, 0) << "drone 2 never added";
  EXPECT_EQ(graph_ns, mutual_ns);
  EXPECT_EQ(via, teammate);
  EXPECT_GT(sink.graph_entries_sent, 0);
  const DroneOutput& last = sink.outputs.back();
  ASSERT_EQ(last.teammates.size(), 2u);
  for (const TeammateEstimate& t : last.teammates) {
    SCOPED_TRACE(t.drone_id);
    const Eigen::Isometry3d T_true = ToIsometry(simulator.T_W_G(observer)).inverse() *
                                     ToIsometry(simulator.T_W_G(t.drone_id));
    const double p_err = (t.T_Gi_Gj.p_Gb_in_Ga - T_true.translation()).norm();
    const double angle =
        Eigen::AngleAxisd(t.T_Gi_Gj.R_Ga_Gb().transpose() * T_true.linear()).angle();
    std::printf("[ figures  ] T_G%d_G%d error at the end %.4f m %.3f deg\n", observer, t.drone_id,
                p_err, angle * 180.0 / M_PI);
    // Measured 0.0053 m / 0.161 deg (T_G0_G1), 0.0241 m / 0.197 deg (T_G0_G2).
    EXPECT_LT(p_err, 0.06);
    EXPECT_LT(angle, 0.5 * M_PI / 180.0);
    // At least the relayed entry's own uncertainty (1 cm): composing cannot
    // make it more certain than its parts.
    if (t.drone_id == relayed) {
      EXPECT_GT(t.extrinsic_covariance(3, 3), 0.9e-4);
    }
  }
}

}  // namespace
}  // namespace swarmlio::swarm
