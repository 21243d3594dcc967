// The summary a live driver prints at the end and saves as
// <name>_live_summary.txt (swarmlio_live, swarmlio_ros; docs/online.md):
// played time, scans processed/dropped, latency percentiles, IMU-rate poses,
// message and UDP counters, fusion counters, the playback mapping, the
// initialization stamp and the teammates' clock offsets.
#pragma once

#include <string>
#include <vector>

#include "live_outputs.h"
#include "swarmlio/live/live_drone.h"
#include "swarmlio/net/udp_transport.h"

namespace swarmlio::tools {

/// After LiveDrone::Run(). `outputs` (may be null: no latency or IMU-rate
/// figures) gives the latencies unless `latencies_ms` (may be null) does
/// (the ROS node measures them at publication, with or without files);
/// `rate` the playback speed (1 live).
std::string FormatLiveSummary(const std::string& name, const live::LiveDrone& drone,
                              const LiveOutputs* outputs, const net::UdpStats& udp, double rate,
                              const std::vector<std::string>& drone_names,
                              const std::vector<float>* latencies_ms = nullptr);

}  // namespace swarmlio::tools
