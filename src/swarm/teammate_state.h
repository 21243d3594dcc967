// What one drone knows of each teammate from its messages (swarm::
// DroneEstimator, docs/swarm.md): the newest broadcast state and its session,
// when it was last heard and seen, the passive observations and the mutual
// identification waiting for the next scan, and the few operations on them.
// Internal to src/swarm.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <map>

#include "swarmlio/common/time.h"
#include "swarmlio/net/messages.h"
#include "swarmlio/state/swarm_state.h"
#include "swarmlio/swarm/swarm_options.h"

namespace swarmlio::swarm::internal {

/// The message is finite in every field the estimator uses.
bool Finite(const net::EgoStateMessage& m);

/// Teammate j's own trajectory match of its teammate k, from j's
/// GlobalExtrinsicMessage entry about k (named by frames at the inbox).
struct TeammateMatch {
  GlobalExtrinsic T_Gj_Gk;  // its rotation normalized at the inbox
  /// Covariance of [dtheta (rad); dp (m)], R_Gj_Gk = R^ Exp(dtheta), as sent.
  Eigen::Matrix<double, 6, 6> cov_T_Gj_Gk = Eigen::Matrix<double, 6, 6>::Zero();
};

struct TeammateInfo {
  bool have_message = false;
  net::EgoStateMessage last;       // the newest received state
  int64_t session_start_ns = 0;
  int64_t last_heard_ns = 0;       // arrival of the newest message (own clock)
  int64_t last_seen_ns = 0;        // last LiDAR observation (own clock)
  bool restarted = false;          // session_start changed: drop its block
  // Arrival (own clock) of the first message of its current session when it
  // restarted (0: its first session): the other teammates' T_Gk_Gj about it
  // made before this + max_message_age_s are of its old G_j.
  int64_t session_heard_ns = 0;
  bool via_graph = false;          // its block came through a teammate's T_Gj_Gk
  bool second_hand = false;        // its block came from a teammate (mutual or graph)
  // Provenance of a derived block (via_graph): the teammates whose frames its
  // chain T_Gi_Gv ... T_Gw_Gj may pass through, each with the session it was
  // in then (id -> session_start_ns). Empty for a first-hand block.
  std::map<int, int64_t> derived_through;
  // Own active and passive observations fused into its block since it was added.
  int observations_fused = 0;
  // Scale of its active observations' covariance from the innovations
  // (innovation_noise_scale.h); 1 while noise_adaptation_rate is 0.
  double observation_noise_scale = 1.0;
  // j's clock stamps of the observations of this drone already taken (j
  // repeats observations, SwarmOptions::repeat_observations): the newest few.
  std::deque<int64_t> taken_observation_stamps;
  // j's own trajectory matches T_Gj_Gk, by k (from its GlobalExtrinsic
  // broadcasts; kTrajectoryMatch entries only: j's derived edges are never
  // composed here, j cannot tell through whom it derived them).
  std::map<int, TeammateMatch> identified;
};

using Teammates = std::map<int, TeammateInfo>;

/// A block was just added for this teammate: where it came from (from a
/// teammate at all: `second_hand`; through the graph, with a derived block's
/// chain: the teammates it may pass through, with their sessions; a
/// first-hand one: none) and no own observations in it yet.
void SetProvenance(bool second_hand, bool via_graph, std::map<int, int64_t> derived_through,
                   TeammateInfo* info);

/// The session a teammate is in now, as far as its messages told (0: none heard).
int64_t SessionOf(const Teammates& teammates, int id);

/// Every teammate heard so far but `except`, with its current session: the
/// chain of the inverse of j's own derived entry, which j does not name (it
/// composed it through teammates it had, and they broadcast too).
std::map<int, int64_t> HeardTeammates(const Teammates& teammates, int except);

/// j's derived block still hangs on a block of this state it was composed
/// from: a teammate its chain passes through is in the state, in the session
/// the chain used.
bool LeansOnTeammates(const TeammateInfo& info_j, const SwarmState& x, const Teammates& teammates);

/// Whether j's block may be composed with j's own matches T_Gj_Gk (the
/// identification through teammates): a first-hand block always; a derived
/// one (SwarmOptions::graph_through_derived) when it no longer leans on the
/// teammates it came through, or when
/// graph_derived_min_observations own observations of j were fused into it.
bool CanRelay(const TeammateInfo& info_j, const SwarmState& x, const Teammates& teammates,
              const SwarmOptions& options);

/// j's chain passes through k's current frame: T_Gi_Gj T_Gj_Gk would close a
/// loop (k's own edge counted twice, as if independent). A k that restarted
/// since has a new frame, which the chain never used.
bool ChainPassesThrough(const TeammateInfo& info_j, int k, const Teammates& teammates);

// A teammate's broadcast state predicted to time t (own clock).
struct PredictedTeammate {
  Eigen::Matrix3d R_Gj_bj;
  Eigen::Vector3d p_bj_in_Gj;
  Eigen::Vector3d v_bj_in_Gj;
  Eigen::Matrix3d cov_p;
  Eigen::Matrix3d cov_theta;
};

/// j's broadcast state moved by dt [s] with its velocity and angular rate
/// (covariance: position + dt^2 velocity).
PredictedTeammate Predict(const net::EgoStateMessage& m, double dt);

/// T_Gi_Gk = T_Gi_Gj T_Gj_Gk and the Jacobians of its error [dphi; dp]
/// (R = R^ Exp(dphi), p = p^ + dp) with respect to the errors of T_Gi_Gj
/// (J_ij) and of T_Gj_Gk (J_jk):
///   dphi_ik = R_jk^T dphi_ij + dphi_jk
///   dp_ik   = dp_ij - R_ij [p_Gk_in_Gj]x dphi_ij + R_ij dp_jk
void ComposeExtrinsic(const GlobalExtrinsic& T_ij, const GlobalExtrinsic& T_jk, GlobalExtrinsic* T_ik,
                      Eigen::Matrix<double, 6, 6>* J_ij, Eigen::Matrix<double, 6, 6>* J_jk);

struct PendingPassive {
  int from = -1;
  bool repeated = false;  // a past observation: p_bi_in_bj is in G_j, sender at identity
  int64_t stamp_ns = 0;  // when j saw this drone (j's scan end, assumed own clock)
  Eigen::Vector3d p_bi_in_bj = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
  net::EgoStateMessage sender;  // j's state at that time
};

// A teammate j's T_Gj_Gi (it identified this drone), waiting for the next
// scan: its GlobalExtrinsicMessage entry about this drone, named by frames at
// the inbox.
struct PendingMutual {
  GlobalExtrinsic T_Gj_Gi;  // its rotation normalized at the inbox
  // Covariance of [dtheta (rad); dp (m)], R_Gj_Gi = R^ Exp(dtheta), as sent.
  Eigen::Matrix<double, 6, 6> cov_T_Gj_Gi = Eigen::Matrix<double, 6, 6>::Zero();
  net::ExtrinsicSource source = net::ExtrinsicSource::kTrajectoryMatch;  // how j got it
};

// T_Gi_Gj = T_Gj_Gi^-1 with the covariance mapped to the inverse's error
// state (R Exp(theta), p + dp): theta' = -R theta, dp' = [p']x theta - R^T dp.
// T_Gj_Gi's rotation must be unit (PendingMutual's is).
void InvertExtrinsic(const GlobalExtrinsic& T_Gj_Gi,
                     const Eigen::Matrix<double, 6, 6>& cov_T_Gj_Gi,
                     GlobalExtrinsic* T_Gi_Gj,
                     Eigen::Matrix<double, 6, 6>* cov_T_Gi_Gj);

}  // namespace swarmlio::swarm::internal
