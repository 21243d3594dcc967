#include "swarmlio/net/clock_sync_simulation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <variant>

#include "swarmlio/net/packet_codec.h"
#include "swarmlio/net/swarm_key.h"
#include "swarmlio/net/swarm_limits.h"

namespace swarmlio::net {
namespace {

constexpr int64_t kMs = 1'000'000;
constexpr int64_t kS = 1'000'000'000;
constexpr int64_t kNever = std::numeric_limits<int64_t>::max();

/// A valid state broadcast of drone `sender` (the pose is irrelevant to the
/// clock synchronisation; the packet has a state's size).
EgoStateMessage PlaceholderState(int sender) {
  EgoStateMessage m;
  m.sender_id = sender;
  m.cov_theta_Gj_bj = 1e-5 * Eigen::Matrix3d::Identity();
  m.cov_p_bj_in_Gj = 1e-3 * Eigen::Matrix3d::Identity();
  m.cov_v_bj_in_Gj = 1e-2 * Eigen::Matrix3d::Identity();
  return m;
}

}  // namespace

int64_t SimulatedClock::Local(int64_t true_ns) const {
  return epoch_ns + true_ns + std::llround(drift * static_cast<double>(true_ns));
}

int64_t SimulatedClock::TrueAt(int64_t local_ns) const {
  int64_t t = std::llround(static_cast<double>(local_ns - epoch_ns) / (1.0 + drift));
  while (Local(t) < local_ns) ++t;
  while (Local(t - 1) >= local_ns) --t;
  return t;
}

std::vector<SimulatedClock> SwarmClocks() {
  return {{1000 * kS + 500 * kMs, 20e-6}, {1000 * kS - 500 * kMs, -20e-6}, {1000 * kS, 0.0}};
}

ClockSyncSimulation::ClockSyncSimulation(std::vector<SimulatedClock> clocks, int64_t turnaround_ns,
                                         bool states)
    : clocks_(std::move(clocks)), turnaround_ns_(turnaround_ns), states_(states) {}

ClockSyncSimulation::~ClockSyncSimulation() = default;

Status ClockSyncSimulation::Create(const NetworkOptions& network_options,
                                   std::vector<SimulatedClock> clocks,
                                   const ClockSyncOptions& sync_options,
                                   int64_t turnaround_ns,
                                   std::unique_ptr<ClockSyncSimulation>* out) {
  std::unique_ptr<ClockSyncSimulation> sim(new ClockSyncSimulation(
      std::move(clocks), turnaround_ns, sync_options.exchange == ClockExchange::kStateEcho));
  SWARMLIO_RETURN_IF_ERROR(
      PacketCodec::Create(SwarmKey::ForSimulation(7), &sim->codec_));
  std::vector<int> ids;
  for (size_t i = 0; i < sim->clocks_.size(); ++i) ids.push_back(static_cast<int>(i));
  SWARMLIO_RETURN_IF_ERROR(SimulatedNetwork::Create(network_options, ids, &sim->network_));
  for (int id : ids) {
    sim->channels_.emplace_back(&sim->codec_, sim->network_->Endpoint(id));
    std::unique_ptr<ClockSync> sync;
    SWARMLIO_RETURN_IF_ERROR(ClockSync::Create(id, sync_options, &sync));
    for (int other : ids) sync->AddTeammate(other, sim->clocks_[id].Local(0));
    sim->syncs_.push_back(std::move(sync));
    // The first state at a whole period of the drone's clock.
    const int64_t first = sim->clocks_[id].Local(0);
    sim->next_state_ns_.push_back(first + (kStatePeriodNs - first % kStatePeriodNs) % kStatePeriodNs);
  }
  *out = std::move(sim);
  return Status::Ok();
}

int64_t ClockSyncSimulation::NextEventNs() const {
  int64_t t = network_->NextArrivalNs();
  for (size_t i = 0; i < syncs_.size(); ++i) {
    const int64_t next = states_ ? next_state_ns_[i] : syncs_[i]->NextRequestNs();
    if (next != kNever) t = std::min(t, clocks_[i].TrueAt(next));
  }
  for (const PendingReply& p : replies_) t = std::min(t, p.send_ns);
  for (const PendingState& p : states_out_) t = std::min(t, p.send_ns);
  return t;
}

Status ClockSyncSimulation::SendDue(int64_t t) {
  std::vector<TimeSyncMessage> requests;
  for (size_t i = 0; i < syncs_.size(); ++i) {
    requests.clear();
    syncs_[i]->DueRequests(clocks_[i].Local(t), &requests);
    for (const TimeSyncMessage& r : requests) {
      SWARMLIO_RETURN_IF_ERROR(channels_[i].Send(now_ns_, r.target_id, r));
    }
    if (states_ && clocks_[i].TrueAt(next_state_ns_[i]) <= t) MakeState(static_cast<int>(i));
  }
  for (size_t k = 0; k < states_out_.size();) {
    if (states_out_[k].send_ns <= t) {
      const PendingState& p = states_out_[k];
      SWARMLIO_RETURN_IF_ERROR(
          channels_[p.from].Send(now_ns_, kBroadcastId, p.state, p.local_send_ns));
      states_out_.erase(states_out_.begin() + static_cast<std::ptrdiff_t>(k));
    } else {
      ++k;
    }
  }
  for (size_t k = 0; k < replies_.size();) {
    if (replies_[k].send_ns <= t) {
      const TimeSyncMessage& reply = replies_[k].reply;
      SWARMLIO_RETURN_IF_ERROR(channels_[replies_[k].from].Send(now_ns_, reply.target_id, reply));
      replies_.erase(replies_.begin() + static_cast<std::ptrdiff_t>(k));
    } else {
      ++k;
    }
  }
  return Status::Ok();
}

Status ClockSyncSimulation::Receive(int64_t t) {
  std::vector<ReceivedMessage> inbox;
  for (size_t i = 0; i < syncs_.size(); ++i) {
    inbox.clear();
    SWARMLIO_RETURN_IF_ERROR(channels_[i].Poll(t, &inbox));
    for (const ReceivedMessage& m : inbox) {
      const int64_t arrival = clocks_[i].Local(m.arrival_ns);
      if (const auto* state = std::get_if<EgoStateMessage>(&m.message)) {
        syncs_[i]->NoteTeammateState(*state, arrival);
        continue;
      }
      const auto* sync_message = std::get_if<TimeSyncMessage>(&m.message);
      if (sync_message == nullptr) {
        return Status::Internal("clock sync simulation: an unexpected message type arrived");
      }
      TimeSyncMessage reply;
      if (syncs_[i]->HandleMessage(*sync_message, arrival, arrival + turnaround_ns_, &reply)) {
        replies_.push_back({clocks_[i].TrueAt(reply.t3_ns), static_cast<int>(i), reply});
      }
    }
  }
  return Status::Ok();
}

Status ClockSyncSimulation::RunUntil(int64_t end_ns) {
  for (;;) {
    const int64_t t = NextEventNs();
    if (t > end_ns) break;
    now_ns_ = t;
    SWARMLIO_RETURN_IF_ERROR(SendDue(t));
    SWARMLIO_RETURN_IF_ERROR(Receive(t));
  }
  now_ns_ = end_ns;
  return Status::Ok();
}

void ClockSyncSimulation::MakeState(int i) {
  PendingState p;
  p.from = i;
  p.state = PlaceholderState(i);
  p.state.stamp_ns = next_state_ns_[i];
  p.state.session_start_ns = clocks_[i].Local(0);
  syncs_[i]->EchoesFor(p.state.stamp_ns, &p.state.echoes);
  ClockOffsetReport report;
  if (syncs_[i]->ReportFor(p.state.stamp_ns, &report)) p.state.offset_report = report;
  syncs_[i]->NoteOwnState(p.state.stamp_ns);
  p.local_send_ns = p.state.stamp_ns + turnaround_ns_;
  p.send_ns = clocks_[i].TrueAt(p.local_send_ns);
  states_out_.push_back(std::move(p));
  next_state_ns_[i] += kStatePeriodNs;
}

int64_t ClockSyncSimulation::TrueOffset(int i, int j) const {
  return clocks_[j].Local(now_ns_) - clocks_[i].Local(now_ns_);
}

ClockOffsetEstimate ClockSyncSimulation::Estimate(int i, int j) const {
  return syncs_[i]->Estimate(j, clocks_[i].Local(now_ns_));
}

double ClockSyncSimulation::Error(int i, int j) const {
  return static_cast<double>(Estimate(i, j).offset_ns - TrueOffset(i, j));
}

Status RunClockSyncCase(const LinkOptions& link,
                        const ClockSyncOptions& options,
                        int seeds,
                        int end_s,
                        int settle_s,
                        const std::vector<SimulatedClock>& clocks,
                        ClockSyncFigures* figures) {
  ClockSyncFigures f;
  double sum_sq = 0;
  int covered = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    NetworkOptions network;
    network.seed = seed;
    network.default_link = link;
    std::unique_ptr<ClockSyncSimulation> sim;
    SWARMLIO_RETURN_IF_ERROR(ClockSyncSimulation::Create(network, clocks, options, kMs, &sim));
    for (int t = 1; t <= end_s; ++t) {
      SWARMLIO_RETURN_IF_ERROR(sim->RunUntil(t * kS));
      for (int i = 0; i < sim->size(); ++i) {
        for (int j = 0; j < sim->size(); ++j) {
          if (i == j) continue;
          const ClockOffsetEstimate e = sim->Estimate(i, j);
          const double error = e.valid ? sim->Error(i, j) : 1e18;
          if (std::abs(error) > 2 * kMs) {
            f.within_2ms_from_s = std::max<double>(f.within_2ms_from_s, t + 1);
          }
          if (t < settle_s) continue;
          f.max_abs_ms = std::max(f.max_abs_ms, std::abs(error) / kMs);
          f.max_normalised = std::max(f.max_normalised, std::abs(error) / e.std_ns);
          covered += std::abs(error) <= 3.0 * e.std_ns ? 1 : 0;
          sum_sq += error * error;
          ++f.checks;
        }
      }
    }
  }
  f.rms_ms = std::sqrt(sum_sq / std::max(f.checks, 1)) / kMs;
  f.within_3_sigma = static_cast<double>(covered) / std::max(f.checks, 1);
  *figures = f;
  return Status::Ok();
}

}  // namespace swarmlio::net
