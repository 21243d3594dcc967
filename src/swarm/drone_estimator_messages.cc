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

  // A teammate whose block went (lost or restarted) is new again when it is
  // identified again: its T_Gi_Gj entry goes out at once.
  for (int id : im.parts.back().removed) im.extrinsic_rotation.Forget(id);
  Broadcast(output, x, P);
}

}  // namespace swarmlio::swarm
