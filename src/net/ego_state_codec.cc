// EgoState payload (layout in swarmlio/net/wire_format.h).
#include <string>

#include "src/net/field_codec.h"
#include "src/net/payload_codecs.h"
#include "swarmlio/net/wire_format.h"

namespace swarmlio::net::internal {

namespace {
// The bits byte: quaternion largest index, degenerated, observation count.
constexpr uint8_t kDegeneratedFlag = 0x04;
constexpr int kCountShift = 3;

Status DecodeObservation(PacketReader* r, CurrentObservation* o) {
  uint8_t id = 0;
  SWARMLIO_RETURN_IF_ERROR(r->U8("observed_id", &id));
  o->observed_id = id;
  SWARMLIO_RETURN_IF_ERROR(
      ReadScaledVectorI16("p_bk_in_bj", kObservationPositionStepM, r, &o->p_bk_in_bj));
  return ReadCovariance<3>("cov_p_bk_in_bj", r, &o->cov_p_bk_in_bj);
}

/// The float32 position the receiver decodes: past observations travel
/// relative to it.
Eigen::Vector3d AsSentF32(const Eigen::Vector3d& v) { return v.cast<float>().cast<double>(); }

Status DecodePastObservation(const Eigen::Vector3d& p_bj_in_Gj, PacketReader* r,
                             PastObservation* o) {
  uint8_t id = 0;
  SWARMLIO_RETURN_IF_ERROR(r->U8("observed_id", &id));
  o->observed_id = id;
  uint16_t age = 0;
  SWARMLIO_RETURN_IF_ERROR(r->U16("age", &age));
  if (age == 0) return r->Invalid("age", -1, "is 0 (a past observation is older than the state)");
  o->age_ns = int64_t{age} * kPastObservationAgeStepNs;
  Eigen::Vector3d relative;
  SWARMLIO_RETURN_IF_ERROR(
      ReadScaledVectorI16("p_bk_in_Gj - p_bj_in_Gj", kObservationPositionStepM, r, &relative));
  o->p_bk_in_Gj = p_bj_in_Gj + relative;
  return ReadCovariance<3>("cov_p_bk_in_Gj", r, &o->cov_p_bk_in_Gj);
}

}  // namespace

void EncodeEgoState(const EgoStateMessage& m, PacketWriter* w) {
  const QuaternionCodes q = EncodeQuaternion(m.q_Gj_bj);
  w->I64(m.stamp_ns);
  w->I48(m.stamp_ns - m.session_start_ns);
  w->U8(static_cast<uint8_t>(q.largest | (m.degenerated ? kDegeneratedFlag : 0) |
                             (m.observations.size() << kCountShift)));
  WriteQuaternion(q, w);
  WriteVectorF32(m.p_bj_in_Gj, w);
  WriteVectorF16(m.v_bj_in_Gj, w);
  WriteVectorF16(m.omega_bj_in_bj, w);
  WriteCovariance<3>(m.cov_theta_Gj_bj, w);
  WriteCovariance<3>(m.cov_p_bj_in_Gj, w);
  WriteCovariance<3>(m.cov_v_bj_in_Gj, w);
  w->U16(static_cast<uint16_t>(m.send_delay_ns < 0 ? kSendDelayUnknownCode
                                                   : SyncDelayCode(m.send_delay_ns)));
  w->U8(static_cast<uint8_t>(m.echoes.size() | (m.offset_report ? kOffsetReportFlag : 0)));
  for (const StateEcho& e : m.echoes) {
    int64_t hold_ns = 0;
    StateEchoHoldNs(m.stamp_ns, m.send_delay_ns, e.arrival_ns, &hold_ns);  // checked by Check()
    w->U8(static_cast<uint8_t>(e.teammate_id));
    w->U16(e.stamp_ref);
    w->U16(static_cast<uint16_t>(SyncDelayCode(e.send_delay_ns)));
    w->U16(static_cast<uint16_t>(SyncDelayCode(hold_ns)));
  }
  if (m.offset_report) {
    w->U8(static_cast<uint8_t>(m.offset_report->teammate_id));
    w->U16(m.offset_report->offset_residue);
    w->U8(static_cast<uint8_t>(m.offset_report->std_code));
  }
  for (const CurrentObservation& o : m.observations) {
    w->U8(static_cast<uint8_t>(o.observed_id));
    WriteScaledVectorI16(o.p_bk_in_bj, kObservationPositionStepM, w);
    WriteCovariance<3>(o.cov_p_bk_in_bj, w);
  }
  if (m.past_observations.empty()) return;  // the version 3 layout
  w->U8(static_cast<uint8_t>(m.past_observations.size()));
  const Eigen::Vector3d p_bj_sent = AsSentF32(m.p_bj_in_Gj);
  for (const PastObservation& o : m.past_observations) {
    w->U8(static_cast<uint8_t>(o.observed_id));
    w->U16(static_cast<uint16_t>(PastObservationAgeCode(o.age_ns)));
    WriteScaledVectorI16(o.p_bk_in_Gj - p_bj_sent, kObservationPositionStepM, w);
    WriteCovariance<3>(o.cov_p_bk_in_Gj, w);
  }
}

Status DecodeEgoState(int sender_id, PacketReader* r, EgoStateMessage* out) {
  EgoStateMessage m;
  m.sender_id = sender_id;
  SWARMLIO_RETURN_IF_ERROR(r->I64("stamp_ns", &m.stamp_ns));
  int64_t session_offset = 0;
  SWARMLIO_RETURN_IF_ERROR(r->I48("stamp_ns - session_start_ns", &session_offset));
  if (__builtin_sub_overflow(m.stamp_ns, session_offset, &m.session_start_ns)) {
    return r->Invalid("session_start_ns", -1, "overflows int64");
  }
  uint8_t bits = 0;
  SWARMLIO_RETURN_IF_ERROR(r->U8("bits", &bits));
  m.degenerated = (bits & kDegeneratedFlag) != 0;
  const int count = bits >> kCountShift;
  if (count > EgoStateMessage::kMaxObservations) {
    return Status::DataLoss("observation count " + std::to_string(count) + " exceeds the maximum " +
                            std::to_string(EgoStateMessage::kMaxObservations));
  }
  if (kEgoStateFixedBytes - r->position() > r->remaining()) {
    return Status::DataLoss("the fixed part needs " + std::to_string(kEgoStateFixedBytes) +
                            " payload bytes but the payload has " +
                            std::to_string(r->position() + r->remaining()));
  }
  SWARMLIO_RETURN_IF_ERROR(ReadQuaternion("q_Gj_bj", bits & kQuaternionLargestMask, r, &m.q_Gj_bj));
  SWARMLIO_RETURN_IF_ERROR(ReadVectorF32("p_bj_in_Gj", r, &m.p_bj_in_Gj));
  SWARMLIO_RETURN_IF_ERROR(ReadVectorF16("v_bj_in_Gj", r, &m.v_bj_in_Gj));
  SWARMLIO_RETURN_IF_ERROR(ReadVectorF16("omega_bj_in_bj", r, &m.omega_bj_in_bj));
  SWARMLIO_RETURN_IF_ERROR(ReadCovariance<3>("cov_theta_Gj_bj", r, &m.cov_theta_Gj_bj));
  SWARMLIO_RETURN_IF_ERROR(ReadCovariance<3>("cov_p_bj_in_Gj", r, &m.cov_p_bj_in_Gj));
  SWARMLIO_RETURN_IF_ERROR(ReadCovariance<3>("cov_v_bj_in_Gj", r, &m.cov_v_bj_in_Gj));
  uint16_t delay_code = 0;
  SWARMLIO_RETURN_IF_ERROR(r->U16("send_delay", &delay_code));
  m.send_delay_ns = delay_code == kSendDelayUnknownCode ? -1 : int64_t{delay_code} * kSyncDelayStepNs;
  uint8_t echo_bits = 0;
  SWARMLIO_RETURN_IF_ERROR(r->U8("echo bits", &echo_bits));
  const uint8_t echo_count = echo_bits & kEchoCountMask;
  const bool has_report = (echo_bits & kOffsetReportFlag) != 0;
  if (echo_count > EgoStateMessage::kMaxEchoes) {
    return Status::DataLoss("echo count " + std::to_string(echo_count) + " exceeds the maximum " +
                            std::to_string(EgoStateMessage::kMaxEchoes));
  }
  if ((echo_count > 0 || has_report) && m.send_delay_ns < 0) {
    return Status::DataLoss("echo count " + std::to_string(echo_count) +
                            (has_report ? " and an offset report" : "") +
                            " with an unknown send delay");
  }
  // The observations end the payload, or the past-observation section follows.
  const size_t lists = size_t{echo_count} * kStateEchoBytes +
                       (has_report ? kOffsetReportBytes : 0) +
                       static_cast<size_t>(count) * kObservationBytes;
  if (lists > r->remaining()) {
    return Status::DataLoss("observation count " + std::to_string(count) + " needs " +
                            std::to_string(r->position() + lists) + " payload bytes (with " +
                            std::to_string(echo_count) + " echoes) but the payload has " +
                            std::to_string(r->position() + r->remaining()));
  }
  m.echoes.resize(echo_count);
  for (int i = 0; i < echo_count; ++i) {
    StateEcho& e = m.echoes[static_cast<size_t>(i)];
    uint8_t id = 0;
    uint16_t ref = 0, delay = 0, hold = 0;
    SWARMLIO_RETURN_IF_ERROR(r->U8("echo teammate_id", &id));
    SWARMLIO_RETURN_IF_ERROR(r->U16("echo stamp_ref", &ref));
    SWARMLIO_RETURN_IF_ERROR(r->U16("echo send_delay", &delay));
    SWARMLIO_RETURN_IF_ERROR(r->U16("echo hold", &hold));
    if (delay > kSendDelayMaxCode) {
      return Status::DataLoss("echoes[" + std::to_string(i) + "]: send delay code " +
                              std::to_string(delay) + " is not a known delay");
    }
    e.teammate_id = id;
    e.stamp_ref = ref;
    e.send_delay_ns = int64_t{delay} * kSyncDelayStepNs;
    // stamp + send delay - hold; the stamp is any int64, so guard the sum.
    int64_t sent_ns = 0;
    if (__builtin_add_overflow(m.stamp_ns, m.send_delay_ns, &sent_ns) ||
        __builtin_sub_overflow(sent_ns, int64_t{hold} * kSyncDelayStepNs, &e.arrival_ns)) {
      return Status::DataLoss("echoes[" + std::to_string(i) + "]: arrival overflows int64");
    }
  }
  if (has_report) {
    uint8_t id = 0, std_code = 0;
    ClockOffsetReport report;
    SWARMLIO_RETURN_IF_ERROR(r->U8("offset report teammate_id", &id));
    SWARMLIO_RETURN_IF_ERROR(r->U16("offset report residue", &report.offset_residue));
    SWARMLIO_RETURN_IF_ERROR(r->U8("offset report std", &std_code));
    if (std_code < 1 || std_code > ClockOffsetReport::kMaxStdCode) {
      return Status::DataLoss("offset report: std code " + std::to_string(std_code) +
                              " is outside [1, " + std::to_string(ClockOffsetReport::kMaxStdCode) +
                              "]");
    }
    report.teammate_id = id;
    report.std_code = std_code;
    m.offset_report = report;
  }
  m.observations.resize(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    const Status s = DecodeObservation(r, &m.observations[static_cast<size_t>(i)]);
    if (!s.ok()) return s.WithContext("observations[" + std::to_string(i) + "]");
  }
  if (r->remaining() > 0) {
    uint8_t past = 0;
    SWARMLIO_RETURN_IF_ERROR(r->U8("past count", &past));
    if (past == 0 || past > EgoStateMessage::kMaxPastObservations ||
        size_t{past} * kPastObservationBytes != r->remaining()) {
      return Status::DataLoss("past observation count " + std::to_string(past) +
                              " (1.." + std::to_string(EgoStateMessage::kMaxPastObservations) +
                              ") does not match the " + std::to_string(r->remaining()) +
                              " bytes after it (" + std::to_string(kPastObservationBytes) +
                              " per entry)");
    }
    m.past_observations.resize(past);
    for (int i = 0; i < past; ++i) {
      const Status s =
          DecodePastObservation(m.p_bj_in_Gj, r, &m.past_observations[static_cast<size_t>(i)]);
      if (!s.ok()) return s.WithContext("past_observations[" + std::to_string(i) + "]");
    }
  }
  SWARMLIO_RETURN_IF_ERROR(r->ExpectEnd("payload"));
  *out = std::move(m);
  return Status::Ok();
}

}  // namespace swarmlio::net::internal
