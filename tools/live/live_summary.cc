// The summary the live drivers print and save (live_summary.h).
#include "live_summary.h"

#include <cstdio>

#include "swarmlio/eval/error_statistics.h"

namespace swarmlio::tools {

std::string FormatLiveSummary(const std::string& name, const live::LiveDrone& drone,
                              const LiveOutputs* outputs, const net::UdpStats& udp, double rate,
                              const std::vector<std::string>& drone_names,
                              const std::vector<float>* latencies_ms) {
  const live::LiveStats& s = drone.stats();
  std::vector<double> latency;
  // From the drone's own counters: the ROS node without --output_dir has no
  // LiveOutputs and used to print 0 Hz.
  const double imu_span_s = ToSeconds(s.last_imu_pose_ns - s.first_imu_pose_ns);
  if (outputs != nullptr) {
    latency.assign(outputs->latencies_ms().begin(), outputs->latencies_ms().end());
  }
  if (latencies_ms != nullptr) latency.assign(latencies_ms->begin(), latencies_ms->end());
  const double played_s = ToSeconds(s.sensor_end_ns - s.sensor_start_ns);
  const std::string held =
      s.scans_held_by_initialization > 0
          ? " (not counted: " + std::to_string(s.scans_held_by_initialization) +
                " scans held by the in-flight initialization)"
          : "";
  char buffer[2048];
  std::snprintf(
      buffer, sizeof(buffer),
      "%s: played %.1f s of log in %.1f s (rate %.2f)\n"
      "  scans: %lld played, %lld processed, %lld dropped (%lld queue full, %lld backlog)\n"
      "  latency scan end -> odometry out [ms]: median %.2f  p95 %.2f  max %.2f%s\n"
      "  IMU-rate odometry: %lld poses (%.0f Hz)\n"
      "  messages: sent %lld (send errors %lld, outbox full %lld); received %llu, rejected %llu "
      "(last: %s), duplicates %llu, own %llu; delivered %lld, message queue full %lld\n"
      "  UDP: %llu datagrams / %llu B sent (%llu dropped by a full buffer), %llu / %llu B "
      "received; recorded %lld datagrams\n"
      "  input stalls %lld; estimator warnings %lld%s%s\n",
      name.c_str(), played_s, 1e-9 * static_cast<double>(s.clock_elapsed_ns),
      played_s > 0 ? played_s / (1e-9 * static_cast<double>(s.clock_elapsed_ns)) : 0.0,
      static_cast<long long>(s.scans_played), static_cast<long long>(s.scans_processed),
      static_cast<long long>(s.scans_dropped_queue + s.scans_dropped_backlog),
      static_cast<long long>(s.scans_dropped_queue), static_cast<long long>(s.scans_dropped_backlog),
      eval::Percentile(latency, 0.5), eval::Percentile(latency, 0.95),
      eval::Percentile(latency, 1.0), held.c_str(), static_cast<long long>(s.imu_poses),
      imu_span_s > 0 ? static_cast<double>(s.imu_poses - 1) / imu_span_s : 0.0,
      static_cast<long long>(s.messages_sent), static_cast<long long>(s.send_errors),
      static_cast<long long>(s.outgoing_dropped_queue),
      static_cast<unsigned long long>(s.channel.received),
      static_cast<unsigned long long>(s.channel.rejected),
      s.channel.last_reject_reason.empty() ? "-" : s.channel.last_reject_reason.c_str(),
      static_cast<unsigned long long>(s.channel.duplicates),
      static_cast<unsigned long long>(s.channel.own_packets),
      static_cast<long long>(s.messages_delivered), static_cast<long long>(s.messages_dropped_queue),
      static_cast<unsigned long long>(udp.datagrams_sent),
      static_cast<unsigned long long>(udp.bytes_sent),
      static_cast<unsigned long long>(udp.send_dropped),
      static_cast<unsigned long long>(udp.datagrams_received),
      static_cast<unsigned long long>(udp.bytes_received),
      static_cast<long long>(s.datagrams_logged), static_cast<long long>(s.input_stalls),
      static_cast<long long>(s.estimator_warnings), s.first_warning.empty() ? "" : "; first: ",
      s.first_warning.c_str());
  std::string text = buffer;
  const swarm::DroneEstimatorCounters& c = drone.estimator().counters();
  std::snprintf(buffer, sizeof(buffer),
                "  swarm: %lld identifications, %lld active + %lld passive observations fused "
                "(%lld repeats), %lld gravity; teammates restarted %lld, removed %lld; states "
                "waiting for a clock offset %lld, ignored %lld\n",
                static_cast<long long>(c.identifications), static_cast<long long>(c.active_fused),
                static_cast<long long>(c.passive_fused), static_cast<long long>(c.passive_repeated),
                static_cast<long long>(c.gravity_fused), static_cast<long long>(c.teammate_restarts),
                static_cast<long long>(c.teammates_removed),
                static_cast<long long>(c.messages_unsynchronized),
                static_cast<long long>(c.messages_ignored));
  text += buffer;
  text += swarm::FormatBroadcastCounters(c, "  ");
  {
    char line[256];
    std::snprintf(line, sizeof(line),
                  "  playback: sensor stamp %lld ns at steady clock %lld ns, rate %.6g\n",
                  static_cast<long long>(s.sensor_start_ns),
                  static_cast<long long>(s.clock_start_ns), rate);
    text += line;
    std::snprintf(line, sizeof(line), "  odometry initialized at sensor stamp %lld ns (its G)\n",
                  static_cast<long long>(drone.estimator().initialization().stamp_ns));
    text += line;
    if (const net::ClockSync* sync = drone.estimator().clock_sync()) {
      text += net::FormatClockOffsets(*sync, s.sensor_end_ns, drone_names, "  ");
    }
  }
  return text;
}

}  // namespace swarmlio::tools
