// Broadcaster: what leaves after each scan: the own state, and within the
// byte budget (broadcast_budget.h) the echoes for the teammates' clock sync,
// the own airframe when due, the observations of teammates, the repeats of
// the previous scan's observations, and the own T_Gi_Gj estimates with
// gravity.
// docs/swarm.md "Broadcast budget", docs/network.md section 2.2.
//
// Priorities, highest first (what a crowded drone keeps):
//   1. the state (always);
//   2. echoes for teammates whose clock offset is not converged yet (without
//      them no teammate can use this drone's states; 7 B each), at most
//      urgent_echoes_per_state;
//   3. T_Gi_Gj entries never sent (a new identification: teammates need it
//      for mutual and graph identification; once per teammate and session);
//   3b. the own airframe, with the first scan's messages and then every
//      airframe_period_s (78 B every 2 s by default; without it teammates
//      whose gates are stricter than this body may not detect it);
//   4. observations of teammates whose last state reports a degenerate scan
//      (their only information along the degenerate direction);
//   5. repeats of the previous scan's observations (for receivers that lost
//      them; by default only those of degenerate teammates);
//   6. echoes for teammates whose offset is not settled (std above
//      settled_std_s: a jittery link needs many exchanges);
//   7. the other observations; each observation group the least recently
//      reported teammate first;
//   8. the other echoes (settled offsets only track the drift);
//   9. the periodic re-broadcast of T_Gi_Gj entries already sent, the least
//      recently sent first: the receivers have an older version.
// A new T_Gi_Gj entry or a due airframe that does not fit holds everything
// below it back, so the credit saves up for it (otherwise the small items
// below would take each scan's few bytes and a 118 B broadcast would never
// fit). Below them, what does
// not fit is skipped and the smaller items after it take what is left. An
// item that does not fit waits: a later scan, with more credit or fewer
// teammates in view, sends it.
#include "broadcaster.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <map>
#include <string>
#include <variant>
#include <vector>

#include "airframe_message.h"
#include "swarmlio/common/time.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/net/wire_format.h"

