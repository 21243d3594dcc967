// CheckMessage: the semantic rules shared by Encode and Decode.
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "src/net/covariance_codec.h"
#include "src/net/half_float.h"
#include "swarmlio/net/packet_codec.h"
#include "swarmlio/net/swarm_limits.h"
#include "swarmlio/net/wire_format.h"

namespace swarmlio::net {
namespace {

// |norm - 1| bound for a unit quaternion handed to the encoder (it sends the
// normalized one; decoded quaternions are unit to 1e-15).
constexpr double kUnitQuaternionTolerance = 1e-3;
// stamp_ns - session_start_ns travels as a 48-bit signed integer.
constexpr int64_t kMaxSessionOffsetNs = (int64_t{1} << 47) - 1;

/// Collects the first violated rule. Field names are `const char*` plus an
/// optional index and the current list-entry context; the text is built only
/// when a rule fails (this runs for every packet sent and received).
class Checker {
 public:
  explicit Checker(const char* type) : type_(type) {}

  bool ok() const { return error_.empty(); }
  Status status() const {
    return ok() ? Status::Ok() : Status::InvalidArgument(std::string(type_) + ": " + error_);
  }

  /// Prefix for the following fields, e.g. "observations[2]." ("" to clear).
  void SetContext(std::string context) { context_ = std::move(context); }

  void Fail(const char* field, int index, const std::string& reason) {
    if (!ok()) return;
    error_ = "field '" + context_ + field;
    if (index >= 0) error_ += "[" + std::to_string(index) + "]";
    error_ += "' " + reason;
  }

  void Id(const char* field, int id) {
    if (!IsValidDroneId(id)) {
      Fail(field, -1,
           "= " + std::to_string(id) + " is not a drone id (0.." +
               std::to_string(kMaxSwarmSize - 1) + ")");
    }
  }
  void Stamp(const char* field, int64_t stamp_ns) {
    if (stamp_ns < 0) Fail(field, -1, "is negative");
  }
  /// Both stamps >= 0 (checked before), their difference within the 48-bit field.
  void SessionOffset(int64_t stamp_ns, int64_t session_start_ns) {
    if (!ok()) return;
    const int64_t offset = stamp_ns - session_start_ns;  // no overflow: both >= 0
    if (offset > kMaxSessionOffsetNs || offset < -kMaxSessionOffsetNs) {
      Fail("session_start_ns", -1,
           "is more than 2^47 ns (39 h) from stamp_ns (stamp_ns - session_start_ns = " +
               std::to_string(offset) + " travels in 48 bits)");
    }
  }
  /// Finite and representable as a float32 (it travels as one).
  void F32(const char* field, int index, double v) {
    if (!std::isfinite(v) || std::abs(v) > std::numeric_limits<float>::max()) {
      Fail(field, index, "is not a finite float32");
    }
  }
  void Vector32(const char* field, const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) F32(field, i, v[i]);
  }
  /// Finite and within the float16 range (|v| <= 65504 after rounding).
  void Vector16(const char* field, const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) {
      if (!internal::FitsHalf(v[i])) {
        Fail(field, i,
             "is not a finite float16 (|x| <= " + std::to_string(internal::kHalfMax) + ")");
      }
    }
  }
  /// Finite and within the int16 range of the observation position code
  /// (the same division the writer rounds: |x / step| < 32767.5).
  void ObservationPosition(const char* field, const Eigen::Vector3d& v) {
    for (int i = 0; i < 3; ++i) {
      if (!std::isfinite(v[i]) ||
          !(std::abs(v[i] / kObservationPositionStepM) < kObservationPositionMaxCode + 0.5)) {
        Fail(field, i,
             "= " + std::to_string(v[i]) + " m is outside the wire range +-" +
                 std::to_string(kObservationPositionMaxM) + " m");
      }
    }
  }
  /// An airframe length in kAirframeLengthStepM codes: finite, and within
  /// [0, 65.535] m (uint16) or, `may_be_negative`, +-32.767 m (int16).
  void AirframeLength(const char* field, int index, double v, bool may_be_negative) {
    const double steps = v / kAirframeLengthStepM;
    const bool fits = may_be_negative ? std::abs(steps) < kAirframeCentreMaxCode + 0.5
                                      : steps >= 0.0 && steps < kAirframeLengthMaxCode + 0.5;
    if (!std::isfinite(v) || !fits) {
      const double max_m = (may_be_negative ? kAirframeCentreMaxCode : kAirframeLengthMaxCode) *
                           kAirframeLengthStepM;
      Fail(field, index,
           "= " + std::to_string(v) + " m is outside the wire range " +
               (may_be_negative ? "+-" + std::to_string(max_m)
                                : "[0, " + std::to_string(max_m) + "]") +
               " m");
    }
  }
  void UnitQuaternion(const char* field, const Eigen::Quaterniond& q) {
    const Eigen::Vector4d c = q.coeffs();
    for (int i = 0; i < 4; ++i) {
      if (!std::isfinite(c[i])) Fail(field, i, "is not finite");
    }
    if (ok() && std::abs(c.norm() - 1.0) > kUnitQuaternionTolerance) {
      Fail(field, -1, "is not a unit quaternion (norm " + std::to_string(c.norm()) + ")");
    }
  }
  /// Upper triangle finite, diagonal in [0, MaxEncodableVariance()].
  template <int N>
  void Covariance(const char* field, const Eigen::Matrix<double, N, N>& m) {
    for (int row = 0; row < N; ++row) {
      for (int col = row; col < N; ++col) {
        if (!std::isfinite(m(row, col))) {
          Fail(field, -1,
               "is not finite at (" + std::to_string(row) + "," + std::to_string(col) + ")");
        }
      }
      if (m(row, row) < 0.0) {
        Fail(
            field, -1,
            "has a negative variance at (" + std::to_string(row) + "," + std::to_string(row) + ")");
      }
      if (m(row, row) > internal::MaxEncodableVariance()) {
        Fail(field, -1,
             "has a variance above the wire range (" +
                 std::to_string(internal::MaxEncodableVariance()) + ") at (" + std::to_string(row) +
                 "," + std::to_string(row) + ")");
      }
    }
  }
  /// Teammate ids of one list: valid, not the sender, pairwise distinct.
  void TeammateId(const char* field, int id, int sender_id, uint64_t* seen) {
    Id(field, id);
    if (!ok()) return;
    if (id == sender_id) Fail(field, -1, "= " + std::to_string(id) + " is the sender itself");
    const uint64_t bit = uint64_t{1} << id;
    if (ok() && (*seen & bit) != 0) Fail(field, -1, "= " + std::to_string(id) + " is repeated");
    *seen |= bit;
  }

