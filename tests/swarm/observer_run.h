// Test support for swarm::DroneEstimator without a bag or the replay: one
// simulated drone of indoor_3uav feeds the component with its IMU and LiDAR
// (ObserverRun; the component is given the calibration the simulator reports
// as given, with its error, as swarm.yaml would: GivenDroneInput), and a
// teammate's broadcasts are made from the simulator's truth (ObserverSink:
// its state in its own G_j, stamps in the observer's clock, 20 ms latency,
// every scan; each with the teammate's observation of the observer, 2 cm
// noise). The records, the broadcasts among them, go through
// driver::DroneDriver, the loop the replay and the live process run;
// ObserverSink is its sink. Shared by the tests in tests/swarm/.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "swarmlio/driver/drone_driver.h"
#include "swarmlio/driver/manifest.h"
#include "swarmlio/sim/scenario.h"
#include "swarmlio/sim/simulator.h"
#include "swarmlio/swarm/drone_estimator.h"
#include "test_utils/given_calibration.h"

namespace swarmlio::swarm::test_support {

constexpr double kGravity = 9.81;  // the simulator's default [m/s^2]

inline Eigen::Isometry3d ToIsometry(const sim::Pose& pose) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = pose.R_W_b;
  T.translation() = pose.p_b_in_W;
  return T;
}

inline sim::Scenario IndoorScenario() {
  sim::Scenario scenario;
  const Status status = sim::LoadScenario(
      std::string(SWARMLIO_SOURCE_DIR) + "/configs/scenarios/indoor_3uav.yaml", &scenario);
  EXPECT_TRUE(status.ok()) << status.message();
  return scenario;
}

inline DroneEstimatorOptions OptionsFor(const sim::DroneConfig& d) {
  DroneEstimatorOptions o;
  o.odometry = swarmlio::testing::GivenDroneInput(d).odometry;
  o.airframe = swarmlio::testing::GivenDroneInput(d).airframe;
  // The sinks below hand over the teammate's states stamped on one clock
  // without TimeSync exchanges; clock synchronisation has its own test.
  o.swarm.synchronize_clocks = false;
  return o;
}

// The observer as a driver's drone: its sensors and the component's options
// `o` (driver::EstimatorOptionsFor gives `o` back).
inline driver::DroneInput InputFor(const sim::DroneConfig& d, const DroneEstimatorOptions& o) {
  driver::DroneInput input = swarmlio::testing::GivenDroneInput(d);
  input.odometry = o.odometry;
  input.teammate = o.teammate;
  input.swarm = o.swarm;
  input.airframe = o.airframe;
  return input;
}

// Feeds the observer's sensor data and the teammate's broadcasts in time order
// to the observer's driver, and keeps what the driver hands to its sink.
class ObserverSink : public sim::DroneSink, public driver::DriverSink {
 public:
  ObserverSink(const sim::Simulator& sim, int observer, int teammate)
      : sim_(sim), observer_(observer), teammate_(teammate), rng_(5) {
    const sim::DroneConfig& d = sim.drones()[static_cast<size_t>(teammate)];
    T_Gj_W_ = ToIsometry(sim.T_W_G(teammate)).inverse();
    const double period = 1.0 / d.lidar.sensor.scan_rate_hz;
    for (int k = 1; d.lidar.start_time_s + k * period <= sim.config().duration_s; ++k) {
      broadcast_times_.push_back(d.lidar.start_time_s + k * period);
    }
  }
  // The driver the records go to (created with this sink).
  void set_driver(driver::DroneDriver* driver) { driver_ = driver; }

  // sim::DroneSink: the data problems the component skips are the driver's
  // warnings (ObserverRun::Run).
  Status OnImu(const ImuSample& imu) override {
    Deliver(imu.stamp_ns);
    driver_->Add(imu);
    return Status::Ok();
  }
  Status OnScan(const LidarScan& scan, int64_t record_time_ns) override {
    Deliver(record_time_ns);
    driver_->Add(scan);
    return Status::Ok();
  }
  Status OnGroundTruth(const PoseStamped& pose) override {
    ground_truth.push_back(pose);
    return Status::Ok();
  }

