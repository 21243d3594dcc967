#include "swarmlio/replay/swarm_replay.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "swarmlio/io/bag_info.h"

namespace swarmlio::replay {

double ReplayProgress::Fraction() const {
  if (end_stamp_ns <= start_stamp_ns) return 0.0;
  const double f = static_cast<double>(stamp_ns - start_stamp_ns) /
                   static_cast<double>(end_stamp_ns - start_stamp_ns);
  return std::clamp(f, 0.0, 1.0);
}

Status SwarmReplay::Create(const SwarmManifest& manifest, std::unique_ptr<SwarmReplay>* replay) {
  std::unique_ptr<SwarmReplay> r(new SwarmReplay());
  r->manifest_ = manifest;
  std::string errors;
  r->start_stamp_ns_ = std::numeric_limits<int64_t>::max();
  r->end_stamp_ns_ = std::numeric_limits<int64_t>::min();
  for (const DroneInput& input : manifest.drones) {
    std::unique_ptr<DroneRunner> runner;
    const Status status = DroneRunner::Create(input, &runner);
    if (!status.ok()) {
      errors += (errors.empty() ? "" : "; ") + status.message();
      continue;
    }
    io::BagInfo info;
    if (io::ReadBagInfo(input.bag_path, &info).ok() && info.message_count > 0) {
      r->start_stamp_ns_ = std::min(r->start_stamp_ns_, info.start_time_ns);
      r->end_stamp_ns_ = std::max(r->end_stamp_ns_, info.end_time_ns);
    }
    r->runners_.push_back(std::move(runner));
  }
  if (!errors.empty()) return Status::InvalidArgument(errors);
  if (r->start_stamp_ns_ > r->end_stamp_ns_) r->start_stamp_ns_ = r->end_stamp_ns_ = 0;
  *replay = std::move(r);
  return Status::Ok();
}

Status SwarmReplay::Run(const ReplayOptions& options) {
  Status first_error;
  ReplayProgress progress;
  progress.start_stamp_ns = start_stamp_ns_;
  progress.end_stamp_ns = end_stamp_ns_;
  int64_t limit_ns = std::numeric_limits<int64_t>::max();
  if (options.max_duration_s > 0.0) {
    limit_ns = start_stamp_ns_ + static_cast<int64_t>(std::llround(options.max_duration_s * 1e9));
  }
  std::vector<bool> failed(runners_.size(), false);
  while (true) {
    int best = -1;
    for (size_t i = 0; i < runners_.size(); ++i) {
      if (failed[i] || !runners_[i]->has_next()) continue;
      if (best < 0 || runners_[i]->next_stamp_ns() < runners_[best]->next_stamp_ns()) {
        best = static_cast<int>(i);
      }
    }
    if (best < 0 || runners_[best]->next_stamp_ns() > limit_ns) break;
    progress.stamp_ns = runners_[best]->next_stamp_ns();
    const Status status = runners_[best]->Step();
    if (!status.ok()) {
      failed[best] = true;
      if (first_error.ok()) first_error = status;
    }
    ++progress.records;
    if (options.on_progress && progress.records % options.progress_every_records == 0) {
      options.on_progress(progress);
    }
  }
  for (auto& runner : runners_) {
    const Status status = runner->Finish();
    if (!status.ok() && first_error.ok()) first_error = status;
  }
  if (options.on_progress) {
    progress.stamp_ns = progress.end_stamp_ns;
    options.on_progress(progress);
  }
  return first_error;
}

}  // namespace swarmlio::replay