 private:
  const char* type_;
  std::string context_;
  std::string error_;
};

static_assert(kMaxSwarmSize <= 64, "TeammateId tracks ids in a 64-bit mask");

Status Check(const EgoStateMessage& m) {
  Checker c("EgoState");
  c.Id("sender_id", m.sender_id);
  c.Stamp("stamp_ns", m.stamp_ns);
  c.Stamp("session_start_ns", m.session_start_ns);
  c.SessionOffset(m.stamp_ns, m.session_start_ns);
  c.UnitQuaternion("q_Gj_bj", m.q_Gj_bj);
  c.Vector32("p_bj_in_Gj", m.p_bj_in_Gj);
  c.Vector16("v_bj_in_Gj", m.v_bj_in_Gj);
  c.Vector16("omega_bj_in_bj", m.omega_bj_in_bj);
  c.Covariance<3>("cov_theta_Gj_bj", m.cov_theta_Gj_bj);
  c.Covariance<3>("cov_p_bj_in_Gj", m.cov_p_bj_in_Gj);
  c.Covariance<3>("cov_v_bj_in_Gj", m.cov_v_bj_in_Gj);
  if (m.observations.size() > static_cast<size_t>(EgoStateMessage::kMaxObservations)) {
    c.Fail("observations", -1,
           "has " + std::to_string(m.observations.size()) + " entries, more than the maximum " +
               std::to_string(EgoStateMessage::kMaxObservations));
  }
  uint64_t seen = 0;
  for (size_t i = 0; i < m.observations.size() && c.ok(); ++i) {
    c.SetContext("observations[" + std::to_string(i) + "].");
    const CurrentObservation& o = m.observations[i];
    c.TeammateId("observed_id", o.observed_id, m.sender_id, &seen);
    c.ObservationPosition("p_bk_in_bj", o.p_bk_in_bj);
    c.Covariance<3>("cov_p_bk_in_bj", o.cov_p_bk_in_bj);
  }
  c.SetContext("");
  if (m.past_observations.size() > static_cast<size_t>(EgoStateMessage::kMaxPastObservations)) {
    c.Fail("past_observations", -1,
           "has " + std::to_string(m.past_observations.size()) +
               " entries, more than the maximum " +
               std::to_string(EgoStateMessage::kMaxPastObservations));
  }
  // Relative to the float32 position the receiver decodes (ego_state_codec.cc).
  const Eigen::Vector3d p_bj_sent = m.p_bj_in_Gj.cast<float>().cast<double>();
  uint64_t seen_past = 0;
  for (size_t i = 0; i < m.past_observations.size() && c.ok(); ++i) {
    c.SetContext("past_observations[" + std::to_string(i) + "].");
    const PastObservation& o = m.past_observations[i];
    c.TeammateId("observed_id", o.observed_id, m.sender_id, &seen_past);
    const int64_t code = o.age_ns < 0 ? -1 : PastObservationAgeCode(o.age_ns);
    if (code < 1 || code > kPastObservationAgeMaxCode) {
      c.Fail("age_ns", -1,
             "= " + std::to_string(o.age_ns) + " is outside the wire range [" +
                 std::to_string(kPastObservationAgeStepNs / 2) + ", " +
                 std::to_string(kPastObservationAgeMaxCode * kPastObservationAgeStepNs) + ") ns");
    }
    c.ObservationPosition("p_bk_in_Gj - p_bj_in_Gj", o.p_bk_in_Gj - p_bj_sent);
    c.Covariance<3>("cov_p_bk_in_Gj", o.cov_p_bk_in_Gj);
  }
  c.SetContext("");
  const auto delay_range = [](int max_code) {
    return "[0, " + std::to_string(max_code * kSyncDelayStepNs + kSyncDelayStepNs / 2) + ") ns";
  };
  if (m.send_delay_ns != -1 &&
      (m.send_delay_ns < 0 || SyncDelayCode(m.send_delay_ns) > kSendDelayMaxCode)) {
    c.Fail("send_delay_ns", -1,
           "= " + std::to_string(m.send_delay_ns) + " is neither -1 (not known) nor in " +
               delay_range(kSendDelayMaxCode));
  }
  if (m.echoes.size() > static_cast<size_t>(EgoStateMessage::kMaxEchoes)) {
    c.Fail("echoes", -1,
           "has " + std::to_string(m.echoes.size()) + " entries, more than the maximum " +
               std::to_string(EgoStateMessage::kMaxEchoes));
  }
  if (!m.echoes.empty() && m.send_delay_ns < 0 && c.ok()) {
    c.Fail("echoes", -1, "need a known send_delay_ns (the hold is relative to the send time)");
  }
  if (m.offset_report && c.ok()) {
    c.SetContext("offset_report.");
    if (m.send_delay_ns < 0) {
      c.Fail("offset_report", -1, "needs a known send_delay_ns");
    }
    uint64_t seen_report = 0;
    c.TeammateId("teammate_id", m.offset_report->teammate_id, m.sender_id, &seen_report);
    if (m.offset_report->std_code < 1 ||
        m.offset_report->std_code > ClockOffsetReport::kMaxStdCode) {
      c.Fail("std_code", -1,
             "= " + std::to_string(m.offset_report->std_code) + " is outside [1, " +
                 std::to_string(ClockOffsetReport::kMaxStdCode) + "]");
    }
    c.SetContext("");
  }
  uint64_t seen_echo = 0;
  for (size_t i = 0; i < m.echoes.size() && c.ok(); ++i) {
    c.SetContext("echoes[" + std::to_string(i) + "].");
    const StateEcho& e = m.echoes[i];
    c.TeammateId("teammate_id", e.teammate_id, m.sender_id, &seen_echo);
    if (e.send_delay_ns < 0 || SyncDelayCode(e.send_delay_ns) > kSendDelayMaxCode) {
      c.Fail(
          "send_delay_ns", -1,
          "= " + std::to_string(e.send_delay_ns) + " is outside " + delay_range(kSendDelayMaxCode));
    }
    int64_t hold_ns = 0;
    if (!StateEchoHoldNs(m.stamp_ns, m.send_delay_ns, e.arrival_ns, &hold_ns) || hold_ns < 0 ||
        SyncDelayCode(hold_ns) > kHoldMaxCode) {
      c.Fail("arrival_ns", -1,
             "= " + std::to_string(e.arrival_ns) + ": the hold (send time - arrival) is outside " +
                 delay_range(kHoldMaxCode));
    }
  }
  return c.status();
}

