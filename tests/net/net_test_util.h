// Seeded example messages whose values are exactly representable on the wire
// (each is passed through the codec once: version 3 quantizes, and a decoded
// message is a fixed point of encode + decode), and exact comparisons.
// MakeRaw* give the messages before that, for the precision tests.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <random>
#include <vector>

#include "swarmlio/net/messages.h"
#include "swarmlio/net/packet_codec.h"

namespace swarmlio::net::net_test {

/// x rounded to the nearest float32. Through a volatile: GCC 12.2 at -O2
/// drops a plain (double)(float)x when its SLP vectorizer pairs two of them.
inline double RoundToFloat(double x) {
  volatile float f = static_cast<float>(x);
  return f;
}

/// Random values from an explicit seed; uniform via the 53-bit construction so
/// the values do not depend on the standard library's distributions.
class ValueSource {
 public:
  explicit ValueSource(uint64_t seed) : engine_(seed) {}
  double Uniform(double lo, double hi) {
    return lo + (hi - lo) * static_cast<double>(engine_() >> 11) * 0x1.0p-53;
  }
  double F32(double lo, double hi) { return RoundToFloat(Uniform(lo, hi)); }
  Eigen::Vector3d Vector32(double scale) {
    return {F32(-scale, scale), F32(-scale, scale), F32(-scale, scale)};
  }
  Eigen::Vector3d Vector64(double scale) {
    return {Uniform(-scale, scale), Uniform(-scale, scale), Uniform(-scale, scale)};
  }
  Eigen::Quaterniond Quaternion() {
    Eigen::Vector4d c(Uniform(-1, 1), Uniform(-1, 1), Uniform(-1, 1), Uniform(-1, 1));
    c.normalize();
    return Eigen::Quaterniond(RoundToFloat(c[3]), RoundToFloat(c[0]), RoundToFloat(c[1]),
                              RoundToFloat(c[2]));
  }
  /// A symmetric positive semi-definite matrix with float32 entries.
  template <int N>
  Eigen::Matrix<double, N, N> Covariance(double scale) {
    Eigen::Matrix<double, N, N> a;
    for (int i = 0; i < N * N; ++i) a(i) = Uniform(-1, 1);
    Eigen::Matrix<double, N, N> c = scale * a * a.transpose();
    for (int r = 0; r < N; ++r) {
      for (int k = r; k < N; ++k) {
        c(r, k) = RoundToFloat(c(r, k));
        c(k, r) = c(r, k);
      }
    }
    return c;
  }
  uint64_t Next() { return engine_(); }

