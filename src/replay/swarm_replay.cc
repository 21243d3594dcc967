#include "swarmlio/replay/swarm_replay.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <variant>

#include "swarmlio/replay/recorded_packet_transport.h"

namespace swarmlio::replay {

double ReplayProgress::Fraction() const {
  if (end_stamp_ns <= start_stamp_ns) return 0.0;
  const double f = static_cast<double>(stamp_ns - start_stamp_ns) /
                   static_cast<double>(end_stamp_ns - start_stamp_ns);
  return std::clamp(f, 0.0, 1.0);
}

Status SwarmReplay::Create(const driver::SwarmManifest& manifest, std::unique_ptr<SwarmReplay>* replay) {
  std::unique_ptr<SwarmReplay> r(new SwarmReplay());
  r->manifest_ = manifest;
  std::string errors;
  r->start_stamp_ns_ = std::numeric_limits<int64_t>::max();
  r->end_stamp_ns_ = std::numeric_limits<int64_t>::min();
  for (size_t i = 0; i < manifest.drones.size(); ++i) {
    const driver::DroneInput& input = manifest.drones[i];
    std::unique_ptr<DroneRunner> runner;
    const Status status = DroneRunner::Create(input, static_cast<int>(i), &runner);
    if (!status.ok()) {
      errors += (errors.empty() ? "" : "; ") + status.message();
      continue;
    }
    const io::BagReader& reader = runner->reader();
    if (reader.end_time_ns() > 0) {
      r->start_stamp_ns_ = std::min(r->start_stamp_ns_, reader.start_time_ns());
      r->end_stamp_ns_ = std::max(r->end_stamp_ns_, reader.end_time_ns());
    }
    r->runners_.push_back(std::move(runner));
  }
  if (!errors.empty()) return Status::InvalidArgument(errors);
  if (r->start_stamp_ns_ > r->end_stamp_ns_) r->start_stamp_ns_ = r->end_stamp_ns_ = 0;
  *replay = std::move(r);
  return Status::Ok();
}

net::LinkStats SwarmReplay::LinkStats(int from, int to) const {
  return network_ ? network_->Stats(from, to) : net::LinkStats();
}

Status SwarmReplay::SetUpNetwork(const ReplayOptions& options) {
  traffic_.assign(runners_.size(), DroneTraffic());
  channels_.clear();
  network_.reset();
  for (auto& runner : runners_) runner->SetFusion(!options.single_agent);
  std::vector<int> ids;
  for (size_t i = 0; i < runners_.size(); ++i) ids.push_back(static_cast<int>(i));
  SWARMLIO_RETURN_IF_ERROR(net::SimulatedNetwork::Create(options.network, ids, &network_));
  SWARMLIO_RETURN_IF_ERROR(net::PacketCodec::Create(
      options.key ? *options.key
                  : net::SwarmKey::ForSimulation(static_cast<uint64_t>(options.network.seed)),
      &codec_));
  SWARMLIO_RETURN_IF_ERROR(OpenRecordedPackets(options));
  for (int id : ids) {
    net::Transport* transport = recorded_[id] ? recorded_[id].get() : network_->Endpoint(id);
    channels_.push_back(std::make_unique<net::MessageChannel>(&codec_, transport));
  }
  return Status::Ok();
}

Status SwarmReplay::OpenRecordedPackets(const ReplayOptions& options) {
  recorded_.clear();
  recorded_.resize(runners_.size());
  recording_damage_ = Status::Ok();
  for (const auto& [name, path] : options.received_packets) {
    const int id = FindDrone(name);
    if (id < 0) {
      return Status::InvalidArgument("received_packets: no drone named '" + name +
                                     "' in the manifest");
    }
    std::unique_ptr<RecordedPacketTransport> transport;
    SWARMLIO_RETURN_IF_ERROR(RecordedPacketTransport::Open(path, id, &transport));
    // A damaged log re-runs with its complete records; Run() reports it.
    if (recording_damage_.ok()) recording_damage_ = transport->damage();
    recorded_[id] = std::move(transport);
  }
  return Status::Ok();
}

int SwarmReplay::FindDrone(const std::string& name) const {
  for (size_t i = 0; i < runners_.size(); ++i) {
    if (runners_[i]->input().name == name) return static_cast<int>(i);
  }
  return -1;
}

Status SwarmReplay::SkipDroppedScans(const ReplayOptions& options) {
  for (const auto& [name, stamps_ns] : options.dropped_scans) {
    const int id = FindDrone(name);
    if (id < 0) {
      return Status::InvalidArgument("dropped_scans: no drone named '" + name +
                                     "' in the manifest");
    }
    runners_[id]->SkipScans(stamps_ns);
  }
  return Status::Ok();
}

Status SwarmReplay::Broadcast(int drone, int64_t now_ns) {
  outbox_.clear();
  runners_[drone]->TakeMessages(&outbox_);
  for (const net::SwarmMessage& m : outbox_) {
    // A state leaves at its scan end (processing taken as instantaneous);
    // everything else when it was produced, at the record just consumed.
    // The network runs on true time (the drones' clocks differ, TrueClock).
    const int64_t local_ns = std::holds_alternative<net::EgoStateMessage>(m)
                                 ? std::get<net::EgoStateMessage>(m).stamp_ns
                                 : now_ns;
    const int64_t stamp_ns = runners_[drone]->input().true_clock.ToTrue(local_ns);
    SWARMLIO_RETURN_IF_ERROR(channels_[drone]->Send(stamp_ns, net::kBroadcastId, m, local_ns));
    ++traffic_[drone].sent;
  }
  return Status::Ok();
}

Status SwarmReplay::Run(const ReplayOptions& options) {
  SWARMLIO_RETURN_IF_ERROR(SetUpNetwork(options));
  SWARMLIO_RETURN_IF_ERROR(SkipDroppedScans(options));
  std::vector<net::ReceivedMessage> inbox;
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
    // The drone whose next record comes first in true time.
    int best = -1;
    int64_t best_true_ns = 0;
    for (size_t i = 0; i < runners_.size(); ++i) {
      if (failed[i] || !runners_[i]->has_next()) continue;
      const int64_t true_ns = runners_[i]->input().true_clock.ToTrue(runners_[i]->next_stamp_ns());
      if (best < 0 || true_ns < best_true_ns) {
        best = static_cast<int>(i);
        best_true_ns = true_ns;
      }
    }
    if (best < 0 || runners_[best]->next_stamp_ns() > limit_ns) break;
    progress.stamp_ns = runners_[best]->next_stamp_ns();
    if (!channels_.empty()) {
      // What reached this drone by the stamp of its next record.
      inbox.clear();
      // A live recording (received_packets) is on the drone's own time line.
      const bool recorded = recorded_[best] != nullptr;
      const Status polled =
          channels_[best]->Poll(recorded ? progress.stamp_ns : best_true_ns, &inbox);
      if (!polled.ok() && first_error.ok()) first_error = polled;
      for (net::ReceivedMessage& m : inbox) {
        if (!recorded) m.arrival_ns = runners_[best]->input().true_clock.ToDrone(m.arrival_ns);
        ++traffic_[best].received;
        if (std::holds_alternative<net::EgoStateMessage>(m.message)) ++traffic_[best].ego_states;
        runners_[best]->Deliver(m);
      }
    }
    const Status status = runners_[best]->Step();
    if (!status.ok()) {
      failed[best] = true;
      if (first_error.ok()) first_error = status;
    }
    if (!channels_.empty()) {
      const Status sent = Broadcast(best, progress.stamp_ns);
      if (!sent.ok() && first_error.ok()) first_error = sent;
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
  for (size_t i = 0; i < channels_.size(); ++i) traffic_[i].channel = channels_[i]->stats();
  if (options.on_progress) {
    progress.stamp_ns = progress.end_stamp_ns;
    options.on_progress(progress);
  }
  if (first_error.ok()) first_error = recording_damage_;
  return first_error;
}

}  // namespace swarmlio::replay
