// Inter-drone messages (plain values; SI units; frames in the names, see
// docs/conventions.md). Wire encoding and sizes: docs/network.md.
//
// The codec quantizes (wire version 7, docs/network.md §2.1): stamps exact,
// positions float32, quaternions as smallest-three int16 codes, rates
// float16, observation positions in 2 mm steps, ages of past observations
// in 0.1 ms steps, airframe lengths in 1 mm steps, covariances as 8-bit log
// variances and partial correlations. Decoding gives each field back within
// that precision; the encoder reads only the upper triangle of a covariance,
// and decoded covariances are symmetric positive definite.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <variant>
#include <vector>

namespace swarmlio::net {

enum class MessageType : uint8_t {
  kEgoState = 1,
  kGlobalExtrinsic = 2,
  kTimeSync = 3,
  kAirframe = 4,
};

const char* MessageTypeName(MessageType type);

/// Sender j saw teammate k (LiDAR cluster of k's reflective tape) in the scan
/// this message's state ends: the wire form of teammate::TeammateObservation
/// in EgoStateMessage::observations (PastObservation: an earlier scan's).
struct CurrentObservation {
  int observed_id = 0;                                   // k
  Eigen::Vector3d p_bk_in_bj = Eigen::Vector3d::Zero();  // k's body origin in j's body frame [m]
  Eigen::Matrix3d cov_p_bk_in_bj = Eigen::Matrix3d::Zero();  // its covariance [m^2]
};

/// An observation sender j made at an earlier scan, sent again so that a
/// receiver that lost that scan's message still gets it (repetition against
/// loss, docs/swarm.md "Repeated observations"). It carries no sender pose:
/// k's position is given in G_j, its covariance includes j's pose
/// uncertainty at that scan.
struct PastObservation {
  int observed_id = 0;                                       // k
  int64_t age_ns = 0;  // stamp_ns of the message - the observation's scan end, > 0 [ns]
  Eigen::Vector3d p_bk_in_Gj = Eigen::Vector3d::Zero();      // [m]
  Eigen::Matrix3d cov_p_bk_in_Gj = Eigen::Matrix3d::Zero();  // [m^2]
};

/// A teammate k's state that drone j received, echoed back in j's next
/// state so that k gets a four-timestamp clock exchange out of the two
/// broadcasts (docs/network.md, "Clock synchronisation"): k sent it at
/// t1 = k's stamp + send_delay_ns (k's clock), it arrived at j at
/// t2 = arrival_ns, j's state left at t3 = j's stamp + j's send_delay_ns (both
/// j's clock), and k stamps t4 when j's state arrives.
struct StateEcho {
  int teammate_id = 0;       // k
  uint16_t stamp_ref = 0;    // StateEchoRef(k's stamp_ns): which of k's states
  int64_t send_delay_ns = 0; // that state's send delay as k sent it [ns]
  int64_t arrival_ns = 0;    // when it arrived at j (j's clock) [ns]
};

/// Drone j's own estimate of teammate k's clock offset (k's clock - j's
/// clock) at j's state stamp, for k to fuse with its own estimate of j's
/// (wire version 6; docs/network.md "Both ends of a pair"). It travels as a
/// residue modulo 65.536 ms: k resolves it against its own estimate, which
/// agrees with it to a few milliseconds once both have converged.
struct ClockOffsetReport {
  static constexpr int kMaxStdCode = 254;
  int teammate_id = 0;          // k
  uint16_t offset_residue = 0;  // round(offset / kOffsetReportStepNs) mod 2^16
  int std_code = 1;             // the estimate's std in kOffsetReportStdStepNs, 1..kMaxStdCode
};

/// The reference a StateEcho carries for a state stamped `stamp_ns`: its
/// stamp in whole milliseconds modulo 2^16 (unique over 65 s of states).
inline uint16_t StateEchoRef(int64_t stamp_ns) {
  const int64_t ms = stamp_ns / 1000000 - (stamp_ns % 1000000 < 0 ? 1 : 0);  // floor
  return static_cast<uint16_t>(static_cast<uint64_t>(ms) & 0xFFFFu);
}

/// Drone j's ego state at `stamp_ns` (j's clock), sent after every scan.
/// The covariance blocks are the ones a receiver k needs for the active and
/// passive observation terms and for propagating j to k's scan time with
/// constant velocity + gyro: rotation, position and velocity marginals (the
/// diagonal 3x3 blocks of j's error-state covariance; cross blocks are not
/// sent, see docs/network.md).
struct EgoStateMessage {
  /// Upper bound on observations per message (keeps the packet <= 1200 B).
  static constexpr int kMaxObservations = 24;
  /// Upper bound on past observations per message.
  static constexpr int kMaxPastObservations = 24;
  /// Upper bound on echoed teammate states per message.
  static constexpr int kMaxEchoes = 8;

