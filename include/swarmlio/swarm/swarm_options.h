// Options of the swarm layer of one drone (swarm::DroneEstimator): YAML
// section `swarm` of a drone entry. docs/swarm.md explains each policy.
#pragma once

#include <array>
#include <cmath>
#include <string>
#include <utility>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/net/clock_sync.h"
#include "swarmlio/swarm/broadcast_budget.h"

namespace swarmlio::swarm {

/// What the update does with the extrinsic blocks when the last scan was
/// LiDAR-degenerate (docs/swarm.md "Degeneracy").
enum class DegeneracyPolicy {
  kConsiderExtrinsics,  // do not correct T_Gi_Gj, but its covariance enters the gain
                        // (Schmidt-Kalman consider states; docs/esikf.md)
  kFreezeExtrinsics,    // Swarm-LIO2: hold T_Gi_Gj as exact constants, trust the teammates
                        // (the observations constrain the ego state only)
  kEstimateAll,         // keep estimating T_Gi_Gj
};

/// Which observations a drone sends again in its next state message, for
/// receivers that lost the message that carried them (docs/swarm.md
/// "Repeated observations").
enum class RepeatObservations {
  kNone,
  kDegenerateTeammates,  // of teammates whose last message reported a degenerate scan:
                         // they depend on them (skip_degenerate_teammates)
  kAll,
};

}  // namespace swarmlio::swarm

namespace swarmlio::config {
template <>
struct EnumTraits<swarm::DegeneracyPolicy> {
  static constexpr std::array<std::pair<swarm::DegeneracyPolicy, const char*>, 3> kNames{{
      {swarm::DegeneracyPolicy::kConsiderExtrinsics, "consider_extrinsics"},
      {swarm::DegeneracyPolicy::kFreezeExtrinsics, "freeze_extrinsics"},
      {swarm::DegeneracyPolicy::kEstimateAll, "estimate_all"},
  }};
};
template <>
struct EnumTraits<swarm::RepeatObservations> {
  static constexpr std::array<std::pair<swarm::RepeatObservations, const char*>, 3> kNames{{
      {swarm::RepeatObservations::kNone, "none"},
      {swarm::RepeatObservations::kDegenerateTeammates, "degenerate_teammates"},
      {swarm::RepeatObservations::kAll, "all"},
  }};
};
}  // namespace swarmlio::config