namespace swarmlio::swarm {
namespace {

// Wire bytes of a GlobalExtrinsic broadcast of n entries (split into
// messages of at most kMaxEntries, each with its own header and gravity).
size_t ExtrinsicWireBytes(const BroadcastBudget& budget, size_t n) {
  if (n == 0) return 0;
  const size_t per = static_cast<size_t>(net::GlobalExtrinsicMessage::kMaxEntries);
  const size_t messages = (n + per - 1) / per;
  return messages * budget.WireBytes(net::GlobalExtrinsicPacketBytes(0)) +
         n * net::kExtrinsicEntryBytes;
}

// Appends `candidates` (in order) to `chosen` while the entry cap allows and
// the budget affords the growing broadcast; false if the budget refused one.
// Overdue T_Gi_Gj entries may take at most this share of the byte budget.
constexpr double kOverdueBudgetShare = 0.1;

bool ChooseExtrinsicEntries(const std::vector<int>& candidates,
                            int max_entries,
                            BroadcastBudget* budget,
                            std::vector<int>* chosen) {
  for (int id : candidates) {
    if (max_entries > 0 && static_cast<int>(chosen->size()) >= max_entries) return true;
    const size_t extra = ExtrinsicWireBytes(*budget, chosen->size() + 1) -
                         ExtrinsicWireBytes(*budget, chosen->size());
    if (!budget->TrySpend(extra)) return false;
    chosen->push_back(id);
  }
  return true;
}

}  // namespace

std::string FormatBroadcastCounters(const DroneEstimatorCounters& c, const std::string& indent) {
  char line[256];
  std::snprintf(
      line, sizeof(line),
      "broadcast: %lld B states, %lld B echoes, %lld B observations (%lld left out by "
      "the byte budget), %lld B repeats, %lld B extrinsics, %lld B airframe\n",
      static_cast<long long>(c.sent_state_bytes), static_cast<long long>(c.sent_echo_bytes),
      static_cast<long long>(c.sent_observation_bytes),
      static_cast<long long>(c.observations_unsent), static_cast<long long>(c.sent_repeat_bytes),
      static_cast<long long>(c.sent_extrinsic_bytes),
      static_cast<long long>(c.sent_airframe_bytes));
  return indent + line;
}

namespace internal {

// One scan's broadcast in the making.
struct Broadcaster::Pass {
  explicit Pass(const BroadcastScan& s) : scan(s) {}
  const BroadcastScan& scan;
  net::EgoStateMessage m;
  bool send_state = false;
  size_t state_bytes = 0;
  // A new T_Gi_Gj entry that did not fit: everything below it waits.
  bool blocked = false;
  std::vector<int> entry_ids;    // T_Gi_Gj entries chosen
  std::vector<int> sent_before;  // entries sent before and not overdue
  // This scan's observations, the first of each teammate; those of
  // teammates that report degenerate scans (needy) and the others.
  std::map<int, const teammate::TeammateObservation*> seen;
  std::vector<int> needy_ids;
  std::vector<int> other_ids;
};

void Broadcaster::Broadcast(const BroadcastScan& scan) {
  budget_.Refill(scan.t_k);
  Pass pass(scan);
  // 1. The state.
  MakeState(&pass);
  // 2. Echoes for teammates whose clock offset is not converged: teammates'
  // states back to them (the send delay is set when the packet leaves,
  // MessageChannel::Send).
  AddEchoes(net::ClockSync::EchoSelection::kUnconverged,
            options_.broadcast_budget.urgent_echoes_per_state, &pass);
  // 3. T_Gi_Gj entries never sent, or overdue.
  ChooseNewExtrinsics(&pass);
  // 3b. The own airframe, when due.
  AnnounceAirframe(&pass);
  // 4. Observations of teammates that report degenerate scans (they depend
  // on them), then 5. the repeats, then 7. the others; each group the least
  // recently reported teammate first.
  SortObservations(&pass);
  AddObservations(pass.needy_ids, &pass);
  AddRepeats(&pass);
  // 6. Our estimate of a teammate's offset, then echoes for teammates whose
  // offset is not settled.
  AddClockItems(&pass);
  // 7. The other observations.
  AddObservations(pass.other_ids, &pass);
  repeat_.clear();
  RememberForRepeat(pass.m, *scan.x, *scan.P);
  // 8. The other echoes (settled offsets: they track the drift).
  if (!pass.blocked) {
    AddEchoes(net::ClockSync::EchoSelection::kAll, net::EgoStateMessage::kMaxEchoes, &pass);
  }
  QueueState(pass);
  // 9. The periodic re-broadcast of the entries sent before, and the entries.
  SendExtrinsics(&pass);
}

void Broadcaster::MakeState(Pass* pass) {
  const SwarmState& x = *pass->scan.x;
  const Eigen::MatrixXd& P = *pass->scan.P;
  net::EgoStateMessage& m = pass->m;
  m.sender_id = self_id_;
  m.stamp_ns = pass->scan.t_k;
  m.session_start_ns = pass->scan.session_start_ns;
  m.q_Gj_bj = x.ego.q_G_b.normalized();
  m.p_bj_in_Gj = x.ego.p_b_in_G;
  m.v_bj_in_Gj = x.ego.v_b_in_G;
  m.omega_bj_in_bj = pass->scan.last_gyro - x.ego.gyro_bias;
  const auto block = [&P](const Segment& s) {
    return Eigen::Matrix3d(P.block<3, 3>(s.offset, s.offset));
  };
  m.cov_theta_Gj_bj = block(ErrorStateLayout::kRotation);
  m.cov_p_bj_in_Gj = block(ErrorStateLayout::kPosition);
  m.cov_v_bj_in_Gj = block(ErrorStateLayout::kVelocity);
  m.degenerated = pass->scan.degenerate;
  pass->send_state = m.q_Gj_bj.coeffs().allFinite() && m.p_bj_in_Gj.allFinite();
  pass->state_bytes = budget_.WireBytes(net::EgoStatePacketBytes(0));
  if (pass->send_state) budget_.Spend(pass->state_bytes);
}

void Broadcaster::AnnounceAirframe(Pass* pass) {
  // With the first scan's messages, then every airframe_period_s of the own
  // clock. One that does not fit holds everything below back, like a new
  // T_Gi_Gj entry: the credit saves up for it.
  const int64_t t_k = pass->scan.t_k;
  const double period = options_.airframe_period_s;
  const bool due =
      period > 0.0 && (!airframe_announced_ || ToSeconds(t_k - last_airframe_ns_) >= period);
  if (!due || pass->blocked) return;
  const size_t bytes = budget_.WireBytes(net::AirframePacketBytes());
  if (!budget_.TrySpend(bytes)) {
    pass->blocked = true;
    return;
  }
  counters_->sent_airframe_bytes += static_cast<int64_t>(bytes);
  messages_.push_back(ToAirframeMessage(self_id_, t_k, airframe_));
  last_airframe_ns_ = t_k;
  airframe_announced_ = true;
}

void Broadcaster::AddEchoes(net::ClockSync::EchoSelection selection, int most, Pass* pass) {
  if (!pass->send_state || clock_sync_ == nullptr) return;
  std::vector<net::StateEcho>& echoes = pass->m.echoes;
  const size_t before = echoes.size();
  clock_sync_->EchoesFor(pass->scan.t_k, budget_.Affordable(0, net::kStateEchoBytes, most),
                         selection, &echoes);
  budget_.Spend((echoes.size() - before) * net::kStateEchoBytes);
}

void Broadcaster::ChooseNewExtrinsics(Pass* pass) {
  // T_Gi_Gj entries never sent, or not for extrinsic_overdue_s (period 0:
  // never broadcast), the never sent first. One that does not fit holds
  // everything below back: the credit saves up for it.
  const SwarmState& x = *pass->scan.x;
  const int64_t t_k = pass->scan.t_k;
  const double period = options_.extrinsic_broadcast_period_s;
  const int max_entries = options_.broadcast_budget.max_extrinsic_entries_per_broadcast;
  // Overdue after extrinsic_overdue_s, or longer when the entries would then
  // take more than kOverdueBudgetShare of the budget (a large swarm).
  const BroadcastBudgetOptions& bo = options_.broadcast_budget;
  double overdue_s = bo.extrinsic_overdue_s;
  if (overdue_s > 0.0 && bo.max_bytes_per_s > 0.0) {
    overdue_s = std::max(overdue_s, static_cast<double>(x.layout().teammate_ids().size() *
                                                        net::kExtrinsicEntryBytes) /
                                        (kOverdueBudgetShare * bo.max_bytes_per_s));
  }
  std::vector<int> fresh;
  if (period > 0.0) {
    for (int id : x.layout().teammate_ids()) {
      const bool urgent =
          !extrinsic_rotation_.EverSent(id) ||
          (overdue_s > 0.0 &&
           extrinsic_rotation_.LastSentNs(id) != std::numeric_limits<int64_t>::min() &&
           ToSeconds(t_k - extrinsic_rotation_.LastSentNs(id)) >= overdue_s);
      (urgent ? fresh : pass->sent_before).push_back(id);
    }
    fresh = extrinsic_rotation_.Order(std::move(fresh));
  }
  pass->blocked = !ChooseExtrinsicEntries(fresh, max_entries, &budget_, &pass->entry_ids);
}

void Broadcaster::SortObservations(Pass* pass) {
  for (const teammate::TeammateObservation& o : *pass->scan.observations) {
    if (o.drone_id != self_id_) pass->seen.emplace(o.drone_id, &o);  // the first of each
  }
  const Teammates& teammates = registry_->teammates();
  for (const auto& [id, o] : pass->seen) {
    const auto it = teammates.find(id);
    const bool degenerate =
        it != teammates.end() && it->second.have_message && it->second.last.degenerated;
    (degenerate ? pass->needy_ids : pass->other_ids).push_back(id);
  }
}

void Broadcaster::AddObservations(const std::vector<int>& ids, Pass* pass) {
  net::EgoStateMessage& m = pass->m;
  for (int id : observation_rotation_.Order(ids)) {
    if (!pass->send_state || pass->blocked ||
        static_cast<int>(m.observations.size()) >= net::EgoStateMessage::kMaxObservations ||
        !budget_.TrySpend(net::kObservationBytes)) {
      return;
    }
    const teammate::TeammateObservation& o = *pass->seen.at(id);
    net::CurrentObservation n;
    n.observed_id = o.drone_id;
    n.p_bk_in_bj = o.p_bj_in_bi;
    n.cov_p_bk_in_bj = o.covariance_m2;
    m.observations.push_back(n);
    observation_rotation_.MarkSent(o.drone_id);
  }
}

void Broadcaster::AddRepeats(Pass* pass) {
  // The previous scan's observations again, for receivers that lost them.
  net::EgoStateMessage& m = pass->m;
  for (net::PastObservation& o : repeat_) {
    if (!pass->send_state || pass->blocked) break;
    o.age_ns = pass->scan.t_k - repeat_stamp_ns_;
    if (o.age_ns <= 0 || net::PastObservationAgeCode(o.age_ns) > net::kPastObservationAgeMaxCode ||
        !((o.p_bk_in_Gj - m.p_bj_in_Gj).array().abs() < 0.9 * net::kObservationPositionMaxM)
             .all()) {
      continue;
    }
    if (static_cast<int>(m.past_observations.size()) >=
        net::EgoStateMessage::kMaxPastObservations) {
      break;
    }
    const size_t bytes = net::kPastObservationBytes + (m.past_observations.empty() ? 1 : 0);
    if (!budget_.TrySpend(bytes)) break;
    m.past_observations.push_back(o);
  }
}

void Broadcaster::AddClockItems(Pass* pass) {
  // Our estimate of a teammate's offset, for it to fuse with its own (at
  // most one per state, each teammate every report_period_s), then echoes
  // for teammates whose offset is not settled (a jittery link: the offset
  // needs many exchanges; every unsettled_echo_period_s).
  if (!pass->blocked && pass->send_state && clock_sync_ != nullptr &&
      budget_.Affordable(0, net::kOffsetReportBytes, 1) > 0) {
    net::ClockOffsetReport report;
    if (clock_sync_->ReportFor(pass->scan.t_k, &report)) {
      pass->m.offset_report = report;
      budget_.Spend(net::kOffsetReportBytes);
    }
  }
  if (!pass->blocked) {
    AddEchoes(net::ClockSync::EchoSelection::kUnsettled, net::EgoStateMessage::kMaxEchoes, pass);
  }
}

void Broadcaster::QueueState(const Pass& pass) {
  const net::EgoStateMessage& m = pass.m;
  if (pass.send_state && clock_sync_ != nullptr) clock_sync_->NoteOwnState(pass.scan.t_k);
  if (!pass.send_state) return;
  messages_.push_back(m);
  const size_t past_bytes =
      m.past_observations.empty() ? 0 : 1 + net::kPastObservationBytes * m.past_observations.size();
  counters_->sent_state_bytes += static_cast<int64_t>(pass.state_bytes);
  counters_->sent_echo_bytes += static_cast<int64_t>(
      net::kStateEchoBytes * m.echoes.size() + (m.offset_report ? net::kOffsetReportBytes : 0));
  counters_->sent_observation_bytes +=
      static_cast<int64_t>(net::kObservationBytes * m.observations.size());
  counters_->sent_repeat_bytes += static_cast<int64_t>(past_bytes);
  counters_->observations_unsent += static_cast<int64_t>(pass.seen.size() - m.observations.size());
}

void Broadcaster::SendExtrinsics(Pass* pass) {
  const SwarmState& x = *pass->scan.x;
  const Eigen::MatrixXd& P = *pass->scan.P;
  const int64_t t_k = pass->scan.t_k;
  const double period = options_.extrinsic_broadcast_period_s;
  const int max_entries = options_.broadcast_budget.max_extrinsic_entries_per_broadcast;
  std::vector<int>& entry_ids = pass->entry_ids;
  const bool due = period > 0.0 && (!broadcast_extrinsics_once_ ||
                                    ToSeconds(t_k - last_extrinsic_broadcast_ns_) >= period);
  if (due && !pass->blocked) {
    const size_t before = entry_ids.size();
    ChooseExtrinsicEntries(extrinsic_rotation_.Order(std::move(pass->sent_before)), max_entries,
                           &budget_, &entry_ids);
    if (entry_ids.size() > before) {
      last_extrinsic_broadcast_ns_ = t_k;
      broadcast_extrinsics_once_ = true;
    }
  }
  if (entry_ids.empty()) return;
  std::vector<net::GlobalExtrinsicEntry> entries;
  for (int id : entry_ids) {
    net::GlobalExtrinsicEntry e;
    e.teammate_id = id;
    e.source = registry_->teammates()[id].via_graph ? net::ExtrinsicSource::kGraph
                                                    : net::ExtrinsicSource::kTrajectoryMatch;
    e.q_Ga_Gb = x.teammate(id).q_Ga_Gb.normalized();
    e.p_Gb_in_Ga = x.teammate(id).p_Gb_in_Ga;
    const Segment b = x.layout().TeammateBlock(id);
    e.covariance = P.block<6, 6>(b.offset, b.offset);
    e.covariance = 0.5 * (e.covariance + e.covariance.transpose()).eval();
    extrinsic_rotation_.MarkSent(id, t_k);  // a non-finite one is not retried before its turn
    if (e.q_Ga_Gb.coeffs().allFinite() && e.p_Gb_in_Ga.allFinite() && e.covariance.allFinite()) {
      entries.push_back(e);
    }
  }
  if (entries.empty()) return;
  counters_->sent_extrinsic_bytes +=
      static_cast<int64_t>(ExtrinsicWireBytes(budget_, entries.size()));
  const Segment gravity = ErrorStateLayout::kGravity;
  Eigen::Matrix3d cov_g = P.block<3, 3>(gravity.offset, gravity.offset);
  cov_g = 0.5 * (cov_g + cov_g.transpose()).eval();
  const Eigen::Vector3d g =
      x.ego.g_in_G.allFinite() && cov_g.allFinite() ? x.ego.g_in_G : Eigen::Vector3d::Zero();
  if (!cov_g.allFinite()) cov_g.setZero();
  for (net::GlobalExtrinsicMessage& g_msg :
       net::SplitGlobalExtrinsics(self_id_, t_k, entries, g, cov_g)) {
    messages_.push_back(std::move(g_msg));
  }
}

void Broadcaster::RememberForRepeat(const net::EgoStateMessage& m,
                                    const SwarmState& x,
                                    const Eigen::MatrixXd& P) {
  const RepeatObservations policy = options_.repeat_observations;
  if (policy == RepeatObservations::kNone) return;
  // k's position in G_i and its covariance with the own pose's:
  //   p = R z + p_b,  dp = R dz - R [z]x dtheta + dp_b.
  const Eigen::Matrix3d R = x.ego.R_G_b();
  const Segment rot = ErrorStateLayout::kRotation;
  const Segment pos = ErrorStateLayout::kPosition;
  const Eigen::Matrix3d P_tt = P.block<3, 3>(rot.offset, rot.offset);
  const Eigen::Matrix3d P_pp = P.block<3, 3>(pos.offset, pos.offset);
  const Eigen::Matrix3d P_tp = P.block<3, 3>(rot.offset, pos.offset);
  repeat_stamp_ns_ = m.stamp_ns;
  for (const net::CurrentObservation& o : m.observations) {
    if (policy == RepeatObservations::kDegenerateTeammates) {
      const auto it = registry_->teammates().find(o.observed_id);
      if (it == registry_->teammates().end() || !it->second.have_message ||
          !it->second.last.degenerated) {
        continue;
      }
    }
    const Eigen::Matrix3d A = -R * so3::Hat(o.p_bk_in_bj);
    Eigen::Matrix3d C = R * o.cov_p_bk_in_bj * R.transpose() + A * P_tt * A.transpose() + P_pp +
                        A * P_tp + P_tp.transpose() * A.transpose();
    C = 0.5 * (C + C.transpose()).eval();
    net::PastObservation r;
    r.observed_id = o.observed_id;
    r.p_bk_in_Gj = R * o.p_bk_in_bj + x.ego.p_b_in_G;
    r.cov_p_bk_in_Gj = C;
    if (r.p_bk_in_Gj.allFinite() && C.allFinite()) repeat_.push_back(r);
  }
}

}  // namespace internal
}  // namespace swarmlio::swarm

