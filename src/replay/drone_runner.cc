#include "swarmlio/replay/drone_runner.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace swarmlio::replay {

Status DroneRunner::Create(const driver::DroneInput& input, int drone_id,
                           std::unique_ptr<DroneRunner>* runner) {
  std::unique_ptr<DroneRunner> r(new DroneRunner());
  r->input_ = input;
  Status status = io::BagReader::Open(input.bag_path, input.bag, &r->reader_);
  if (!status.ok()) return status.WithContext(input.name);
  SWARMLIO_RETURN_IF_ERROR(driver::DroneDriver::Create(input, drone_id, r.get(), &r->driver_));
  status = r->ReadNext();
  if (!status.ok()) return status.WithContext(input.name);
  if (input.restart_at_s > 0.0 && r->has_next_) {
    r->restart_ns_ =
        r->next_.stamp_ns() + static_cast<int64_t>(std::llround(input.restart_at_s * 1e9));
  }
  if (input.start_offset_s > 0.0 && r->has_next_) {
    // A late join or a restart mid-flight: the drone starts later in its log.
    const int64_t start_ns =
        r->next_.stamp_ns() + static_cast<int64_t>(std::llround(input.start_offset_s * 1e9));
    while (r->has_next_ && r->next_.stamp_ns() < start_ns) {
      status = r->ReadNext();
      if (!status.ok()) return status.WithContext(input.name);
    }
    if (!r->has_next_) {
      return Status::InvalidArgument(input.name + ": start_offset_s " +
                                     std::to_string(input.start_offset_s) +
                                     " s is beyond the end of the log");
    }
  }
  *runner = std::move(r);
  return Status::Ok();
}

swarm::DroneOutput KeptOutput(swarm::DroneOutput output) {
  output.ego.registered_in_G = std::vector<Eigen::Vector3d>();
  output.ego.update_error = std::string();
  output.ego.front_end_error = std::string();
  output.identifications = std::vector<swarm::IdentificationEvent>();
  output.removed_teammates = std::vector<int>();
  return output;
}

namespace {

void AppendIfUpdated(const lio::ScanOutput& s, eval::CovariantTrajectory* out) {
  if (!s.updated) return;
  Eigen::Isometry3d T_G_b = Eigen::Isometry3d::Identity();
  T_G_b.linear() = s.state.q_G_b.normalized().toRotationMatrix();
  T_G_b.translation() = s.state.p_b_in_G;
  out->poses.stamps_s.push_back(ToSeconds(s.stamp_ns));
  out->poses.T_G_b.push_back(T_G_b);
  out->position_covariances.push_back(s.position_covariance_in_G);
  out->map_position_covariances.push_back(
      s.covariance.block<3, 3>(ErrorStateLayout::kPosition.offset, ErrorStateLayout::kPosition.offset));
}

}  // namespace

eval::CovariantTrajectory UpdatedEstimate(const std::vector<lio::ScanOutput>& scans) {
  eval::CovariantTrajectory out;
  for (const lio::ScanOutput& s : scans) AppendIfUpdated(s, &out);
  return out;
}

eval::CovariantTrajectory UpdatedEstimate(const std::vector<swarm::DroneOutput>& scans) {
  eval::CovariantTrajectory out;
  for (const swarm::DroneOutput& s : scans) AppendIfUpdated(s.ego, &out);
  return out;
}

void DroneRunner::Deliver(const net::ReceivedMessage& message) { driver_->Add(message); }

void DroneRunner::TakeMessages(std::vector<net::SwarmMessage>* messages) {
  for (net::SwarmMessage& m : outbox_) messages->push_back(std::move(m));
  outbox_.clear();
}

void DroneRunner::SetFusion(bool fuse) { driver_->SetFusion(fuse); }

Status DroneRunner::Restart() {
  restart_ns_ = -1;
  outbox_.clear();
  SWARMLIO_RETURN_IF_ERROR(driver_->Restart(input_.restart_initialization));
  const int64_t back_ns =
      next_.stamp_ns() + static_cast<int64_t>(std::llround(input_.restart_down_s * 1e9));
  while (has_next_ && next_.stamp_ns() < back_ns) SWARMLIO_RETURN_IF_ERROR(ReadNext());
  scans_.clear();
  identifications_.clear();
  return Status::Ok();
}

void DroneRunner::SkipScans(std::vector<int64_t> scan_stamps_ns) {
  std::sort(scan_stamps_ns.begin(), scan_stamps_ns.end());
  skip_scan_stamps_ns_ = std::move(scan_stamps_ns);
}

int64_t DroneRunner::next_stamp_ns() const { return next_.stamp_ns(); }

Status DroneRunner::ReadNext() {
  return reader_->Next(&next_, &has_next_);
}

Status DroneRunner::Step() {
  if (!has_next_) return Status::OutOfRange(input_.name + ": no record left");
  if (restart_ns_ >= 0 && next_.stamp_ns() >= restart_ns_) {
    const Status restarted = Restart();
    // The record after the down time is fed at its own turn.
    return restarted.ok() ? restarted : restarted.WithContext(input_.name);
  }
  if (ImuSample* imu = std::get_if<ImuSample>(&next_.data)) {
    driver_->Add(*imu);
  } else if (LidarScan* scan = std::get_if<LidarScan>(&next_.data)) {
    // The live drone names a dropped scan by its record's stamp.
    if (std::binary_search(skip_scan_stamps_ns_.begin(), skip_scan_stamps_ns_.end(),
                           next_.stamp_ns())) {
      ++skipped_scans_;
      driver_->SendMessages();
    } else {
      driver_->Add(std::move(*scan));  // the record is read anew below
    }
  } else if (const PoseStamped* pose = next_.ground_truth()) {
    ground_truth_.push_back(*pose);
    driver_->SendMessages();
  }
  const Status status = ReadNext();
  return status.ok() ? status : status.WithContext(input_.name);
}

Status DroneRunner::Finish() {
  driver_->Finish();
  return Status::Ok();
}

void DroneRunner::OnOutputs(const std::vector<swarm::DroneOutput>& outputs) {
  for (const swarm::DroneOutput& o : outputs) {
    for (const swarm::IdentificationEvent& e : o.identifications) identifications_.push_back(e);
    scans_.push_back(KeptOutput(o));
  }
}

void DroneRunner::OnMessages(std::vector<net::SwarmMessage>* messages) {
  for (net::SwarmMessage& m : *messages) outbox_.push_back(std::move(m));
}

}  // namespace swarmlio::replay