 private:
  std::mt19937_64 engine_;
};

inline EgoStateMessage MakeRawEgoState(int sender,
                                       int num_observations,
                                       uint64_t seed,
                                       int num_past_observations = 0,
                                       int num_echoes = 0) {
  ValueSource v(seed);
  EgoStateMessage m;
  m.sender_id = sender;
  m.stamp_ns = 1'700'000'000'123'456'789 + static_cast<int64_t>(seed);
  m.session_start_ns = 1'700'000'000'000'000'000;
  m.q_Gj_bj = v.Quaternion();
  m.p_bj_in_Gj = v.Vector32(500.0);
  m.v_bj_in_Gj = v.Vector32(5.0);
  m.omega_bj_in_bj = v.Vector32(2.0);
  m.cov_theta_Gj_bj = v.Covariance<3>(1e-5);
  m.cov_p_bj_in_Gj = v.Covariance<3>(1e-3);
  m.cov_v_bj_in_Gj = v.Covariance<3>(1e-2);
  m.degenerated = (seed % 2) == 1;
  for (int i = 0, id = 0; i < num_observations; ++id) {
    if (id == sender) continue;
    CurrentObservation o;
    o.observed_id = id;
    o.p_bk_in_bj = v.Vector32(20.0);
    o.cov_p_bk_in_bj = v.Covariance<3>(1e-3);
    m.observations.push_back(o);
    ++i;
  }
  for (int i = 0, id = 0; i < num_past_observations; ++id) {
    if (id == sender) continue;
    PastObservation o;
    o.observed_id = id;
    o.age_ns = 100'000'000 + static_cast<int64_t>(v.Next() % 1'000'000'000);
    o.p_bk_in_Gj = m.p_bj_in_Gj + v.Vector32(20.0);
    o.cov_p_bk_in_Gj = v.Covariance<3>(1e-3);
    m.past_observations.push_back(o);
    ++i;
  }
  if (num_echoes > 0) m.send_delay_ns = static_cast<int64_t>(v.Next() % 600'000'000);
  for (int i = 0, id = 0; i < num_echoes; ++id) {
    if (id == sender) continue;
    StateEcho e;
    e.teammate_id = id;
    e.stamp_ref = static_cast<uint16_t>(v.Next() & 0xFFFF);
    e.send_delay_ns = static_cast<int64_t>(v.Next() % 600'000'000);
    e.arrival_ns = m.stamp_ns + m.send_delay_ns - static_cast<int64_t>(v.Next() % 600'000'000);
    m.echoes.push_back(e);
    ++i;
  }
  return m;
}

inline GlobalExtrinsicMessage MakeRawGlobalExtrinsic(int sender, int num_entries, uint64_t seed) {
  ValueSource v(seed);
  GlobalExtrinsicMessage m;
  m.sender_id = sender;
  m.stamp_ns = 42'000'000'000 + static_cast<int64_t>(seed);
  m.g_in_Gi = v.Vector32(9.81);
  m.cov_g_in_Gi = v.Covariance<3>(1e-4);
  for (int i = 0, id = 0; i < num_entries; ++id) {
    if (id == sender) continue;
    GlobalExtrinsicEntry e;
    e.teammate_id = id;
    e.source = (i % 2 == 0) ? ExtrinsicSource::kTrajectoryMatch : ExtrinsicSource::kGraph;
    e.q_Ga_Gb = v.Quaternion();
    e.p_Gb_in_Ga = v.Vector32(100.0);
    e.covariance = v.Covariance<6>(1e-4);
    m.entries.push_back(e);
    ++i;
  }
  return m;
}

/// An airframe with random lengths (not on the millimetre grid).
inline AirframeMessage MakeRawAirframe(int sender, uint64_t seed) {
  ValueSource v(seed);
  AirframeMessage m;
  m.sender_id = sender;
  m.stamp_ns = 43'000'000'000 + static_cast<int64_t>(seed);
  m.reflector_shape = static_cast<int>(seed % 3);
  m.reflector_half_extents_m = {v.Uniform(0.0, 2.0), v.Uniform(0.0, 2.0), v.Uniform(0.0, 2.0)};
  m.reflector_centre_in_body_m = v.Vector64(2.0);
  m.depth_offset_m = v.Uniform(0.0, 1.0);
  m.size_m = v.Uniform(0.05, 5.0);
  m.min_intensity = v.Uniform(0.0, 255.0);
  m.centroid_sigma_m = v.Uniform(0.0, 1.0);
  return m;
}

inline PacketCodec MakeCodec(uint64_t key_seed = 7) {
  PacketCodec codec;
  const Status s = PacketCodec::Create(SwarmKey::ForSimulation(key_seed), &codec);
  EXPECT_TRUE(s.ok()) << s.message();
  return codec;
}

/// `message` as the wire represents it: Decode(Encode(message)). A message
/// that Encode rejects (tests build invalid ones on purpose, e.g. too many
/// observations) is returned unchanged.
template <class Message>
Message OnTheWire(const Message& message) {
  const PacketCodec codec = MakeCodec();
  std::vector<uint8_t> packet;
  if (!codec.Encode(message, 0, &packet).ok()) return message;
  DecodedPacket decoded;
  const Status s = codec.Decode(packet.data(), packet.size(), &decoded);
  if (!s.ok()) {
    ADD_FAILURE() << "an encoded packet does not decode: " << s.message();
    return message;
  }
  return std::get<Message>(decoded.message);
}

inline EgoStateMessage MakeEgoState(int sender,
                                    int num_observations,
                                    uint64_t seed,
                                    int num_past_observations = 0,
                                    int num_echoes = 0) {
  return OnTheWire(
      MakeRawEgoState(sender, num_observations, seed, num_past_observations, num_echoes));
}

inline GlobalExtrinsicMessage MakeGlobalExtrinsic(int sender, int num_entries, uint64_t seed) {
  return OnTheWire(MakeRawGlobalExtrinsic(sender, num_entries, seed));
}

inline AirframeMessage MakeAirframe(int sender, uint64_t seed) {
  return OnTheWire(MakeRawAirframe(sender, seed));
}

inline TimeSyncMessage MakeTimeSync(int sender, int target, bool response) {
  TimeSyncMessage m;
  m.sender_id = sender;
  m.target_id = target;
  m.is_response = response;
  m.t1_ns = 1'000'000'123;
  m.t2_ns = response ? 1'000'500'456 : 0;
  m.t3_ns = response ? 1'000'600'789 : 0;
  return m;
}

/// Bitwise equality of every field (== on doubles; NaN never appears).
inline void ExpectSameMessage(const SwarmMessage& expected, const SwarmMessage& actual) {
  ASSERT_EQ(expected.index(), actual.index());
  if (const auto* e = std::get_if<EgoStateMessage>(&expected)) {
    const auto& a = std::get<EgoStateMessage>(actual);
    EXPECT_EQ(e->sender_id, a.sender_id);
    EXPECT_EQ(e->stamp_ns, a.stamp_ns);
    EXPECT_EQ(e->session_start_ns, a.session_start_ns);
    EXPECT_EQ(e->q_Gj_bj.coeffs(), a.q_Gj_bj.coeffs());
    EXPECT_EQ(e->p_bj_in_Gj, a.p_bj_in_Gj);
    EXPECT_EQ(e->v_bj_in_Gj, a.v_bj_in_Gj);
    EXPECT_EQ(e->omega_bj_in_bj, a.omega_bj_in_bj);
    EXPECT_EQ(e->cov_theta_Gj_bj, a.cov_theta_Gj_bj);
    EXPECT_EQ(e->cov_p_bj_in_Gj, a.cov_p_bj_in_Gj);
    EXPECT_EQ(e->cov_v_bj_in_Gj, a.cov_v_bj_in_Gj);
    EXPECT_EQ(e->degenerated, a.degenerated);
    ASSERT_EQ(e->observations.size(), a.observations.size());
    for (size_t i = 0; i < e->observations.size(); ++i) {
      EXPECT_EQ(e->observations[i].observed_id, a.observations[i].observed_id);
      EXPECT_EQ(e->observations[i].p_bk_in_bj, a.observations[i].p_bk_in_bj);
      EXPECT_EQ(e->observations[i].cov_p_bk_in_bj, a.observations[i].cov_p_bk_in_bj);
    }
    ASSERT_EQ(e->past_observations.size(), a.past_observations.size());
    for (size_t i = 0; i < e->past_observations.size(); ++i) {
      EXPECT_EQ(e->past_observations[i].observed_id, a.past_observations[i].observed_id);
      EXPECT_EQ(e->past_observations[i].age_ns, a.past_observations[i].age_ns);
      EXPECT_EQ(e->past_observations[i].p_bk_in_Gj, a.past_observations[i].p_bk_in_Gj);
      EXPECT_EQ(e->past_observations[i].cov_p_bk_in_Gj, a.past_observations[i].cov_p_bk_in_Gj);
    }
    EXPECT_EQ(e->send_delay_ns, a.send_delay_ns);
    ASSERT_EQ(e->echoes.size(), a.echoes.size());
    for (size_t i = 0; i < e->echoes.size(); ++i) {
      EXPECT_EQ(e->echoes[i].teammate_id, a.echoes[i].teammate_id);
      EXPECT_EQ(e->echoes[i].stamp_ref, a.echoes[i].stamp_ref);
      EXPECT_EQ(e->echoes[i].send_delay_ns, a.echoes[i].send_delay_ns);
      EXPECT_EQ(e->echoes[i].arrival_ns, a.echoes[i].arrival_ns);
    }
    ASSERT_EQ(e->offset_report.has_value(), a.offset_report.has_value());
    if (e->offset_report) {
      EXPECT_EQ(e->offset_report->teammate_id, a.offset_report->teammate_id);
      EXPECT_EQ(e->offset_report->offset_residue, a.offset_report->offset_residue);
      EXPECT_EQ(e->offset_report->std_code, a.offset_report->std_code);
    }
  } else if (const auto* g = std::get_if<GlobalExtrinsicMessage>(&expected)) {
    const auto& a = std::get<GlobalExtrinsicMessage>(actual);
    EXPECT_EQ(g->sender_id, a.sender_id);
    EXPECT_EQ(g->stamp_ns, a.stamp_ns);
    EXPECT_EQ(g->g_in_Gi, a.g_in_Gi);
    EXPECT_EQ(g->cov_g_in_Gi, a.cov_g_in_Gi);
    ASSERT_EQ(g->entries.size(), a.entries.size());
    for (size_t i = 0; i < g->entries.size(); ++i) {
      EXPECT_EQ(g->entries[i].teammate_id, a.entries[i].teammate_id);
      EXPECT_EQ(g->entries[i].source, a.entries[i].source);
      EXPECT_EQ(g->entries[i].q_Ga_Gb.coeffs(), a.entries[i].q_Ga_Gb.coeffs());
      EXPECT_EQ(g->entries[i].p_Gb_in_Ga, a.entries[i].p_Gb_in_Ga);
      EXPECT_EQ(g->entries[i].covariance, a.entries[i].covariance);
    }
  } else if (const auto* f = std::get_if<AirframeMessage>(&expected)) {
    const auto& a = std::get<AirframeMessage>(actual);
    EXPECT_EQ(f->sender_id, a.sender_id);
    EXPECT_EQ(f->stamp_ns, a.stamp_ns);
    EXPECT_EQ(f->reflector_shape, a.reflector_shape);
    EXPECT_EQ(f->reflector_half_extents_m, a.reflector_half_extents_m);
    EXPECT_EQ(f->reflector_centre_in_body_m, a.reflector_centre_in_body_m);
    EXPECT_EQ(f->depth_offset_m, a.depth_offset_m);
    EXPECT_EQ(f->size_m, a.size_m);
    EXPECT_EQ(f->min_intensity, a.min_intensity);
    EXPECT_EQ(f->centroid_sigma_m, a.centroid_sigma_m);
  } else {
    const auto& e2 = std::get<TimeSyncMessage>(expected);
    const auto& a = std::get<TimeSyncMessage>(actual);
    EXPECT_EQ(e2.sender_id, a.sender_id);
    EXPECT_EQ(e2.target_id, a.target_id);
    EXPECT_EQ(e2.is_response, a.is_response);
    EXPECT_EQ(e2.t1_ns, a.t1_ns);
    EXPECT_EQ(e2.t2_ns, a.t2_ns);
    EXPECT_EQ(e2.t3_ns, a.t3_ns);
  }
}

/// One of every message kind, with list lengths from empty to the maximum.
inline std::vector<SwarmMessage> AllExampleMessages() {
  std::vector<SwarmMessage> messages;
  for (int k : {0, 1, 5, EgoStateMessage::kMaxObservations}) {
    messages.push_back(MakeEgoState(3, k, 100 + static_cast<uint64_t>(k)));
  }
  messages.push_back(MakeEgoState(3, 1, 150, 1));  // with repeated observations
  messages.push_back(MakeEgoState(3, EgoStateMessage::kMaxObservations, 151,
                                  EgoStateMessage::kMaxPastObservations));
  messages.push_back(MakeEgoState(3, 1, 152, 0, 2));  // with clock echoes
  messages.push_back(MakeEgoState(3, EgoStateMessage::kMaxObservations, 153,
                                  EgoStateMessage::kMaxPastObservations,
                                  EgoStateMessage::kMaxEchoes));
  for (const auto& [echoes, std_code] :
       {std::pair{0, 1}, std::pair{2, ClockOffsetReport::kMaxStdCode}}) {
    EgoStateMessage m = MakeEgoState(3, 1, 154, 0, echoes);  // with an offset report
    if (echoes == 0) m.send_delay_ns = 120'000;
    m.offset_report = ClockOffsetReport{63, 0xFFFE, std_code};
    messages.push_back(m);
  }
  for (int n : {0, 1, GlobalExtrinsicMessage::kMaxEntries}) {
    messages.push_back(MakeGlobalExtrinsic(63, n, 200 + static_cast<uint64_t>(n)));
  }
  messages.push_back(MakeTimeSync(0, 63, false));
  messages.push_back(MakeTimeSync(63, 0, true));
  for (uint64_t seed : {300, 301, 302}) {  // one of each shape
    messages.push_back(MakeAirframe(static_cast<int>(seed % 64), seed));
  }
  return messages;
}

}  // namespace swarmlio::net::net_test