namespace swarmlio::swarm::internal {

void Broadcaster::ForgetTeammates(const std::vector<int>& ids) {
  for (int id : ids) extrinsic_rotation_.Forget(id);
}

void Broadcaster::QueueSyncRequest(const net::TimeSyncMessage& request, int64_t arrival_ns) {
  // Requests from teammates waiting for their answer (a burst of every
  // teammate fits; beyond it, a flood is dropped).
  constexpr size_t kMaxPendingSyncRequests = 256;
  if (sync_requests_.size() < kMaxPendingSyncRequests) {
    sync_requests_.emplace_back(request, arrival_ns);
  }
}

void Broadcaster::TakeMessages(int64_t now_ns, std::vector<net::SwarmMessage>* messages) {
  for (net::SwarmMessage& m : messages_) messages->push_back(std::move(m));
  messages_.clear();
  if (clock_sync_ == nullptr || now_ns == std::numeric_limits<int64_t>::min()) return;
  // Clock synchronisation, stamped with the send time: answers to the
  // teammates' requests (t3), then the own requests that are due (t1).
  for (const auto& [request, arrival_ns] : sync_requests_) {
    net::TimeSyncMessage reply;
    if (clock_sync_->HandleMessage(request, arrival_ns, std::max(now_ns, arrival_ns), &reply)) {
      messages->push_back(reply);
    }
  }
  sync_requests_.clear();
  std::vector<net::TimeSyncMessage> requests;
  clock_sync_->DueRequests(now_ns, &requests);
  for (const net::TimeSyncMessage& r : requests) messages->push_back(r);
  // TimeSync packets (exchange: requests) are not optional: paid whatever the credit.
  for (const net::SwarmMessage& m : *messages) {
    if (std::holds_alternative<net::TimeSyncMessage>(m)) {
      budget_.Spend(budget_.WireBytes(net::TimeSyncPacketBytes()));
    }
  }
}

}  // namespace swarmlio::swarm::internal
