#include "swarmlio/sim/output_writer.h"

#include <cinttypes>
#include <cstdio>

#include "swarmlio/common/check.h"

namespace swarmlio::sim {

io::BagWriterOptions BagOptionsFor(const io::BagWriterOptions& base, const LidarOptions& lidar) {
  io::BagWriterOptions options = base;
  options.lidar_format = lidar.message_format;
  options.point_time_unit = lidar.timestamp_unit;
  return options;
}

Status DroneOutputWriter::Open(const std::string& bag_path, const std::string& tum_path,
                               const io::BagWriterOptions& options,
                               std::unique_ptr<DroneOutputWriter>* writer) {
  std::unique_ptr<DroneOutputWriter> w(new DroneOutputWriter());
  SWARMLIO_RETURN_IF_ERROR(io::BagWriter::Open(bag_path, options, &w->bag_));
  w->tum_path_ = tum_path;
  w->tum_.open(tum_path, std::ios::out | std::ios::trunc);
  if (!w->tum_) return Status::IoError(tum_path + ": cannot open for writing");
  *writer = std::move(w);
  return Status::Ok();
}

Status DroneOutputWriter::OnImu(const ImuSample& imu) { return bag_->WriteImu(imu); }

Status DroneOutputWriter::OnScan(const LidarScan& scan, int64_t record_time_ns) {
  return bag_->WriteScan(scan, record_time_ns);
}

Status DroneOutputWriter::OnGroundTruth(const PoseStamped& pose) {
  SWARMLIO_RETURN_IF_ERROR(bag_->WriteGroundTruth(pose));
  char line[256];
  const Eigen::Quaterniond& q = pose.q_G_b;
  std::snprintf(line, sizeof(line), "%" PRId64 ".%09" PRId64 " %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n",
                pose.stamp_ns / 1000000000, pose.stamp_ns % 1000000000, pose.p_b_in_G.x(),
                pose.p_b_in_G.y(), pose.p_b_in_G.z(), q.x(), q.y(), q.z(), q.w());
  tum_ << line;
  if (!tum_) return Status::IoError(tum_path_ + ": write failed");
  return Status::Ok();
}

Status DroneOutputWriter::Close() {
  tum_.close();
  if (tum_.fail()) return Status::IoError(tum_path_ + ": close failed");
  return bag_->Close();
}

}  // namespace swarmlio::sim