  int sender_id = 0;             // j
  int64_t stamp_ns = 0;          // state time, j's clock [ns]
  int64_t session_start_ns = 0;  // j's estimator start time, j's clock [ns]; a change
                                 // means j rebooted (drop its tracker and extrinsic)
  Eigen::Quaterniond q_Gj_bj = Eigen::Quaterniond::Identity();  // attitude (unit)
  Eigen::Vector3d p_bj_in_Gj = Eigen::Vector3d::Zero();         // [m]
  Eigen::Vector3d v_bj_in_Gj = Eigen::Vector3d::Zero();         // [m/s]
  Eigen::Vector3d omega_bj_in_bj = Eigen::Vector3d::Zero();     // unbiased gyro [rad/s]
  Eigen::Matrix3d cov_theta_Gj_bj = Eigen::Matrix3d::Zero();    // R = R^ Exp(dtheta) [rad^2]
  Eigen::Matrix3d cov_p_bj_in_Gj = Eigen::Matrix3d::Zero();     // [m^2]
  Eigen::Matrix3d cov_v_bj_in_Gj = Eigen::Matrix3d::Zero();     // [m^2/s^2]
  bool degenerated = false;                        // j's last scan was LiDAR-degenerate
  std::vector<CurrentObservation> observations;    // distinct ids, none == sender_id
  std::vector<PastObservation> past_observations;  // distinct ids, none == sender_id
  /// When the packet left j: stamp_ns + send_delay_ns (j's clock); -1 = not
  /// known. MessageChannel::Send sets it from its now_ns (wire version 5).
  int64_t send_delay_ns = -1;
  /// Teammates' states j received, echoed for their clock synchronisation
  /// (distinct ids, none == sender_id; only with send_delay_ns >= 0).
  std::vector<StateEcho> echoes;
  /// At most one of j's offset estimates (only with send_delay_ns >= 0).
  std::optional<ClockOffsetReport> offset_report;
};

/// How the sender obtained a global extrinsic.
enum class ExtrinsicSource : uint8_t {
  kTrajectoryMatch = 1,  // its own tracker-vs-odometry trajectory match
  kGraph = 2,            // derived through the extrinsic graph
};

/// The sender's estimate of T_Ga_Gb for one teammate: a is the sender
/// (GlobalExtrinsicMessage::sender_id), b is teammate_id. Neutral names
/// because the frames are the sender's: a receiver names them once, where it
/// stores the entry (src/swarm/message_inbox.cc: T_Gj_Gk, or T_Gj_Gi when b
/// is the receiver itself).
struct GlobalExtrinsicEntry {
  int teammate_id = 0;  // b
  ExtrinsicSource source = ExtrinsicSource::kTrajectoryMatch;
  Eigen::Quaterniond q_Ga_Gb = Eigen::Quaterniond::Identity();  // unit
  Eigen::Vector3d p_Gb_in_Ga = Eigen::Vector3d::Zero();         // [m]
  /// Covariance of [dtheta (rad); dp (m)], R_Ga_Gb = R^ Exp(dtheta) (the
  /// teammate block order of ErrorStateLayout). Full 6x6: rotation and
  /// translation of a trajectory match are strongly correlated.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
};

/// Drone i's known global extrinsics. A sender with more entries than
/// kMaxEntries splits them over several messages (each is self-contained).
struct GlobalExtrinsicMessage {
  static constexpr int kMaxEntries = 8;

  int sender_id = 0;                          // i
  int64_t stamp_ns = 0;                       // i's clock [ns]
  /// i's gravity estimate in its own global frame and its covariance: with
  /// the receiver's, it fixes the tilt of T_Gi_Gj (docs/swarm.md, "Gravity
  /// alignment"). Sent in every split message.
  Eigen::Vector3d g_in_Gi = Eigen::Vector3d::Zero();          // [m/s^2]
  Eigen::Matrix3d cov_g_in_Gi = Eigen::Matrix3d::Zero();      // [m^2/s^4]
  std::vector<GlobalExtrinsicEntry> entries;  // distinct ids, none == sender_id
};

/// NTP-style four-timestamp clock sync. The requester sends a request with
/// t1; the responder answers with t1 echoed, t2 (request receipt) and t3
/// (response send) on its clock; the requester notes t4 on receipt and
/// computes offset = ((t2 - t1) + (t3 - t4)) / 2.
struct TimeSyncMessage {
  int sender_id = 0;
  int target_id = 0;  // the drone this request or response is for
  bool is_response = false;
  int64_t t1_ns = 0;  // request send time, requester clock
  int64_t t2_ns = 0;  // request receipt, responder clock (0 in a request)
  int64_t t3_ns = 0;  // response send, responder clock (0 in a request)
};

/// Drone j's own airframe, the wire form of teammate::AirframeDescription
/// (teammate/airframe.h has the meaning of each field), sent every few
/// seconds (swarm.experimental.airframe_period_s): what a teammate needs to
/// detect j and to place j's body origin behind the returns it sees
/// (docs/teammate.md "Airframes"). Lengths travel in millimetre steps.
struct AirframeMessage {
  int sender_id = 0;
  int64_t stamp_ns = 0;        // j's clock [ns]
  int reflector_shape = 0;     // teammate::ReflectorShape as its integer, 0..2
  Eigen::Vector3d reflector_half_extents_m = Eigen::Vector3d::Zero();    // [m], >= 0
  Eigen::Vector3d reflector_centre_in_body_m = Eigen::Vector3d::Zero();  // [m]
  double depth_offset_m = 0.0;    // [m]
  double size_m = 0.0;            // [m]
  double min_intensity = 0.0;     // Livox 0-255
  double centroid_sigma_m = 0.0;  // [m]
};

using SwarmMessage =
    std::variant<EgoStateMessage, GlobalExtrinsicMessage, TimeSyncMessage, AirframeMessage>;

MessageType TypeOf(const SwarmMessage& message);
int SenderOf(const SwarmMessage& message);

/// Splits `entries` into messages of at most kMaxEntries entries each (at
/// least one message, possibly empty), all with the same sender and stamp.
std::vector<GlobalExtrinsicMessage> SplitGlobalExtrinsics(
    int sender_id, int64_t stamp_ns, const std::vector<GlobalExtrinsicEntry>& entries,
    const Eigen::Vector3d& g_in_Gi = Eigen::Vector3d::Zero(),
    const Eigen::Matrix3d& cov_g_in_Gi = Eigen::Matrix3d::Zero());

}  // namespace swarmlio::net
