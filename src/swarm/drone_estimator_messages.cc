// swarm::DroneEstimator, the message side: what arrives from teammates, and
// what leaves after each scan (the outputs, the own state and observations,
// the own T_Gi_Gj estimates and gravity). The scan's front end is in
// drone_estimator.cc; docs/swarm.md.
#include <algorithm>
#include <cmath>
#include <variant>

#include "drone_estimator_impl.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/net/wire_format.h"

namespace swarmlio::swarm {
namespace {

// Requests from teammates waiting for their answer (a burst of every
// teammate fits; beyond it, a flood is dropped).
constexpr size_t kMaxPendingSyncRequests = 256;

using internal::Finite;
using internal::PendingMutual;
using internal::PendingPassive;
using internal::Predict;
using internal::PredictedTeammate;
using internal::Seconds;
using internal::SwarmPart;
using internal::TeammateInfo;

}  // namespace

bool DroneEstimator::MadeInSessionOf(int teammate_id, int sender_id,
                                     int64_t sender_stamp_ns) const {
  const auto it = impl_->teammates.find(teammate_id);
  if (it == impl_->teammates.end() || it->second.session_heard_ns == 0) return true;
  int64_t local_ns = sender_stamp_ns;
  if (impl_->clock_sync != nullptr &&
      !impl_->clock_sync->ToLocal(sender_id, sender_stamp_ns, &local_ns)) {
    return false;  // its clock is not known yet
  }
  const int64_t margin_ns =
      static_cast<int64_t>(std::llround(options_.swarm.max_message_age_s * 1e9));
  return local_ns >= it->second.session_heard_ns + margin_ns;
}

bool DroneEstimator::MadeInThisSession(int sender_id, int64_t sender_stamp_ns) const {
  if (!odometry_->initialized()) return false;
  int64_t local_ns = sender_stamp_ns;
  if (impl_->clock_sync != nullptr &&
      !impl_->clock_sync->ToLocal(sender_id, sender_stamp_ns, &local_ns)) {
    return false;  // its clock is not known yet
  }
  const int64_t margin_ns =
      static_cast<int64_t>(std::llround(options_.swarm.max_message_age_s * 1e9));
  // Teammates hear this session with its first state message, sent once the
  // odometry started (after an in-flight initialization's passes).
  return local_ns >= odometry_->initialization().started_ns + margin_ns;
}

Status DroneEstimator::AddMessage(const net::ReceivedMessage& received) {
  ++counters_.messages_received;
  if (const auto* t = std::get_if<net::TimeSyncMessage>(&received.message)) {
    if (impl_->clock_sync == nullptr || t->sender_id == self_id_ || t->target_id != self_id_) {
      ++counters_.messages_ignored;
      return Status::Ok();
    }
    if (t->is_response) {
      net::TimeSyncMessage unused;
      impl_->clock_sync->HandleMessage(*t, received.arrival_ns, received.arrival_ns, &unused);
    } else if (impl_->sync_requests.size() < kMaxPendingSyncRequests) {
      impl_->sync_requests.emplace_back(*t, received.arrival_ns);  // answered in PopMessages
    }
    return Status::Ok();
  }
  if (const auto* g = std::get_if<net::GlobalExtrinsicMessage>(&received.message)) {
    if (g->sender_id == self_id_ || g->sender_id < 0) {
      ++counters_.messages_ignored;
      return Status::Ok();
    }
    for (const net::GlobalExtrinsicEntry& e : g->entries) {
      if (!e.q_Gi_Gj.coeffs().allFinite() || !e.p_Gj_in_Gi.allFinite() ||
          !e.covariance.allFinite() || e.teammate_id < 0) {
        continue;
      }
      if (e.teammate_id == self_id_) {
        // The sender's T_Gj_Gi is about this drone's G only if made in this
        // session: after a restart, teammates keep broadcasting the old one
        // until they hear the new session (its first states, one latency).
        if (MadeInThisSession(g->sender_id, g->stamp_ns)) {
          impl_->mutual[g->sender_id] = PendingMutual{e};
        } else {
          ++counters_.extrinsics_stale;
        }
      } else if (e.source == net::ExtrinsicSource::kTrajectoryMatch) {
        // Likewise about a third drone k that restarted: the sender keeps
        // its T_Gj_Gk of k's old G_k until it hears k's new session.
        if (MadeInSessionOf(e.teammate_id, g->sender_id, g->stamp_ns)) {
          impl_->teammates[g->sender_id].identified[e.teammate_id] = e;
        } else {
          ++counters_.extrinsics_stale;
        }
      }
    }
    // A zero vector: an old sender without gravity; ignored.
    if (g->g_in_Gi.allFinite() && g->cov_g_in_Gi.allFinite() && g->g_in_Gi.norm() > 1.0) {
      TeammateInfo& info = impl_->teammates[g->sender_id];
      info.gravity_pending = true;
      info.g_in_Gj = g->g_in_Gi;
      info.cov_g_in_Gj = g->cov_g_in_Gi;
    }
    return Status::Ok();
  }
  const auto* received_state = std::get_if<net::EgoStateMessage>(&received.message);
  if (received_state == nullptr || received_state->sender_id == self_id_ ||
      received_state->sender_id < 0 || !Finite(*received_state)) {
    ++counters_.messages_ignored;
    return Status::Ok();
  }
  // j's stamps on the own clock; its states wait until its offset is known.
  net::EgoStateMessage local_state = *received_state;
  const net::EgoStateMessage* m = &local_state;
  if (impl_->clock_sync != nullptr) {
    // A new session (j rebooted): its clock may have stepped, start over.
    const auto [session, inserted] =
        impl_->clock_sessions.emplace(m->sender_id, m->session_start_ns);
    if (!inserted && session->second != m->session_start_ns) {
      session->second = m->session_start_ns;
      impl_->clock_sync->RemoveTeammate(m->sender_id);
    }
    impl_->clock_sync->AddTeammate(m->sender_id, received.arrival_ns);
    impl_->clock_sync->NoteTeammateState(*received_state, received.arrival_ns);
    if (!impl_->clock_sync->ToLocal(m->sender_id, received_state->stamp_ns, &local_state.stamp_ns)) {
      ++counters_.messages_unsynchronized;
      return Status::Ok();
    }
  }
  TeammateInfo& info = impl_->teammates[m->sender_id];
  if (info.have_message && m->session_start_ns != info.session_start_ns) {
    // j rebooted: its G_j is new. Its old track and trajectory are useless;
    // its state block goes at the next scan; it is identified again.
    ++counters_.teammate_restarts;
    info.restarted = true;
    info.have_message = false;
    info.identified.clear();  // its T_Gj_Gk were in its old G_j
    info.session_heard_ns = received.arrival_ns;
    // The other teammates' T_Gk_Gj were about its old G_j (graph
    // identification would compose them: off by its motion since its start).
    for (auto& [id, other] : impl_->teammates) other.identified.erase(m->sender_id);
    info.taken_observation_stamps.clear();
    detector_->RestartTeammate(m->sender_id, Seconds(received.arrival_ns));
    impl_->mutual.erase(m->sender_id);
    impl_->passive.erase(std::remove_if(impl_->passive.begin(), impl_->passive.end(),
                                        [&](const PendingPassive& p) {
                                          return p.from == m->sender_id;
                                        }),
                         impl_->passive.end());
  }
  if (info.have_message && m->stamp_ns <= info.last.stamp_ns) {
    ++counters_.messages_ignored;  // older than what we have (reordered)
  } else {
    info.last = *m;
    info.have_message = true;
  }
  info.session_start_ns = m->session_start_ns;
  info.last_heard_ns = std::max(info.last_heard_ns, received.arrival_ns);

  teammate::TeammateOdometry odometry;
  odometry.stamp_s = Seconds(m->stamp_ns);
  odometry.drone_id = m->sender_id;
  odometry.p_bj_in_Gj = m->p_bj_in_Gj;
  odometry.q_Gj_bj = m->q_Gj_bj.normalized();
  odometry.v_bj_in_Gj = m->v_bj_in_Gj;
  odometry.degenerate = m->degenerated;
  detector_->AddTeammateOdometry(odometry);

  // j's observations of this drone: each one once, whether it comes in the
  // message of its scan or repeated in the next (stamps on j's clock; a
  // repeat's age travels in 0.1 ms steps).
  const auto queue = [&](int64_t age_ns, const Eigen::Vector3d& p_bi, const Eigen::Matrix3d& cov,
                         bool repeated) {
    constexpr int64_t kTolerance = net::kPastObservationAgeStepNs / 2 + 1;
    const int64_t remote_stamp_ns = received_state->stamp_ns - age_ns;
    for (int64_t t : info.taken_observation_stamps) {
      if (std::abs(t - remote_stamp_ns) <= kTolerance) {
        ++counters_.repeats_duplicate;
        return;
      }
    }
    info.taken_observation_stamps.push_back(remote_stamp_ns);
    constexpr size_t kKeep = 16;
    while (info.taken_observation_stamps.size() > kKeep) info.taken_observation_stamps.pop_front();
    PendingPassive p;
    p.from = m->sender_id;
    p.repeated = repeated;
    p.stamp_ns = m->stamp_ns - age_ns;
    p.p_bi_in_bj = p_bi;
    p.cov = cov;
    p.sender = *m;
    p.sender.observations.clear();
    p.sender.past_observations.clear();
    if (repeated) {
      // A repeat travels in G_j: its sender is "at the origin of G_j", the
      // sender's pose uncertainty already in the observation's covariance.
      p.sender.q_Gj_bj = Eigen::Quaterniond::Identity();
      p.sender.p_bj_in_Gj.setZero();
      p.sender.cov_theta_Gj_bj.setZero();
      p.sender.cov_p_bj_in_Gj.setZero();
    }
    impl_->passive.push_back(std::move(p));
  };
  for (const net::TeammateObservation& o : m->observations) {
    if (o.observed_id == self_id_ && o.p_bk_in_bj.allFinite() && o.cov_p_bk_in_bj.allFinite()) {
      queue(0, o.p_bk_in_bj, o.cov_p_bk_in_bj, false);
    }
  }
  for (const net::PastObservation& o : m->past_observations) {
    if (o.observed_id == self_id_ && o.age_ns > 0 && o.p_bk_in_Gj.allFinite() &&
        o.cov_p_bk_in_Gj.allFinite()) {
      queue(o.age_ns, o.p_bk_in_Gj, o.cov_p_bk_in_Gj, true);
    }
  }
  return Status::Ok();
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

void DroneEstimator::OnScanDone(const lio::ScanOutput& output, const SwarmState& x,
                                const Eigen::MatrixXd& P) {
  Impl& im = *impl_;
  if (!output.hook_error.empty()) ++counters_.front_end_errors;
  const int64_t t_k = output.stamp_ns;
  for (int id : x.layout().teammate_ids()) {
    TeammateEstimate e;
    e.drone_id = id;
    e.T_Gi_Gj = x.teammate(id);
    const Segment block = x.layout().TeammateBlock(id);
    e.extrinsic_covariance = P.block<6, 6>(block.offset, block.offset);
    const TeammateInfo& info = im.teammates[id];
    if (info.have_message &&
        std::abs(Seconds(t_k - info.last.stamp_ns)) <= options_.swarm.max_message_age_s) {
      const PredictedTeammate j = Predict(info.last, Seconds(t_k - info.last.stamp_ns));
      const Eigen::Matrix3d R_Gi_Gj = e.T_Gi_Gj.R_Gi_Gj();
      e.have_pose = true;
      e.q_Gi_bj = Eigen::Quaterniond(R_Gi_Gj * j.R_Gj_bj).normalized();
      e.p_bj_in_Gi = R_Gi_Gj * j.p_bj_in_Gj + e.T_Gi_Gj.p_Gj_in_Gi;
      e.v_bj_in_Gi = R_Gi_Gj * j.v_bj_in_Gj;
    }
    e.seen = info.last_seen_ns == t_k;
    const auto fused = im.fused_by_teammate.find(id);
    if (fused != im.fused_by_teammate.end()) {
      e.active_observations = fused->second.first;
      e.passive_observations = fused->second.second;
    }
    im.part.teammates.push_back(e);
  }
  im.parts.push_back(std::move(im.part));
  im.part = SwarmPart();

  // The broadcast: this drone's state and what it saw of its teammates.
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
  std::set<int> reported;
  for (const teammate::TeammateObservation& o : im.detection.observations) {
    if (static_cast<int>(m.observations.size()) >= net::EgoStateMessage::kMaxObservations) break;
    if (o.drone_id == self_id_ || !reported.insert(o.drone_id).second) continue;
    net::TeammateObservation n;
    n.observed_id = o.drone_id;
    n.p_bk_in_bj = o.p_bj_in_bi;
    n.cov_p_bk_in_bj = o.covariance_m2;
    m.observations.push_back(n);
  }
  im.detection.observations.clear();
  // The previous scan's observations again, for receivers that lost them.
  for (net::PastObservation& o : im.repeat) {
    o.age_ns = t_k - im.repeat_stamp_ns;
    if (o.age_ns <= 0 || net::PastObservationAgeCode(o.age_ns) > net::kPastObservationAgeMaxCode ||
        !((o.p_bk_in_Gj - m.p_bj_in_Gj).array().abs() < 0.9 * net::kObservationPositionMaxM).all()) {
      continue;
    }
    if (static_cast<int>(m.past_observations.size()) >= net::EgoStateMessage::kMaxPastObservations) {
      break;
    }
    m.past_observations.push_back(o);
  }
  im.repeat.clear();
  RememberForRepeat(m, x, P);
  if (m.q_Gj_bj.coeffs().allFinite() && m.p_bj_in_Gj.allFinite()) {
    if (im.clock_sync != nullptr) {
      // Clock synchronisation in the broadcast: teammates' states echoed back
      // (the send delay is set when the packet leaves, MessageChannel::Send).
      im.clock_sync->EchoesFor(t_k, &m.echoes);
      im.clock_sync->NoteOwnState(t_k);
    }
    im.messages.push_back(m);
  }

  // The own T_Gi_Gj estimates, every extrinsic_broadcast_period_s and right
  // after a new identification (teammates use them to identify this drone).
  const double period = options_.swarm.extrinsic_broadcast_period_s;
  const bool new_block = !im.parts.back().identifications.empty();
  if (period > 0.0 && x.layout().NumTeammates() > 0 &&
      (new_block || !im.broadcast_extrinsics_once ||
       Seconds(t_k - im.last_extrinsic_broadcast_ns) >= period)) {
    std::vector<net::GlobalExtrinsicEntry> entries;
    for (int id : x.layout().teammate_ids()) {
      net::GlobalExtrinsicEntry e;
      e.teammate_id = id;
      e.source = im.teammates[id].via_graph ? net::ExtrinsicSource::kGraph
                                            : net::ExtrinsicSource::kTrajectoryMatch;
      e.q_Gi_Gj = x.teammate(id).q_Gi_Gj.normalized();
      e.p_Gj_in_Gi = x.teammate(id).p_Gj_in_Gi;
      const Segment b = x.layout().TeammateBlock(id);
      e.covariance = P.block<6, 6>(b.offset, b.offset);
      e.covariance = 0.5 * (e.covariance + e.covariance.transpose()).eval();
      if (e.q_Gi_Gj.coeffs().allFinite() && e.p_Gj_in_Gi.allFinite() && e.covariance.allFinite()) {
        entries.push_back(e);
      }
    }
    const Segment gravity = ErrorStateLayout::kGravity;
    Eigen::Matrix3d cov_g = P.block<3, 3>(gravity.offset, gravity.offset);
    cov_g = 0.5 * (cov_g + cov_g.transpose()).eval();
    const Eigen::Vector3d g = x.ego.g_in_G.allFinite() && cov_g.allFinite()
                                  ? x.ego.g_in_G
                                  : Eigen::Vector3d::Zero();
    if (!cov_g.allFinite()) cov_g.setZero();
    for (net::GlobalExtrinsicMessage& g_msg :
         net::SplitGlobalExtrinsics(self_id_, t_k, entries, g, cov_g)) {
      im.messages.push_back(std::move(g_msg));
    }
    im.last_extrinsic_broadcast_ns = t_k;
    im.broadcast_extrinsics_once = true;
  }
}

}  // namespace swarmlio::swarm
