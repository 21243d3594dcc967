// BagPlaybackSource: the bag released record by record at its time
// (bag_playback_source.h).
#include "swarmlio/live/bag_playback_source.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace swarmlio::live {
namespace {

constexpr int64_t kMaxSleepNs = 5'000'000;  // Interrupt() is noticed within this

}  // namespace

Status BagPlaybackSource::Open(const driver::DroneInput& drone, double start_offset_s,
                               const Clock* clock, std::unique_ptr<BagPlaybackSource>* source) {
  const std::string& name = drone.name;
  if (clock == nullptr) return Status::InvalidArgument(name + ": bag playback needs a clock");
  std::unique_ptr<BagPlaybackSource> s(new BagPlaybackSource());
  s->clock_ = clock;
  s->name_ = name;
  Status status = io::BagReader::Open(drone.bag_path, drone.bag, &s->reader_);
  if (!status.ok()) return status.WithContext(name);
  status = s->reader_->Next(&s->next_, &s->has_next_);
  if (!status.ok()) return status.WithContext(name);
  if (start_offset_s > 0.0 && s->has_next_) {
    // A late join or a restart mid-flight: the playback starts later in the log.
    const int64_t start_ns =
        s->next_.stamp_ns() + static_cast<int64_t>(std::llround(start_offset_s * 1e9));
    while (s->has_next_ && s->next_.stamp_ns() < start_ns) {
      status = s->reader_->Next(&s->next_, &s->has_next_);
      if (!status.ok()) return status.WithContext(name);
    }
    if (!s->has_next_) {
      return Status::InvalidArgument(name + ": start_offset_s " + std::to_string(start_offset_s) +
                                     " s is beyond the end of the log");
    }
  }
  *source = std::move(s);
  return Status::Ok();
}

Status BagPlaybackSource::Start(SourceStart* start, bool* has_record) {
  start->sensor_ns = has_next_ ? next_.stamp_ns() : 0;
  start->clock_ns = clock_->NowNs();
  *has_record = has_next_ && !interrupted_;
  return Status::Ok();
}

Status BagPlaybackSource::Next(const SensorTimeMapping& mapping, io::BagRecord* record,
                               bool* has_record) {
  *has_record = false;
  if (!read_error_.ok()) return read_error_;
  if (!has_next_ || interrupted_) return Status::Ok();
  const int64_t due_ns = mapping.ToClockNs(next_.stamp_ns());
  for (int64_t now = clock_->NowNs(); now < due_ns && !interrupted_; now = clock_->NowNs()) {
    clock_->SleepForNs(std::min(due_ns - now, kMaxSleepNs));
  }
  if (interrupted_) return Status::Ok();
  *record = std::move(next_);
  *has_record = true;
  // A read error ends the playback after this record (reported by the next call).
  const Status status = reader_->Next(&next_, &has_next_);
  if (!status.ok()) {
    has_next_ = false;
    read_error_ = status;
  }
  return Status::Ok();
}

}  // namespace swarmlio::live
