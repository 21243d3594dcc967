// swarm::DroneEstimator, what leaves after each scan: the own state, and
// within the byte budget (broadcast_budget.h) the echoes for the teammates'
// clock sync, the observations of teammates, the repeats of the previous
// scan's observations, and the own T_Gi_Gj estimates with gravity.
// docs/swarm.md "Broadcast budget", docs/network.md section 2.2.
//
// Priorities, highest first (what a crowded drone keeps):
//   1. the state (always);
//   2. echoes for teammates whose clock offset is not converged yet (without
//      them no teammate can use this drone's states; 7 B each), at most
//      urgent_echoes_per_state;
//   3. T_Gi_Gj entries never sent (a new identification: teammates need it
//      for mutual and graph identification; once per teammate and session);
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
// A new T_Gi_Gj entry that does not fit holds everything below it back, so the
// credit saves up for it (otherwise the small items below would take each
// scan's few bytes and a 118 B broadcast would never fit). Below it, what does
// not fit is skipped and the smaller items after it take what is left. An
// item that does not fit waits: a later scan, with more credit or fewer
// teammates in view, sends it.
#include <algorithm>
#include <cstdio>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "drone_estimator_impl.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/net/wire_format.h"

namespace swarmlio::swarm {
namespace {

using internal::Seconds;

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

bool ChooseExtrinsicEntries(const std::vector<int>& candidates, int max_entries,
                            BroadcastBudget* budget, std::vector<int>* chosen) {
  for (int id : candidates) {
    if (max_entries > 0 && static_cast<int>(chosen->size()) >= max_entries) return true;
    const size_t extra =
        ExtrinsicWireBytes(*budget, chosen->size() + 1) - ExtrinsicWireBytes(*budget, chosen->size());
    if (!budget->TrySpend(extra)) return false;
    chosen->push_back(id);
  }
  return true;
}

}  // namespace

std::string FormatBroadcastCounters(const DroneEstimatorCounters& c, const std::string& indent) {
  char line[256];
  std::snprintf(line, sizeof(line),
                "broadcast: %lld B states, %lld B echoes, %lld B observations (%lld left out by "
                "the byte budget), %lld B repeats, %lld B extrinsics\n",
                static_cast<long long>(c.sent_state_bytes), static_cast<long long>(c.sent_echo_bytes),
                static_cast<long long>(c.sent_observation_bytes),
                static_cast<long long>(c.observations_unsent),
                static_cast<long long>(c.sent_repeat_bytes),
                static_cast<long long>(c.sent_extrinsic_bytes));
  return indent + line;
}

void DroneEstimator::Broadcast(const lio::ScanOutput& output, const SwarmState& x,
                               const Eigen::MatrixXd& P) {
  Impl& im = *impl_;
  BroadcastBudget& budget = im.budget;
  const int64_t t_k = output.stamp_ns;
  budget.Refill(t_k);

  // 1. The state.
  net::EgoStateMessage m;
  m.sender_id = self_id_;
  m.stamp_ns = t_k;
  m.session_start_ns = odometry_->initialization().stamp_ns;
  m.q_Gj_bj = x.ego.q_G_b.normalized();
  m.p_bj_in_Gj = x.ego.p_b_in_G;
  m.v_bj_in_Gj = x.ego.v_b_in_G;
  m.omega_bj_in_bj = im.last_gyro - x.ego.gyro_bias;
  const auto block = [&P](const Segment& s) {
    return Eigen::Matrix3d(P.block<3, 3>(s.offset, s.offset));
  };
  m.cov_theta_Gj_bj = block(ErrorStateLayout::kRotation);
  m.cov_p_bj_in_Gj = block(ErrorStateLayout::kPosition);
  m.cov_v_bj_in_Gj = block(ErrorStateLayout::kVelocity);
  m.degenerated = output.degenerate;
  const bool send_state = m.q_Gj_bj.coeffs().allFinite() && m.p_bj_in_Gj.allFinite();
  const size_t state_bytes = budget.WireBytes(net::EgoStatePacketBytes(0));
  if (send_state) budget.Spend(state_bytes);

  // 2. Echoes for teammates whose clock offset is not converged: teammates'
  // states back to them (the send delay is set when the packet leaves,
  // MessageChannel::Send).
  const auto add_echoes = [&](net::ClockSync::EchoSelection selection, int most) {
    if (!send_state || im.clock_sync == nullptr) return;
    const size_t before = m.echoes.size();
    im.clock_sync->EchoesFor(t_k, budget.Affordable(0, net::kStateEchoBytes, most), selection,
                             &m.echoes);
    budget.Spend((m.echoes.size() - before) * net::kStateEchoBytes);
  };
  add_echoes(net::ClockSync::EchoSelection::kUnconverged,
             options_.swarm.broadcast_budget.urgent_echoes_per_state);

  // 3. T_Gi_Gj entries never sent, or not for extrinsic_overdue_s (period 0:
  // never broadcast), the never sent first. One that does not fit holds
  // everything below back: the credit saves up for it.
  const double period = options_.swarm.extrinsic_broadcast_period_s;
  const int max_entries = options_.swarm.broadcast_budget.max_extrinsic_entries_per_broadcast;
  // Overdue after extrinsic_overdue_s, or longer when the entries would then
  // take more than kOverdueBudgetShare of the budget (a large swarm).
  const BroadcastBudgetOptions& bo = options_.swarm.broadcast_budget;
  double overdue_s = bo.extrinsic_overdue_s;
  if (overdue_s > 0.0 && bo.max_bytes_per_s > 0.0) {
    overdue_s = std::max(overdue_s, static_cast<double>(x.layout().teammate_ids().size() *
                                                        net::kExtrinsicEntryBytes) /
                                        (kOverdueBudgetShare * bo.max_bytes_per_s));
  }
  std::vector<int> fresh;
  std::vector<int> sent_before;
  if (period > 0.0) {
    for (int id : x.layout().teammate_ids()) {
      const bool urgent =
          !im.extrinsic_rotation.EverSent(id) ||
          (overdue_s > 0.0 &&
           im.extrinsic_rotation.LastSentNs(id) != std::numeric_limits<int64_t>::min() &&
           Seconds(t_k - im.extrinsic_rotation.LastSentNs(id)) >= overdue_s);
      (urgent ? fresh : sent_before).push_back(id);
    }
    fresh = im.extrinsic_rotation.Order(std::move(fresh));
  }
  std::vector<int> entry_ids;
  bool blocked = !ChooseExtrinsicEntries(fresh, max_entries, &budget, &entry_ids);

  // 4. Observations: one per teammate; of teammates that report degenerate
  // scans first (they depend on them), then 5. the repeats (by default only
  // of those), then 7. the others; each group the least recently reported
  // teammate first.
  std::map<int, const teammate::TeammateObservation*> seen;
  for (const teammate::TeammateObservation& o : im.detection.observations) {
    if (o.drone_id != self_id_) seen.emplace(o.drone_id, &o);  // the first of each
  }
  std::vector<int> needy_ids, other_ids;
  for (const auto& [id, o] : seen) {
    const auto it = im.teammates.find(id);
    const bool degenerate =
        it != im.teammates.end() && it->second.have_message && it->second.last.degenerated;
    (degenerate ? needy_ids : other_ids).push_back(id);
  }
  const auto add_observations = [&](const std::vector<int>& ids) {
    for (int id : im.observation_rotation.Order(ids)) {
      if (!send_state || blocked ||
          static_cast<int>(m.observations.size()) >= net::EgoStateMessage::kMaxObservations ||
          !budget.TrySpend(net::kObservationBytes)) {
        return;
      }
      const teammate::TeammateObservation& o = *seen.at(id);
      net::TeammateObservation n;
      n.observed_id = o.drone_id;
      n.p_bk_in_bj = o.p_bj_in_bi;
      n.cov_p_bk_in_bj = o.covariance_m2;
      m.observations.push_back(n);
      im.observation_rotation.MarkSent(o.drone_id);
    }
  };
  add_observations(needy_ids);

  // 5. The previous scan's observations again, for receivers that lost them.
  for (net::PastObservation& o : im.repeat) {
    if (!send_state || blocked) break;
    o.age_ns = t_k - im.repeat_stamp_ns;
    if (o.age_ns <= 0 || net::PastObservationAgeCode(o.age_ns) > net::kPastObservationAgeMaxCode ||
        !((o.p_bk_in_Gj - m.p_bj_in_Gj).array().abs() < 0.9 * net::kObservationPositionMaxM).all()) {
      continue;
    }
    if (static_cast<int>(m.past_observations.size()) >= net::EgoStateMessage::kMaxPastObservations) {
      break;
    }
    const size_t bytes = net::kPastObservationBytes + (m.past_observations.empty() ? 1 : 0);
    if (!budget.TrySpend(bytes)) break;
    m.past_observations.push_back(o);
  }

  // 6. Our estimate of a teammate's offset, for it to fuse with its own (at
  // most one per state, each teammate every report_period_s), then echoes
  // for teammates whose offset is not settled (a jittery link: the offset
  // needs many exchanges; every unsettled_echo_period_s).
  if (!blocked && send_state && im.clock_sync != nullptr &&
      budget.Affordable(0, net::kOffsetReportBytes, 1) > 0) {
    net::ClockOffsetReport report;
    if (im.clock_sync->ReportFor(t_k, &report)) {
      m.offset_report = report;
      budget.Spend(net::kOffsetReportBytes);
    }
  }
  if (!blocked) {
    add_echoes(net::ClockSync::EchoSelection::kUnsettled, net::EgoStateMessage::kMaxEchoes);
  }

  // 7. The other observations.
  add_observations(other_ids);
  im.detection.observations.clear();
  im.repeat.clear();
  RememberForRepeat(m, x, P);

  // 8. The other echoes (settled offsets: they track the drift).
  if (!blocked) add_echoes(net::ClockSync::EchoSelection::kAll, net::EgoStateMessage::kMaxEchoes);
  if (send_state && im.clock_sync != nullptr) im.clock_sync->NoteOwnState(t_k);
  if (send_state) {
    im.messages.push_back(m);
    const size_t past_bytes =
        m.past_observations.empty() ? 0 : 1 + net::kPastObservationBytes * m.past_observations.size();
    counters_.sent_state_bytes += static_cast<int64_t>(state_bytes);
    counters_.sent_echo_bytes += static_cast<int64_t>(
        net::kStateEchoBytes * m.echoes.size() + (m.offset_report ? net::kOffsetReportBytes : 0));
    counters_.sent_observation_bytes +=
        static_cast<int64_t>(net::kObservationBytes * m.observations.size());
    counters_.sent_repeat_bytes += static_cast<int64_t>(past_bytes);
    counters_.observations_unsent += static_cast<int64_t>(seen.size() - m.observations.size());
  }

  // 9. The periodic re-broadcast of the entries sent before.
  const bool due = period > 0.0 && (!im.broadcast_extrinsics_once ||
                                    Seconds(t_k - im.last_extrinsic_broadcast_ns) >= period);
  if (due && !blocked) {
    const size_t before = entry_ids.size();
    ChooseExtrinsicEntries(im.extrinsic_rotation.Order(std::move(sent_before)), max_entries,
                           &budget, &entry_ids);
    if (entry_ids.size() > before) {
      im.last_extrinsic_broadcast_ns = t_k;
      im.broadcast_extrinsics_once = true;
    }
  }
  if (entry_ids.empty()) return;
  std::vector<net::GlobalExtrinsicEntry> entries;
  for (int id : entry_ids) {
    net::GlobalExtrinsicEntry e;
    e.teammate_id = id;
    e.source = im.teammates[id].via_graph ? net::ExtrinsicSource::kGraph
                                          : net::ExtrinsicSource::kTrajectoryMatch;
    e.q_Gi_Gj = x.teammate(id).q_Gi_Gj.normalized();
    e.p_Gj_in_Gi = x.teammate(id).p_Gj_in_Gi;
    const Segment b = x.layout().TeammateBlock(id);
    e.covariance = P.block<6, 6>(b.offset, b.offset);
    e.covariance = 0.5 * (e.covariance + e.covariance.transpose()).eval();
    im.extrinsic_rotation.MarkSent(id, t_k);  // a non-finite one is not retried before its turn
    if (e.q_Gi_Gj.coeffs().allFinite() && e.p_Gj_in_Gi.allFinite() && e.covariance.allFinite()) {
      entries.push_back(e);
    }
  }
  if (entries.empty()) return;
  counters_.sent_extrinsic_bytes += static_cast<int64_t>(ExtrinsicWireBytes(budget, entries.size()));
  const Segment gravity = ErrorStateLayout::kGravity;
  Eigen::Matrix3d cov_g = P.block<3, 3>(gravity.offset, gravity.offset);
  cov_g = 0.5 * (cov_g + cov_g.transpose()).eval();
  const Eigen::Vector3d g =
      x.ego.g_in_G.allFinite() && cov_g.allFinite() ? x.ego.g_in_G : Eigen::Vector3d::Zero();
  if (!cov_g.allFinite()) cov_g.setZero();
  for (net::GlobalExtrinsicMessage& g_msg :
       net::SplitGlobalExtrinsics(self_id_, t_k, entries, g, cov_g)) {
    im.messages.push_back(std::move(g_msg));
  }
}

void DroneEstimator::RememberForRepeat(const net::EgoStateMessage& m, const SwarmState& x,
                                       const Eigen::MatrixXd& P) {
  Impl& im = *impl_;
  const RepeatObservations policy = options_.swarm.repeat_observations;
  if (policy == RepeatObservations::kNone) return;
  // k's position in G_i and its covariance with the own pose's:
  //   p = R z + p_b,  dp = R dz - R [z]x dtheta + dp_b.
  const Eigen::Matrix3d R = x.ego.R_G_b();
  const Segment rot = ErrorStateLayout::kRotation;
  const Segment pos = ErrorStateLayout::kPosition;
  const Eigen::Matrix3d P_tt = P.block<3, 3>(rot.offset, rot.offset);
  const Eigen::Matrix3d P_pp = P.block<3, 3>(pos.offset, pos.offset);
  const Eigen::Matrix3d P_tp = P.block<3, 3>(rot.offset, pos.offset);
  im.repeat_stamp_ns = m.stamp_ns;
  for (const net::TeammateObservation& o : m.observations) {
    if (policy == RepeatObservations::kDegenerateTeammates) {
      const auto it = im.teammates.find(o.observed_id);
      if (it == im.teammates.end() || !it->second.have_message || !it->second.last.degenerated) {
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
    if (r.p_bk_in_Gj.allFinite() && C.allFinite()) im.repeat.push_back(r);
  }
}

}  // namespace swarmlio::swarm
