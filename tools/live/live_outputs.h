// The files swarmlio_live writes while it runs (a live::LiveSink, streamed:
// nothing per scan is kept but one float of latency):
//   <name>_tum.txt       estimated trajectory, TUM, one pose per scan end
//   <name>_timing.csv    per scan: counts, stage total, latency scan end -> odometry out;
//                        a dropped scan is a row with `dropped` = queue | backlog
//   <name>_imu_odom.csv  the IMU-rate propagated state (one row per IMU sample)
//   <name>_extrinsics.csv  per scan and teammate in the state: T_Gi_Gj, its covariance
//                        diagonal, observations fused (the replay's columns)
//   <name>_identifications.csv  every identification (the replay's columns)
//   <name>_dropped_scans.txt  the record stamps of the dropped scans [ns], which the
//                        offline re-run leaves out (replay/dropped_scans.h)
#pragma once

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/live/live_sink.h"

namespace swarmlio::tools {

class LiveOutputs : public live::LiveSink {
 public:
  /// Creates the files in `dir`; `imu_odometry` false: no IMU-rate file.
  /// `drone_names[id]` names the teammates in the swarm files (ids without a
  /// name are written as "id<N>").
  static Status Open(const std::string& dir, const std::string& name, bool imu_odometry,
                     const std::vector<std::string>& drone_names,
                     std::unique_ptr<LiveOutputs>* outputs);
  ~LiveOutputs() override;

  void OnScan(const swarm::DroneOutput& output, const live::ScanLatency& latency) override;
  void OnScanDropped(int64_t scan_stamp_ns, live::ScanDropReason reason) override;
  void OnImuPose(const live::ImuRatePose& pose) override;

  /// Closes the files; the first write error, naming the file.
  Status Close();

  const std::vector<float>& latencies_ms() const { return latencies_ms_; }

 private:
  LiveOutputs() = default;
  void Check(bool ok, const std::string& path);
  std::string DroneName(int id) const;

  std::string name_;
  std::vector<std::string> drone_names_;
  double first_scan_s_ = -1.0;
  std::string tum_path_, timing_path_, imu_path_, extrinsics_path_, identifications_path_,
      dropped_path_;
  std::FILE* tum_ = nullptr;
  std::FILE* timing_ = nullptr;
  std::FILE* imu_ = nullptr;
  std::FILE* extrinsics_ = nullptr;
  std::FILE* identifications_ = nullptr;
  std::FILE* dropped_ = nullptr;
  std::vector<float> latencies_ms_;
  std::string error_;
};

}  // namespace swarmlio::tools
