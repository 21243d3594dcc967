#include "swarmlio/replay/drone_runner.h"

#include <utility>

namespace swarmlio::replay {

Status DroneRunner::Create(const DroneInput& input, std::unique_ptr<DroneRunner>* runner) {
  std::unique_ptr<DroneRunner> r(new DroneRunner());
  r->input_ = input;
  Status status = io::BagReader::Open(input.bag_path, input.bag, &r->reader_);
  if (!status.ok()) return status.WithContext(input.name);
  status = lio::Odometry::Create(input.odometry, input.lidar, &r->odometry_);
  if (!status.ok()) return status.WithContext(input.name);
  status = r->ReadNext();
  if (!status.ok()) return status.WithContext(input.name);
  *runner = std::move(r);
  return Status::Ok();
}

ScanRecord ToScanRecord(const lio::ScanOutput& o) {
  ScanRecord r;
  r.stamp_ns = o.stamp_ns;
  r.state = o.state;
  r.pose_covariance = o.covariance.topLeftCorner<6, 6>();
  r.velocity_covariance = o.covariance.block<3, 3>(ErrorStateLayout::kVelocity.offset,
                                                   ErrorStateLayout::kVelocity.offset);
  r.updated = o.updated;
  r.num_raw_points = o.num_raw_points;
  r.num_points = o.num_points;
  r.num_correspondences = o.num_correspondences;
  r.iterations = o.iterations;
  r.min_normal_information = o.min_normal_information;
  r.degenerate = o.degenerate;
  r.map_size = o.map_size;
  r.timings = o.timings;
  return r;
}

int64_t DroneRunner::next_stamp_ns() const { return next_.stamp_ns(); }

Status DroneRunner::ReadNext() {
  return reader_->Next(&next_, &has_next_);
}

void DroneRunner::Warn(const Status& status) {
  if (status.ok()) return;
  if (warnings_.count == 0) warnings_.first = status.message();
  ++warnings_.count;
}

Status DroneRunner::Step() {
  if (!has_next_) return Status::OutOfRange(input_.name + ": no record left");
  if (const ImuSample* imu = next_.imu()) {
    Warn(odometry_->AddImu(*imu));
  } else if (const LidarScan* scan = next_.scan()) {
    Warn(odometry_->AddScan(*scan));
  } else if (const PoseStamped* pose = next_.ground_truth()) {
    ground_truth_.push_back(*pose);
  }
  Collect();
  const Status status = ReadNext();
  return status.ok() ? status : status.WithContext(input_.name);
}

Status DroneRunner::Finish() {
  Warn(odometry_->Flush());
  Collect();
  return Status::Ok();
}

void DroneRunner::Collect() {
  outputs_.clear();
  odometry_->PopOutputs(&outputs_);
  for (const lio::ScanOutput& o : outputs_) {
    scans_.push_back(ToScanRecord(o));
    if (!o.update_error.empty()) Warn(Status::Internal("update failed: " + o.update_error));
  }
}

}  // namespace swarmlio::replay
