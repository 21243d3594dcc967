// SwarmReplay: runs the estimators of N drones in one process on recorded
// time. Records of all bags are consumed in stamp order (ties: lower drone
// index first), so a run is a deterministic function of the logs and options.
// Until the swarm layer exists, drones run independently (the single-agent
// ablation); the inter-drone network plugs into this loop.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/replay/drone_runner.h"
#include "swarmlio/replay/manifest.h"

namespace swarmlio::replay {

struct ReplayProgress {
  int64_t stamp_ns = 0;        // the record just consumed
  int64_t start_stamp_ns = 0;  // earliest bag time over all drones
  int64_t end_stamp_ns = 0;    // latest bag time over all drones
  int64_t records = 0;         // consumed so far
  double Fraction() const;
};

struct ReplayOptions {
  /// Stop after this much log time from the start [s]; 0 = the whole logs.
  double max_duration_s = 0.0;
  /// Called every `progress_every_records` records (tool-side progress bar).
  std::function<void(const ReplayProgress&)> on_progress;
  int64_t progress_every_records = 2000;
};

class SwarmReplay {
 public:
  /// Opens every drone's bag (all of them: every error is reported, joined).
  static Status Create(const SwarmManifest& manifest, std::unique_ptr<SwarmReplay>* replay);

  /// Runs to the end of all logs (or max_duration_s). On a read error the
  /// other drones still run to the end; the first error is returned and the
  /// results so far are kept.
  Status Run(const ReplayOptions& options);

  int num_drones() const { return static_cast<int>(runners_.size()); }
  const DroneRunner& drone(int i) const { return *runners_[i]; }
  const SwarmManifest& manifest() const { return manifest_; }

 private:
  SwarmReplay() = default;

  SwarmManifest manifest_;
  std::vector<std::unique_ptr<DroneRunner>> runners_;
  int64_t start_stamp_ns_ = 0;
  int64_t end_stamp_ns_ = 0;
};

}  // namespace swarmlio::replay