  // driver::DriverSink.
  void OnOutputs(const std::vector<DroneOutput>& out) override {
    outputs.insert(outputs.end(), out.begin(), out.end());
  }
  void OnMessages(std::vector<net::SwarmMessage>* sent) override {
    for (const net::SwarmMessage& m : *sent) {
      if (const auto* e = std::get_if<net::EgoStateMessage>(&m)) {
        ++ego_states_sent;
        observations_sent += static_cast<int>(e->observations.size());
        wire_bytes.emplace_back(
            e->stamp_ns, kIpUdpBytes + net::EgoStatePacketBytes(
                                           e->observations.size(), e->past_observations.size(),
                                           e->echoes.size(), e->offset_report.has_value()));
      }
      if (const auto* a = std::get_if<net::AirframeMessage>(&m)) {
        ++airframe_messages_sent;
        wire_bytes.emplace_back(a->stamp_ns, kIpUdpBytes + net::AirframePacketBytes());
      }
      if (const auto* g = std::get_if<net::GlobalExtrinsicMessage>(&m)) {
        ++extrinsic_messages_sent;
        wire_bytes.emplace_back(g->stamp_ns,
                                kIpUdpBytes + net::GlobalExtrinsicPacketBytes(g->entries.size()));
        for (const net::GlobalExtrinsicEntry& e : g->entries) {
          if (e.teammate_id == teammate_) teammate_entry_stamps.push_back(g->stamp_ns);
          if (e.teammate_id == relayed_id) {
            ++graph_entries_sent;
            EXPECT_EQ(e.source, net::ExtrinsicSource::kGraph);  // never relayed as first-hand
          } else {
            EXPECT_EQ(e.teammate_id, teammate_);
            if (e.source == net::ExtrinsicSource::kGraph) ++teammate_graph_entries_sent;
          }
        }
      }
    }
  }

  std::vector<DroneOutput> outputs;
  std::vector<PoseStamped> ground_truth;
  static constexpr size_t kIpUdpBytes = 28;
  int ego_states_sent = 0;                             // one per scan
  int observations_sent = 0;                           // in the states
  std::vector<std::pair<int64_t, size_t>> wire_bytes;  // (stamp, bytes on the wire) per message
  int extrinsic_messages_sent = 0;  // the own T_Gi_Gj, about once a second once identified
  int airframe_messages_sent = 0;   // the own airframe, every airframe_period_s
  std::vector<int64_t> teammate_entry_stamps;  // broadcasts with the teammate's entry
  double restart_at_s = 1e9;                   // the teammate reboots then (new session_start)
  double mutual_at_s = 1e9;    // from then on the teammate sends its T_Gj_Gi (it identified us)
  // Until then its T_Gj_Gi is off by this yaw about G_j's origin (a wrong
  // first match that its own observations later corrected).
  double mutual_wrong_until_s = -1.0;
  double mutual_wrong_yaw_deg = 0.0;
  int indefinite_every_k = 0;  // every k-th broadcast has indefinite covariances (0: none)
  int gravity_messages_delivered = 0;  // GlobalExtrinsic messages with the teammate's gravity
  int relayed_id = -1;  // with mutual_at_s: the teammate also sends its own match of this drone
  int graph_entries_sent = 0;           // the observer's broadcasts of relayed_id
  int teammate_graph_entries_sent = 0;  // ... of the teammate, as derived
  // The teammate's G after its reboot: restart_shift T_Gj_W (before: T_Gj_W).
  Eigen::Isometry3d restart_shift = Eigen::Isometry3d::Identity();
  // With relayed_id: from then on the relayed drone sends its own match of
  // the teammate (T_Gk_Gj, of the teammate's current G).
  double relayed_match_at_s = 1e9;
  // With relayed_id: the relayed drone, not the teammate, made the first
  // edge: from mutual_at_s on it sends its own derived T_Gk_Gi (kGraph), and
  // the teammate sends no match of it.
  bool relayed_sends_derived = false;

