#include "swarmlio/driver/drone_driver.h"

#include <utility>

namespace swarmlio::driver {

swarm::DroneEstimatorOptions EstimatorOptionsFor(const DroneInput& drone,
                                                 lio::InitializationMode initialization) {
  swarm::DroneEstimatorOptions options;
  options.odometry = drone.odometry;
  options.odometry.initialization = initialization;
  options.teammate = drone.teammate;
  options.swarm = drone.swarm;
  options.airframe = drone.airframe;
  return options;
}

DroneDriver::DroneDriver(const DroneInput& drone, int drone_id, DriverSink* sink)
    : drone_(drone), drone_id_(drone_id), sink_(sink) {}

Status DroneDriver::Create(const DroneInput& drone,
                           int drone_id,
                           DriverSink* sink,
                           std::unique_ptr<DroneDriver>* driver) {
  if (sink == nullptr) return Status::InvalidArgument(drone.name + ": DroneDriver needs a sink");
  std::unique_ptr<DroneDriver> d(new DroneDriver(drone, drone_id, sink));
  const Status status = d->Restart(drone.odometry.initialization);
  if (!status.ok()) return status.WithContext(drone.name);
  *driver = std::move(d);
  return Status::Ok();
}

Status DroneDriver::Restart(lio::InitializationMode initialization) {
  SWARMLIO_RETURN_IF_ERROR(swarm::DroneEstimator::Create(
      drone_id_, EstimatorOptionsFor(drone_, initialization), drone_.lidar, &estimator_));
  estimator_->SetFusion(fuse_);
  return Status::Ok();
}

void DroneDriver::SetFusion(bool fuse) {
  fuse_ = fuse;
  estimator_->SetFusion(fuse);
}

void DroneDriver::Add(const swarm::SensorRecord& record) {
  Warn(estimator_->Add(record));
  if (std::holds_alternative<net::ReceivedMessage>(record)) return;
  Collect();
  SendMessages();
}

void DroneDriver::SendMessages() {
  messages_.clear();
  estimator_->PopMessages(&messages_);
  sink_->OnMessages(&messages_);
}

void DroneDriver::Finish() {
  Warn(estimator_->Flush());
  Collect();
}

void DroneDriver::Collect() {
  outputs_.clear();
  estimator_->PopOutputs(&outputs_);
  if (outputs_.empty()) return;
  for (const swarm::DroneOutput& o : outputs_) {
    if (!o.ego.update_error.empty()) Warn(Status::Internal("update failed: " + o.ego.update_error));
    if (!o.ego.front_end_error.empty()) {
      Warn(Status::Internal("swarm front end: " + o.ego.front_end_error));
    }
  }
  sink_->OnOutputs(outputs_);
}

void DroneDriver::Warn(const Status& status) {
  if (status.ok()) return;
  if (warnings_.count == 0) warnings_.first = status.message();
  ++warnings_.count;
}

}  // namespace swarmlio::driver
