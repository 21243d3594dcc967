#include "message_inbox.h"

#include <algorithm>
#include <cmath>
#include <variant>

#include "airframe_message.h"
#include "swarmlio/common/time.h"
#include "swarmlio/net/wire_format.h"

namespace swarmlio::swarm::internal {
namespace {

// The one place a received entry's frames get their names: the wire's
// T_Ga_Gb is the sender j's extrinsic of b = e.teammate_id (T_Gj_Gk, or T_Gj_Gi
// when b is this drone), its rotation normalized here for every later use.
GlobalExtrinsic SendersExtrinsic(const net::GlobalExtrinsicEntry& e) {
  GlobalExtrinsic T_Gj_Gb;
  T_Gj_Gb.q_Ga_Gb = e.q_Ga_Gb.normalized();
  T_Gj_Gb.p_Gb_in_Ga = e.p_Gb_in_Ga;
  return T_Gj_Gb;
}

}  // namespace

bool MessageInbox::ToLocal(int sender_id, int64_t sender_stamp_ns, int64_t* local_ns) const {
  *local_ns = sender_stamp_ns;
  return to_.clock_sync == nullptr || to_.clock_sync->ToLocal(sender_id, sender_stamp_ns, local_ns);
}

bool MessageInbox::MadeInSessionOf(int teammate_id, int sender_id, int64_t sender_stamp_ns) const {
  const Teammates& teammates = to_.registry->teammates();
  const auto it = teammates.find(teammate_id);
  if (it == teammates.end() || it->second.session_heard_ns == 0) return true;
  int64_t local_ns = 0;
  if (!ToLocal(sender_id, sender_stamp_ns, &local_ns)) return false;  // its clock is not known yet
  const int64_t margin_ns = ToNanoseconds(options_.max_message_age_s);
  return local_ns >= it->second.session_heard_ns + margin_ns;
}

bool MessageInbox::MadeInThisSession(int sender_id,
                                     int64_t sender_stamp_ns,
                                     const OwnSession& own) const {
  if (!own.started) return false;
  int64_t local_ns = 0;
  if (!ToLocal(sender_id, sender_stamp_ns, &local_ns)) return false;  // its clock is not known yet
  const int64_t margin_ns = ToNanoseconds(options_.max_message_age_s);
  // Teammates hear this session with its first state message, sent once the
  // odometry started (after an in-flight initialization's passes).
  return local_ns >= own.started_ns + margin_ns;
}

void MessageInbox::Route(const net::ReceivedMessage& received, const OwnSession& own) {
  ++to_.counters->messages_received;
  if (const auto* t = std::get_if<net::TimeSyncMessage>(&received.message)) {
    OnTimeSync(*t, received.arrival_ns);
  } else if (const auto* g = std::get_if<net::GlobalExtrinsicMessage>(&received.message)) {
    OnExtrinsics(*g, own);
  } else if (const auto* s = std::get_if<net::EgoStateMessage>(&received.message)) {
    OnState(*s, received.arrival_ns);
  } else if (const auto* a = std::get_if<net::AirframeMessage>(&received.message)) {
    OnAirframe(*a);
  } else {
    ++to_.counters->messages_ignored;
  }
}

void MessageInbox::OnTimeSync(const net::TimeSyncMessage& t, int64_t arrival_ns) {
  if (to_.clock_sync == nullptr || t.sender_id == self_id_ || t.target_id != self_id_) {
    ++to_.counters->messages_ignored;
    return;
  }
  if (t.is_response) {
    net::TimeSyncMessage unused;
    to_.clock_sync->HandleMessage(t, arrival_ns, arrival_ns, &unused);
  } else {
    to_.broadcaster->QueueSyncRequest(t, arrival_ns);
  }
}

void MessageInbox::OnExtrinsics(const net::GlobalExtrinsicMessage& g, const OwnSession& own) {
  if (g.sender_id == self_id_ || g.sender_id < 0) {
    ++to_.counters->messages_ignored;
    return;
  }
  for (const net::GlobalExtrinsicEntry& e : g.entries) {
    if (!e.q_Ga_Gb.coeffs().allFinite() || !e.p_Gb_in_Ga.allFinite() || !e.covariance.allFinite() ||
        e.teammate_id < 0) {
      continue;
    }
    if (e.teammate_id == self_id_) {
      // The sender's T_Gj_Gi is about this drone's G only if made in this
      // session: after a restart, teammates keep broadcasting the old one
      // until they hear the new session (its first states, one latency).
      if (MadeInThisSession(g.sender_id, g.stamp_ns, own)) {
        PendingMutual mutual;
        mutual.T_Gj_Gi = SendersExtrinsic(e);
        mutual.cov_T_Gj_Gi = e.covariance;
        mutual.source = e.source;
        to_.registry->SetMutual(g.sender_id, mutual);
      } else {
        ++to_.counters->extrinsics_stale;
      }
    } else if (e.source == net::ExtrinsicSource::kTrajectoryMatch) {
      // Likewise about a third drone k that restarted: the sender keeps
      // its T_Gj_Gk of k's old G_k until it hears k's new session.
      if (MadeInSessionOf(e.teammate_id, g.sender_id, g.stamp_ns)) {
        TeammateMatch match;
        match.T_Gj_Gk = SendersExtrinsic(e);
        match.cov_T_Gj_Gk = e.covariance;
        to_.registry->teammates()[g.sender_id].identified[e.teammate_id] = match;
      } else {
        ++to_.counters->extrinsics_stale;
      }
    }
  }
  // A zero vector: an old sender without gravity; ignored.
  if (g.g_in_Gi.allFinite() && g.cov_g_in_Gi.allFinite() && g.g_in_Gi.norm() > 1.0) {
    to_.gravity->Queue(g.sender_id, g.g_in_Gi, g.cov_g_in_Gi);
  }
}

void MessageInbox::OnState(const net::EgoStateMessage& received, int64_t arrival_ns) {
  if (received.sender_id == self_id_ || received.sender_id < 0 || !Finite(received)) {
    ++to_.counters->messages_ignored;
    return;
  }
  // j's stamps on the own clock; its states wait until its offset is known.
  net::EgoStateMessage m = received;
  if (to_.clock_sync != nullptr) {
    // A new session (j rebooted): its clock may have stepped, start over.
    const auto [session, inserted] = clock_sessions_.emplace(m.sender_id, m.session_start_ns);
    if (!inserted && session->second != m.session_start_ns) {
      session->second = m.session_start_ns;
      to_.clock_sync->RemoveTeammate(m.sender_id);
    }
    to_.clock_sync->AddTeammate(m.sender_id, arrival_ns);
    to_.clock_sync->NoteTeammateState(received, arrival_ns);
    if (!to_.clock_sync->ToLocal(m.sender_id, received.stamp_ns, &m.stamp_ns)) {
      ++to_.counters->messages_unsynchronized;
      return;
    }
  }
  TeammateInfo& info = to_.registry->teammates()[m.sender_id];
  if (info.have_message && m.session_start_ns != info.session_start_ns)
    OnRestart(m.sender_id, arrival_ns);
  if (info.have_message && m.stamp_ns <= info.last.stamp_ns) {
    ++to_.counters->messages_ignored;  // older than what we have (reordered)
  } else {
    info.last = m;
    info.have_message = true;
  }
  info.session_start_ns = m.session_start_ns;
  info.last_heard_ns = std::max(info.last_heard_ns, arrival_ns);

  teammate::TeammateOdometry odometry;
  odometry.stamp_ns = m.stamp_ns;
  odometry.drone_id = m.sender_id;
  odometry.p_bj_in_Gj = m.p_bj_in_Gj;
  odometry.q_Gj_bj = m.q_Gj_bj.normalized();
  odometry.v_bj_in_Gj = m.v_bj_in_Gj;
  odometry.degenerate = m.degenerated;
  to_.detector->AddTeammateOdometry(odometry);
  QueueObservations(received, m);
}

void MessageInbox::OnAirframe(const net::AirframeMessage& a) {
  // The body does not change with a session or a clock: every valid
  // announcement is taken as it arrives (the same one again changes nothing).
  teammate::AirframeDescription airframe;
  if (a.sender_id == self_id_ || a.sender_id < 0 || !FromAirframeMessage(a, &airframe) ||
      !to_.detector->SetTeammateAirframe(a.sender_id, airframe)) {
    ++to_.counters->messages_ignored;
  }
}

void MessageInbox::OnRestart(int j, int64_t arrival_ns) {
  // j rebooted: its G_j is new. Its old track and trajectory are useless;
  // its state block goes at the next scan; it is identified again.
  Teammates& teammates = to_.registry->teammates();
  TeammateInfo& info = teammates[j];
  ++to_.counters->teammate_restarts;
  info.restarted = true;
  info.have_message = false;
  info.identified.clear();  // its T_Gj_Gk were in its old G_j
  info.session_heard_ns = arrival_ns;
  // The other teammates' T_Gk_Gj were about its old G_j (graph
  // identification would compose them: off by its motion since its start).
  for (auto& [id, other] : teammates) other.identified.erase(j);
  info.taken_observation_stamps.clear();
  to_.detector->RestartTeammate(j, arrival_ns);
  to_.registry->ForgetMutual(j);
  to_.passive->ForgetSender(j);
}

void MessageInbox::QueueObservations(const net::EgoStateMessage& received,
                                     const net::EgoStateMessage& m) {
  TeammateInfo& info = to_.registry->teammates()[m.sender_id];
  // j's observations of this drone: each one once, whether it comes in the
  // message of its scan or repeated in the next (stamps on j's clock; a
  // repeat's age travels in 0.1 ms steps).
  const auto queue = [&](int64_t age_ns, const Eigen::Vector3d& p_bi, const Eigen::Matrix3d& cov,
                         bool repeated) {
    constexpr int64_t kTolerance = net::kPastObservationAgeStepNs / 2 + 1;
    const int64_t remote_stamp_ns = received.stamp_ns - age_ns;
    for (int64_t t : info.taken_observation_stamps) {
      if (std::abs(t - remote_stamp_ns) <= kTolerance) {
        ++to_.counters->repeats_duplicate;
        return;
      }
    }
    info.taken_observation_stamps.push_back(remote_stamp_ns);
    constexpr size_t kKeep = 16;
    while (info.taken_observation_stamps.size() > kKeep) info.taken_observation_stamps.pop_front();
    PendingPassive p;
    p.from = m.sender_id;
    p.repeated = repeated;
    p.stamp_ns = m.stamp_ns - age_ns;
    p.p_bi_in_bj = p_bi;
    p.cov = cov;
    p.sender = m;
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
    to_.passive->Queue(std::move(p));
  };
  for (const net::CurrentObservation& o : m.observations) {
    if (o.observed_id == self_id_ && o.p_bk_in_bj.allFinite() && o.cov_p_bk_in_bj.allFinite()) {
      queue(0, o.p_bk_in_bj, o.cov_p_bk_in_bj, false);
    }
  }
  for (const net::PastObservation& o : m.past_observations) {
    if (o.observed_id == self_id_ && o.age_ns > 0 && o.p_bk_in_Gj.allFinite() &&
        o.cov_p_bk_in_Gj.allFinite()) {
      queue(o.age_ns, o.p_bk_in_Gj, o.cov_p_bk_in_Gj, true);
    }
  }
}

}  // namespace swarmlio::swarm::internal