 private:
  // Broadcasts of the teammate that arrived (20 ms after its scan end) by `now_ns`.
  void Deliver(int64_t now_ns) {
    const double latency_s = 0.02;
    while (next_ < broadcast_times_.size() &&
           sim_.StampNs(observer_, broadcast_times_[next_] + latency_s) <= now_ns) {
      const double t = broadcast_times_[next_++];
      const sim::KinematicState s =
          sim_.drones()[static_cast<size_t>(teammate_)].trajectory.StateAt(t);
      // The teammate's G in its current session.
      const Eigen::Isometry3d T_Gj_W = t < restart_at_s ? T_Gj_W_ : restart_shift * T_Gj_W_;
      net::EgoStateMessage m;
      m.sender_id = teammate_;
      m.stamp_ns = sim_.StampNs(observer_, t);  // synchronised clocks
      m.session_start_ns = t < restart_at_s ? 1 : 2;
      m.q_Gj_bj = Eigen::Quaterniond(T_Gj_W.linear() * s.R_W_b).normalized();
      m.p_bj_in_Gj = T_Gj_W * s.p_b_in_W;
      m.v_bj_in_Gj = T_Gj_W.linear() * s.v_b_in_W;
      m.omega_bj_in_bj = s.omega_b;
      m.cov_theta_Gj_bj = 1e-6 * Eigen::Matrix3d::Identity();
      m.cov_p_bj_in_Gj = 1e-5 * Eigen::Matrix3d::Identity();
      m.cov_v_bj_in_Gj = 1e-4 * Eigen::Matrix3d::Identity();
      if (indefinite_every_k > 0 && next_ % static_cast<size_t>(indefinite_every_k) == 0) {
        // Passes the wire checks (finite, variances >= 0) but is indefinite.
        m.cov_p_bj_in_Gj(0, 1) = m.cov_p_bj_in_Gj(1, 0) = 0.5;
        m.cov_theta_Gj_bj(1, 2) = m.cov_theta_Gj_bj(2, 1) = 0.3;
      }
      // The teammate sees the observer when it is within 6 m.
      const sim::Pose bi = sim_.drones()[static_cast<size_t>(observer_)].trajectory.PoseAt(t);
      const Eigen::Vector3d p_bi_in_bj = s.R_W_b.transpose() * (bi.p_b_in_W - s.p_b_in_W);
      if (p_bi_in_bj.norm() < 6.0) {
        net::CurrentObservation o;
        o.observed_id = observer_;
        std::normal_distribution<double> noise(0.0, 0.02);
        o.p_bk_in_bj = p_bi_in_bj + Eigen::Vector3d(noise(rng_), noise(rng_), noise(rng_));
        o.cov_p_bk_in_bj = 4e-4 * Eigen::Matrix3d::Identity();
        m.observations.push_back(o);
      }
      net::ReceivedMessage r;
      r.arrival_ns = sim_.StampNs(observer_, t + latency_s);
      r.message = m;
      driver_->Add(r);
      if (relayed_id >= 0) {
        // The relayed drone broadcasts its state too (no observations).
        const sim::KinematicState sk =
            sim_.drones()[static_cast<size_t>(relayed_id)].trajectory.StateAt(t);
        const Eigen::Isometry3d T_Gk_W = ToIsometry(sim_.T_W_G(relayed_id)).inverse();
        net::EgoStateMessage mk = m;
        mk.sender_id = relayed_id;
        mk.session_start_ns = 1;
        mk.q_Gj_bj = Eigen::Quaterniond(T_Gk_W.linear() * sk.R_W_b).normalized();
        mk.p_bj_in_Gj = T_Gk_W * sk.p_b_in_W;
        mk.v_bj_in_Gj = T_Gk_W.linear() * sk.v_b_in_W;
        mk.omega_bj_in_bj = sk.omega_b;
        mk.observations.clear();
        net::ReceivedMessage rk = r;
        rk.message = mk;
        driver_->Add(rk);
        net::GlobalExtrinsicMessage gk;
        gk.sender_id = relayed_id;
        gk.stamp_ns = m.stamp_ns;
        // Truth, 1 cm / 0.2 deg sigma.
        const auto entry = [](int id, const Eigen::Isometry3d& T, net::ExtrinsicSource source) {
          net::GlobalExtrinsicEntry e;
          e.teammate_id = id;
          e.source = source;
          e.q_Ga_Gb = Eigen::Quaterniond(T.linear()).normalized();
          e.p_Gb_in_Ga = T.translation();
          e.covariance.diagonal() << 1.2e-5, 1.2e-5, 1.2e-5, 1e-4, 1e-4, 1e-4;
          return e;
        };
        if (relayed_sends_derived && t >= mutual_at_s) {
          gk.entries.push_back(entry(observer_, T_Gk_W * ToIsometry(sim_.T_W_G(observer_)),
                                     net::ExtrinsicSource::kGraph));
        }
        if (t >= relayed_match_at_s) {  // its own match of the teammate
          gk.entries.push_back(
              entry(teammate_, T_Gk_W * T_Gj_W.inverse(), net::ExtrinsicSource::kTrajectoryMatch));
        }
        if (!gk.entries.empty()) {
          rk.message = gk;
          driver_->Add(rk);
        }
      }
      // The teammate's new session has not identified the observer.
      if (t >= mutual_at_s && t < restart_at_s) {
        // The teammate's estimate of T_Gj_Gi: the truth, 1 cm / 0.2 deg sigma.
        Eigen::Isometry3d T_Gj_Gi = T_Gj_W_ * ToIsometry(sim_.T_W_G(observer_));
        if (t < mutual_wrong_until_s) {
          T_Gj_Gi = Eigen::Isometry3d(Eigen::AngleAxisd(mutual_wrong_yaw_deg * M_PI / 180.0,
                                                        Eigen::Vector3d::UnitZ())) *
                    T_Gj_Gi;
        }
        net::GlobalExtrinsicMessage g;
        g.sender_id = teammate_;
        g.stamp_ns = m.stamp_ns;
        net::GlobalExtrinsicEntry e;
        e.teammate_id = observer_;
        e.q_Ga_Gb = Eigen::Quaterniond(T_Gj_Gi.linear()).normalized();
        e.p_Gb_in_Ga = T_Gj_Gi.translation();
        e.covariance.diagonal() << 1.2e-5, 1.2e-5, 1.2e-5, 1e-4, 1e-4, 1e-4;
        g.entries.push_back(e);
        if (relayed_id >= 0 && !relayed_sends_derived) {
          // And its own trajectory match of drone k: the truth, same sigma.
          const Eigen::Isometry3d T_Gj_Gk = T_Gj_W_ * ToIsometry(sim_.T_W_G(relayed_id));
          net::GlobalExtrinsicEntry ek = e;
          ek.teammate_id = relayed_id;
          ek.q_Ga_Gb = Eigen::Quaterniond(T_Gj_Gk.linear()).normalized();
          ek.p_Gb_in_Ga = T_Gj_Gk.translation();
          g.entries.push_back(ek);
        }
        // Its gravity in G_j (the simulator's W has z up).
        g.g_in_Gi = T_Gj_W_.linear() * Eigen::Vector3d(0.0, 0.0, -kGravity);
        g.cov_g_in_Gi = 1e-4 * Eigen::Matrix3d::Identity();
        r.message = g;
        driver_->Add(r);
        ++gravity_messages_delivered;
      }
    }
  }