Status Check(const GlobalExtrinsicMessage& m) {
  Checker c("GlobalExtrinsic");
  c.Id("sender_id", m.sender_id);
  c.Stamp("stamp_ns", m.stamp_ns);
  c.Vector32("g_in_Gi", m.g_in_Gi);
  c.Covariance<3>("cov_g_in_Gi", m.cov_g_in_Gi);
  if (m.entries.size() > static_cast<size_t>(GlobalExtrinsicMessage::kMaxEntries)) {
    c.Fail("entries", -1,
           "has " + std::to_string(m.entries.size()) + " entries, more than the maximum " +
               std::to_string(GlobalExtrinsicMessage::kMaxEntries) +
               " (use SplitGlobalExtrinsics)");
  }
  uint64_t seen = 0;
  for (size_t i = 0; i < m.entries.size() && c.ok(); ++i) {
    c.SetContext("entries[" + std::to_string(i) + "].");
    const GlobalExtrinsicEntry& e = m.entries[i];
    c.TeammateId("teammate_id", e.teammate_id, m.sender_id, &seen);
    if (e.source != ExtrinsicSource::kTrajectoryMatch && e.source != ExtrinsicSource::kGraph) {
      c.Fail("source", -1, "has an unknown value");
    }
    c.UnitQuaternion("q_Ga_Gb", e.q_Ga_Gb);
    c.Vector32("p_Gb_in_Ga", e.p_Gb_in_Ga);
    c.Covariance<6>("covariance", e.covariance);
  }
  return c.status();
}