namespace swarmlio::swarm {

struct SwarmOptions {
  /// Fuse active observations (I see j) in the update.
  bool fuse_active = true;
  /// Fuse passive observations (j saw me, from j's messages).
  bool fuse_passive = true;
  /// Fuse each teammate's broadcast gravity (GlobalExtrinsic message, once
  /// per message) with the own: R_Gi_Gj g_in_Gj = g_in_Gi fixes the tilt of
  /// T_Gi_Gj (docs/swarm.md "Gravity alignment").
  bool fuse_gravity = true;
  /// 1-sigma added to the teammate's gravity covariance per component: the
  /// same estimate comes back with every broadcast, its error correlated in
  /// time [m/s^2] (0.02 m/s^2 ~ 0.12 deg of tilt).
  double gravity_alignment_sigma_m_s2 = 0.02;
  /// Each mutual observation is fused twice in the swarm: actively by the
  /// drone that made it and passively by the drone it saw. Each use takes
  /// this share of its information (observation covariance / share), so that
  /// the two filters together count the measurement about once when their
  /// estimates meet again through later messages (information splitting, as
  /// in split covariance intersection). 1 = both uses at full weight (the
  /// paper). A drone whose last scan was degenerate uses 1: its teammates
  /// skip observations involving it (skip_degenerate_teammates). docs/swarm.md
  /// "Information sharing".
  double observation_information_share = 0.5;
  /// Passive observations shift the own position by v (t_j - t_k); active
  /// ones predict j's broadcast state to the update time with its velocity
  /// and angular rate. Off: both taken as if made at the update time.
  bool time_compensation = true;
  /// Estimate each teammate's clock offset from TimeSync exchanges (NTP-style,
  /// net/clock_sync.h) and map every stamp it sends onto the own clock; a
  /// teammate's states are not used before its offset is known (about one
  /// burst, burst_requests x burst_period_s). Off: remote stamps are taken as
  /// own-clock stamps (clocks synchronised outside, e.g. by PTP or chrony).
  bool synchronize_clocks = true;
  net::ClockSyncOptions clock_sync;
  /// Teammate messages older than this at the update time are not used [s].
  double max_message_age_s = 0.5;
  /// A teammate neither seen nor heard for this long leaves the state [s].
  double teammate_timeout_s = 10.0;
  /// Initial T_Gi_Gj covariance from a trajectory match: 1-sigma translation
  /// = max(this floor, translation_sigma_per_residual x mean residual) [m] ...
  double init_translation_sigma_floor_m = 0.05;
  double init_translation_sigma_per_residual = 3.0;
  /// ... and rotation = max(floor, translation sigma / excitation extent) [rad].
  double init_rotation_sigma_floor_rad = 1.0 * M_PI / 180.0;
  /// Observations farther than this many sigma from the prediction are
  /// rejected before the update (chi-square gate on 3 dof; 0 = off).
  double gate_sigma = 5.0;
  /// Per-teammate scale of the active observation covariance from the
  /// innovations (docs/swarm.md "Observation noise from the innovations"):
  /// the weight of each observation in the scale's update (0 = off), and the
  /// scale's range.
  double noise_adaptation_rate = 0.0;
  double min_noise_scale = 0.5;
  double max_noise_scale = 10.0;
  DegeneracyPolicy degeneracy_policy = DegeneracyPolicy::kConsiderExtrinsics;
  /// Observations that involve a teammate whose last message says its scan
  /// was degenerate are not fused while this drone's own last scan was not
  /// degenerate (the teammate's pose is not to be trusted by a drone that
  /// does not need it; a degenerate drone still fuses them).
  bool skip_degenerate_teammates = true;
  /// Observations sent again, in G_j, with the next state message: a
  /// receiver that lost the first message still fuses them (15 B each on
  /// the wire; docs/swarm.md "Repeated observations").
  RepeatObservations repeat_observations = RepeatObservations::kDegenerateTeammates;
  /// A teammate j that identified this drone (and sent its T_Gj_Gi) is
  /// added here with the inverse, without waiting for an own match
  /// (docs/swarm.md "Mutual identification").
  bool mutual_identification = true;
  /// A teammate k that a known teammate j identified itself (its broadcast
  /// T_Gj_Gk from a trajectory match) is added through T_Gi_Gj T_Gj_Gk
  /// without an own match (docs/swarm.md "Identification through teammates").
  bool graph_identification = true;
  /// A teammate j that was itself added through the graph may serve as the
  /// intermediary of the identification through teammates once its block no
  /// longer leans on the teammates it came through: each of them left the
  /// state or restarted (new session), or graph_derived_min_observations own
  /// observations of j were fused into its block (docs/swarm.md
  /// "Identification through teammates"). Off: only first-hand teammates.
  bool graph_through_derived = true;
  /// Own active and passive observations of a graph-derived teammate fused
  /// into its block before it may serve as an intermediary while the
  /// teammates it came through are still in the state [count].
  int graph_derived_min_observations = 20;
  /// A teammate's block that came from a teammate (its T_Gj_Gi inverted, or
  /// composed through the graph) follows that source's newer estimates until
  /// this many own observations were fused into it (docs/swarm.md "Second-hand
  /// blocks follow their source"); 0 = never (the block keeps its first value).
  int follow_source_until_observations = 20;
  /// The own T_Gi_Gj estimates are broadcast this often (0 = never) [s];
  /// new ones at once. Entries per broadcast: broadcast_budget.
  double extrinsic_broadcast_period_s = 1.0;
  /// This drone's airframe (DroneEstimatorOptions::airframe) is announced to
  /// the teammates with the first scan's messages and then this often, on
  /// the own clock (0 = never: teammates detect it with their own defaults).
  /// 78 B on the wire each, within the byte budget (broadcast_budget.h) [s].
  double airframe_period_s = 2.0;
  /// The bytes this drone puts on the wire: a budget shared by the optional
  /// content of its messages (docs/swarm.md "Broadcast budget").
  BroadcastBudgetOptions broadcast_budget;
  /// Radius of the ball around each tracked object kept out of the map [m].
  double map_exclusion_radius_m = 0.5;

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("fuse_active", fuse_active, FieldSpec::Doc("fuse active observations (I see teammate j)"));
    v("fuse_passive", fuse_passive, FieldSpec::Doc("fuse passive observations (j saw me)"));
    v("fuse_gravity", fuse_gravity,
      FieldSpec::Doc("fuse the teammates' broadcast gravity with the own (tilt of T_Gi_Gj)"));
    v("synchronize_clocks", synchronize_clocks,
      FieldSpec::Doc(
          "estimate teammates' clock offsets online and map their stamps to the own clock"));
    v("clock_sync", clock_sync, FieldSpec::Doc("clock synchronisation (docs/network.md)"));
    v("teammate_timeout_s", teammate_timeout_s,
      FieldSpec::Positive("s", "unseen and unheard this long: removed from the state"));
    v("extrinsic_broadcast_period_s", extrinsic_broadcast_period_s,
      FieldSpec::AtLeast(0.0, "s", "broadcast the own T_Gi_Gj estimates this often (0 = never)"));
    v("broadcast_budget", broadcast_budget,
      FieldSpec::Doc("bytes on the wire per second and how the optional content shares them"));
    v("map_exclusion_radius_m", map_exclusion_radius_m,
      FieldSpec::Positive("m", "points this close to a tracked object stay out of the map"));
    config::VisitExperimental(v, [&](auto& x) {
      x("gravity_alignment_sigma_m_s2", gravity_alignment_sigma_m_s2,
        FieldSpec::Positive("m/s^2", "1-sigma added to a teammate's gravity covariance"));
      x("observation_information_share", observation_information_share,
        FieldSpec::InRange(
            0.01, 1.0, "",
            "share of a mutual observation's information per use (active, passive)"));
      x("time_compensation", time_compensation,
        FieldSpec::Doc("predict teammate states / shift passive observations to the update time"));
      x("max_message_age_s", max_message_age_s,
        FieldSpec::Positive("s", "teammate messages older than this are not used"));
      x("init_translation_sigma_floor_m", init_translation_sigma_floor_m,
        FieldSpec::Positive("m", "smallest initial 1-sigma of p_Gj_in_Gi"));
      x("init_translation_sigma_per_residual", init_translation_sigma_per_residual,
        FieldSpec::Positive("", "initial 1-sigma of p_Gj_in_Gi per metre of match residual"));
      x("init_rotation_sigma_floor_rad", init_rotation_sigma_floor_rad,
        FieldSpec::Positive("rad", "smallest initial 1-sigma of R_Gi_Gj"));
      x("gate_sigma", gate_sigma, FieldSpec::AtLeast(0.0, "", "Mahalanobis gate (0 = off)"));
      x("noise_adaptation_rate", noise_adaptation_rate,
        FieldSpec::InRange(0.0, 1.0, "",
                           "weight of each innovation in the per-teammate observation noise "
                           "scale (0 = off)"));
      x("min_noise_scale", min_noise_scale,
        FieldSpec::Positive("", "smallest per-teammate observation noise scale"));
      x("max_noise_scale", max_noise_scale,
        FieldSpec::Positive("", "largest per-teammate observation noise scale"));
      x("degeneracy_policy", degeneracy_policy,
        FieldSpec::Doc("consider_extrinsics | freeze_extrinsics | estimate_all, after a "
                       "degenerate scan"));
      x("skip_degenerate_teammates", skip_degenerate_teammates,
        FieldSpec::Doc("do not fuse observations involving a teammate that reports degeneracy"));
      x("repeat_observations", repeat_observations,
        FieldSpec::Doc(
            "none | degenerate_teammates | all: observations sent again with the next state"));
      x("mutual_identification", mutual_identification,
        FieldSpec::Doc(
            "add a teammate that identified this drone, with the inverse of its T_Gj_Gi"));
      x("graph_identification", graph_identification,
        FieldSpec::Doc("add a teammate that a known teammate identified, through its T_Gj_Gk"));
      x("graph_through_derived", graph_through_derived,
        FieldSpec::Doc(
            "a graph-derived teammate may relay once the teammates it came through left or "
            "its block was fused graph_derived_min_observations times"));
      x("graph_derived_min_observations", graph_derived_min_observations,
        FieldSpec::AtLeast(
            0, "", "own observations fused into a graph-derived block before it may relay"));
      x("follow_source_until_observations", follow_source_until_observations,
        FieldSpec::AtLeast(0, "",
                           "a second-hand block follows its source's newer estimates until this "
                           "many own observations were fused (0 = never)"));
      x("airframe_period_s", airframe_period_s,
        FieldSpec::InRange(0.0, 3600.0, "s", "announce the own airframe this often (0 = never)"));
    });
  }
  std::string Validate() const {
    std::string error = config::ValidateFields(*this);
    if (error.empty() && min_noise_scale > max_noise_scale) {
      error = "min_noise_scale: must not exceed max_noise_scale";
    }
    return error;
  }
};

}  // namespace swarmlio::swarm