  const sim::Simulator& sim_;
  int observer_, teammate_;
  driver::DroneDriver* driver_ = nullptr;
  Eigen::Isometry3d T_Gj_W_;
  std::vector<double> broadcast_times_;
  size_t next_ = 0;
  std::mt19937 rng_;
};

// The first `duration_s` of indoor_3uav for one observer fed by ObserverSink.
struct ObserverRun {
  ObserverRun(sim::Scenario scenario,
              double duration_s,
              int observer_id,
              int teammate,
              const std::function<void(DroneEstimatorOptions*)>& adjust = {})
      : observer(observer_id) {
    sim::SimulationConfig config = scenario.simulation_config();
    config.duration_s = duration_s;
    config.num_threads = 1;
    drones = scenario.drones;
    simulator = std::make_unique<sim::Simulator>(std::move(scenario.scene), drones,
                                                 scenario.objects, config);
    DroneEstimatorOptions options = OptionsFor(drones[observer]);
    if (adjust) adjust(&options);
    sink = std::make_unique<ObserverSink>(*simulator, observer, teammate);
    const Status created = driver::DroneDriver::Create(InputFor(drones[observer], options),
                                                       observer, sink.get(), &driver);
    EXPECT_TRUE(created.ok()) << created.message();
    sink->set_driver(driver.get());
  }
  // The whole run; false when the simulator fails or the component skipped
  // any input (a data problem, a failed update).
  bool Run() {
    if (driver == nullptr) return false;
    sim::DroneStats stats;
    if (!simulator->RunDrone(observer, sink.get(), &stats).ok()) return false;
    driver->Finish();
    driver->SendMessages();
    EXPECT_EQ(driver->warnings().count, 0) << driver->warnings().first;
    return driver->warnings().count == 0;
  }
  const DroneEstimator& estimator() const { return driver->estimator(); }

  int observer;
  std::vector<sim::DroneConfig> drones;
  std::unique_ptr<sim::Simulator> simulator;
  std::unique_ptr<ObserverSink> sink;
  std::unique_ptr<driver::DroneDriver> driver;  // feeds the component, writes to `sink`
};

}  // namespace swarmlio::swarm::test_support
