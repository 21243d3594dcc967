// DroneDriver: the one loop every driver runs around a drone's component
// (the offline replay's DroneRunner, the live process's LiveDrone and, through
// it, the ROS node; the tests' ObserverRun):
//
//   read record -> Add(record) -> component.Add(record)
//                              -> its outputs, then its messages -> the sink
//
// The driver keeps its own I/O, clocks and threads; the sink is where it
// writes outputs and sends messages. The component's options are built here
// from the drone's configuration (one place), and the data problems the
// component skips (a NaN sample, an out-of-order scan, a failed update) are
// counted as warnings, not errors.
//
// A received message is handed to the component only: what it answers leaves
// with the next sensor record's messages (or at SendMessages()), so an
// offline re-run that delivers the same messages before the same records
// reproduces a live run.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/driver/manifest.h"
#include "swarmlio/net/messages.h"
#include "swarmlio/swarm/drone_estimator.h"
#include "swarmlio/swarm/sensor_record.h"

namespace swarmlio::driver {

/// Data problems the component skipped.
struct DroneWarnings {
  int64_t count = 0;
  std::string first;  // the first warning's message
};

/// Where a driver's outputs go. Called from the thread that calls the
/// DroneDriver, in order.
class DriverSink {
 public:
  virtual ~DriverSink() = default;
  /// The outputs of one record (or of the final flush), one per scan, in order.
  virtual void OnOutputs(const std::vector<swarm::DroneOutput>& outputs) = 0;
  /// The messages to send, produced since the last call (may be moved from).
  virtual void OnMessages(std::vector<net::SwarmMessage>* messages) = 0;
};

/// The component's options for a drone: its odometry, teammate and swarm
/// sections, the odometry starting with `initialization`.
swarm::DroneEstimatorOptions EstimatorOptionsFor(const DroneInput& drone,
                                                 lio::InitializationMode initialization);

class DroneDriver {
 public:
  /// Creates the drone's component (EstimatorOptionsFor) with the drone's
  /// odometry.initialization. `sink` is not owned. Errors name the drone.
  static Status Create(const DroneInput& drone,
                       int drone_id,
                       DriverSink* sink,
                       std::unique_ptr<DroneDriver>* driver);

  /// One record. A sensor record (IMU sample, scan): the component takes it,
  /// then its outputs and its messages go to the sink. A received message:
  /// the component takes it, nothing goes to the sink.
  void Add(const swarm::SensorRecord& record);
  /// The component's messages to the sink (for a record that does not reach
  /// the component: a ground-truth pose, a dropped scan).
  void SendMessages();
  /// End of the input: the component processes the scans still waiting for
  /// IMU data; their outputs go to the sink (the messages at SendMessages()).
  void Finish();
  /// A new session (a restart): a new component, odometry starting with
  /// `initialization`; the fusion switch and the warnings are kept.
  Status Restart(lio::InitializationMode initialization);
  /// Ablation switch: fuse mutual observations (true) or not.
  void SetFusion(bool fuse);

  const DroneWarnings& warnings() const { return warnings_; }
  const swarm::DroneEstimator& estimator() const { return *estimator_; }

 private:
  DroneDriver(const DroneInput& drone, int drone_id, DriverSink* sink);
  void Collect();
  void Warn(const Status& status);

  DroneInput drone_;
  int drone_id_;
  DriverSink* sink_;
  bool fuse_ = true;
  std::unique_ptr<swarm::DroneEstimator> estimator_;
  std::vector<swarm::DroneOutput> outputs_;  // scratch
  std::vector<net::SwarmMessage> messages_;  // scratch
  DroneWarnings warnings_;
};

}  // namespace swarmlio::driver