Status Check(const TimeSyncMessage& m) {
  Checker c("TimeSync");
  c.Id("sender_id", m.sender_id);
  c.Id("target_id", m.target_id);
  if (c.ok() && m.target_id == m.sender_id) c.Fail("target_id", -1, "is the sender itself");
  c.Stamp("t1_ns", m.t1_ns);
  c.Stamp("t2_ns", m.t2_ns);
  c.Stamp("t3_ns", m.t3_ns);
  if (!m.is_response && (m.t2_ns != 0 || m.t3_ns != 0)) {
    c.Fail("t2_ns", -1, "and t3_ns must be 0 in a request");
  }
  return c.status();
}

Status Check(const AirframeMessage& m) {
  Checker c("Airframe");
  c.Id("sender_id", m.sender_id);
  c.Stamp("stamp_ns", m.stamp_ns);
  if (m.reflector_shape < 0 || m.reflector_shape > kAirframeMaxShape) {
    c.Fail("reflector_shape", -1,
           "= " + std::to_string(m.reflector_shape) + " is not a shape (0 band, 1 box, 2 round)");
  }
  for (int i = 0; i < 3; ++i) {
    c.AirframeLength("reflector_half_extents_m", i, m.reflector_half_extents_m[i], false);
  }
  for (int i = 0; i < 3; ++i) {
    c.AirframeLength("reflector_centre_in_body_m", i, m.reflector_centre_in_body_m[i], true);
  }
  c.AirframeLength("depth_offset_m", -1, m.depth_offset_m, false);
  c.AirframeLength("size_m", -1, m.size_m, false);
  c.AirframeLength("centroid_sigma_m", -1, m.centroid_sigma_m, false);
  if (!(m.min_intensity >= 0.0 && m.min_intensity <= kAirframeMaxIntensity)) {
    c.Fail("min_intensity", -1,
           "= " + std::to_string(m.min_intensity) + " is outside [0, " +
               std::to_string(kAirframeMaxIntensity) + "]");
  }
  return c.status();
}

}  // namespace

Status CheckMessage(const SwarmMessage& message) {
  return std::visit([](const auto& m) { return Check(m); }, message);
}

}  // namespace swarmlio::net
