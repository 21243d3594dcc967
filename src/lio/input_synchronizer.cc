#include "swarmlio/lio/input_synchronizer.h"

#include <string>
#include <utility>

namespace swarmlio::lio {

Status InputSynchronizer::AddImuStamp(int64_t stamp_ns, int64_t raw_stamp_ns) {
  if (have_imu_ && stamp_ns <= newest_imu_ns_) {
    return Status::InvalidArgument("IMU sample at " + std::to_string(raw_stamp_ns) +
                                   " ns is not after the previous one; dropped");
  }
  have_imu_ = true;
  newest_imu_ns_ = stamp_ns;
  return Status::Ok();
}

Status InputSynchronizer::AddScan(PendingScan scan) {
  const int64_t previous_end_ns = queue_.empty() ? processed_end_ns_ : queue_.back().end_ns;
  if ((have_processed_ || !queue_.empty()) && scan.end_ns <= previous_end_ns) {
    return Status::InvalidArgument("scan at " + std::to_string(scan.scan.stamp_ns) +
                                   " ns does not end after the previous scan; dropped");
  }
  queue_.push_back(std::move(scan));
  if (static_cast<int>(queue_.size()) <= max_queued_scans_) return Status::Ok();
  const Status status = Status::OutOfRange(
      "no IMU data for " + std::to_string(max_queued_scans_) + " scans: dropped the scan at " +
      std::to_string(queue_.front().scan.stamp_ns) + " ns");
  queue_.pop_front();
  return status;
}

bool InputSynchronizer::PopReady(bool flush, PendingScan* scan) {
  if (queue_.empty()) return false;
  const bool imu_covers = have_imu_ && newest_imu_ns_ >= queue_.front().end_ns;
  if (!imu_covers && !flush) return false;
  *scan = std::move(queue_.front());
  queue_.pop_front();
  return true;
}

void InputSynchronizer::MarkProcessed(int64_t end_ns) {
  processed_end_ns_ = end_ns;
  have_processed_ = true;
}

void InputSynchronizer::ClearScans() {
  queue_.clear();
  have_processed_ = false;
}

void InputSynchronizer::ReplayScans(const std::vector<PendingScan>& scans) {
  queue_.assign(scans.begin(), scans.end());
  have_processed_ = false;
  processed_end_ns_ = 0;
}

}  // namespace swarmlio::lio
