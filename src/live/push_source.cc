// PushSource: pushed IMU samples and scans released in stamp order, or IMU
// first (push_source.h).
#include "swarmlio/live/push_source.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

namespace swarmlio::live {
namespace {

// Longest real-time wait between re-checks of the (injected) clock [ns].
constexpr int64_t kMaxCondWaitNs = 2'000'000;

}  // namespace

Status PushSource::Create(const PushSourceOptions& options, const Clock* clock,
                          std::unique_ptr<PushSource>* source) {
  if (const std::string invalid = options.Validate(); !invalid.empty()) {
    return Status::InvalidArgument("push source options: " + invalid);
  }
  if (clock == nullptr) return Status::InvalidArgument("push source needs a clock");
  std::unique_ptr<PushSource> s(new PushSource());
  s->options_ = options;
  s->clock_ = clock;
  s->max_wait_ns_ = static_cast<int64_t>(std::llround(options.max_wait_ms * 1e6));
  *source = std::move(s);
  return Status::Ok();
}

PushSource::~PushSource() = default;

void PushSource::PushImu(const ImuSample& imu) {
  Push(kImu, imu.stamp_ns, imu.stamp_ns, io::BagRecord{imu});
}

void PushSource::PushScan(LidarScan scan) {
  const int64_t stamp_ns = scan.stamp_ns;
  // The next scan starts after this one ends (an overlapping one is dropped
  // by the odometry, offline as live): the stream has passed the scan end.
  double span_s = 0.0;
  for (const LidarPoint& p : scan.points) span_s = std::max(span_s, p.offset_time_s);
  const int64_t end_ns = stamp_ns + static_cast<int64_t>(std::llround(span_s * 1e9));
  Push(kLidar, stamp_ns, end_ns, io::BagRecord{std::move(scan)});
}

void PushSource::Push(Stream stream, int64_t stamp_ns, int64_t passed_ns, io::BagRecord record) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (closed_ || interrupted_) return;
  if (stream == kImu) {
    ++stats_.imu_pushed;
  } else {
    ++stats_.scans_pushed;
  }
  if (stream == kImu && buffer_.size() >= static_cast<size_t>(options_.max_buffered_records)) {
    ++stats_.imu_push_waits;
    changed_.wait(lock, [&] {
      return closed_ || interrupted_ ||
             buffer_.size() < static_cast<size_t>(options_.max_buffered_records);
    });
    if (closed_ || interrupted_) return;
  }
  // After the wait: a full buffer may have released later records meanwhile.
  if (Late(Key{stamp_ns, static_cast<int>(stream), 0})) {
    ++(stream == kImu ? stats_.imu_late : stats_.scans_late);
    return;
  }
  if (stream == kLidar && buffered_scans_ >= options_.max_buffered_scans) {
    ++stats_.scans_dropped_full;
    return;
  }
  if (stream == kLidar) ++buffered_scans_;
  has_pushed_[stream] = true;
  passed_ns_[stream] = std::max(passed_ns_[stream], passed_ns);
  Entry entry;
  entry.record = std::move(record);
  entry.push_clock_ns = clock_->NowNs();  // the bounded wait starts now
  buffer_.emplace(Key{stamp_ns, static_cast<int>(stream), next_seq_++}, std::move(entry));
  lock.unlock();
  changed_.notify_all();
}

void PushSource::Close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

void PushSource::Interrupt() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    interrupted_ = true;
  }
  changed_.notify_all();
}

PushSourceStats PushSource::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

bool PushSource::Late(const Key& key) const {
  const int stream = std::get<1>(key);
  if (options_.ordering == PushOrdering::kImuFirst) {
    // IMU samples run ahead of the scans: only its own stream's order counts.
    return has_released_stream_[stream] && std::get<0>(key) < last_released_ns_[stream];
  }
  return has_released_ && std::make_tuple(std::get<0>(key), stream) <
                              std::make_tuple(std::get<0>(last_released_), std::get<1>(last_released_));
}

bool PushSource::ReleasedOnArrival(const Key& key) const {
  return options_.ordering == PushOrdering::kImuFirst && std::get<1>(key) == kImu;
}

bool PushSource::Releasable(int64_t now_ns) const {
  if (buffer_.empty()) return false;
  if (closed_ || buffer_.size() >= static_cast<size_t>(options_.max_buffered_records)) return true;
  // The first record only: in kImuFirst a scan at the front has no IMU
  // sample behind it (a buffered sample stamped at or after the scan would
  // have passed it), so it holds back nothing that could go.
  const auto& [key, entry] = *buffer_.begin();
  return ReleasedOnArrival(key) || OthersPassed(key) ||
         now_ns - entry.push_clock_ns >= max_wait_ns_;
}

bool PushSource::OthersPassed(const Key& key) const {
  for (int s = 0; s < kNumStreams; ++s) {
    if (s == std::get<1>(key)) continue;
    if (!has_pushed_[s] || passed_ns_[s] < std::get<0>(key)) return false;
  }
  return true;
}

bool PushSource::WaitReleasable(std::unique_lock<std::mutex>* lock) {
  while (true) {
    if (interrupted_) return false;
    if (buffer_.empty() && closed_) return false;
    const int64_t now_ns = clock_->NowNs();
    if (Releasable(now_ns)) return true;
    int64_t wait_ns = kMaxCondWaitNs;
    if (!buffer_.empty()) {
      const int64_t deadline_ns = buffer_.begin()->second.push_clock_ns + max_wait_ns_;
      wait_ns = std::clamp<int64_t>(deadline_ns - now_ns, 1, kMaxCondWaitNs);
    }
    changed_.wait_for(*lock, std::chrono::nanoseconds(wait_ns));
  }
}

Status PushSource::Start(SourceStart* start, bool* has_record) {
  std::unique_lock<std::mutex> lock(mutex_);
  *has_record = WaitReleasable(&lock);
  if (*has_record) {
    start->sensor_ns = std::get<0>(buffer_.begin()->first);
    start->clock_ns = buffer_.begin()->second.push_clock_ns;
  }
  return Status::Ok();
}

Status PushSource::Next(const SensorTimeMapping& /*mapping*/, io::BagRecord* record,
                        bool* has_record) {
  std::unique_lock<std::mutex> lock(mutex_);
  *has_record = WaitReleasable(&lock);
  if (!*has_record) return Status::Ok();
  auto node = buffer_.extract(buffer_.begin());
  const Key& key = node.key();
  if (!ReleasedOnArrival(key) && !OthersPassed(key) && !closed_) ++stats_.released_by_timeout;
  const int stream = std::get<1>(key);
  if (stream == kLidar) --buffered_scans_;
  has_released_ = true;
  last_released_ = key;
  has_released_stream_[stream] = true;
  last_released_ns_[stream] = std::get<0>(key);
  ++stats_.released;
  *record = std::move(node.mapped().record);
  lock.unlock();
  changed_.notify_all();
  return Status::Ok();
}

}  // namespace swarmlio::live
