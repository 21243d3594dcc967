// Wire version 3 quantizes: a decoded message equals the sent one within the
// precision documented per field (docs/network.md §2.1), and every decoded
// covariance is symmetric positive definite.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>

#include "swarmlio/net/packet_codec.h"
#include "swarmlio/net/wire_format.h"
#include "tests/net/net_test_util.h"

namespace swarmlio::net {
namespace {

using net_test::MakeCodec;
using net_test::MakeRawEgoState;
using net_test::MakeRawGlobalExtrinsic;

constexpr double kQuaternionAngle = 1.2e-4;  // rad
const double kVarianceRatio = std::exp2(0.5 * kLogVarianceStep) * (1 + 1e-12);

template <class Message>
Message RoundTrip(const Message& m) {
  const PacketCodec codec = MakeCodec();
  std::vector<uint8_t> packet;
  const Status encoded = codec.Encode(m, 1, &packet);
  EXPECT_TRUE(encoded.ok()) << encoded.message();
  DecodedPacket decoded;
  const Status s = codec.Decode(packet.data(), packet.size(), &decoded);
  EXPECT_TRUE(s.ok()) << s.message();
  return s.ok() ? std::get<Message>(decoded.message) : m;
}

void ExpectFloat32(const Eigen::Vector3d& sent, const Eigen::Vector3d& got, const char* what) {
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(std::abs(got[i] - sent[i]), std::abs(sent[i]) * std::exp2(-24)) << what << i;
  }
}

void ExpectFloat16(const Eigen::Vector3d& sent, const Eigen::Vector3d& got, const char* what) {
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(std::abs(got[i] - sent[i]),
              std::max(std::abs(sent[i]) * std::exp2(-11), std::exp2(-25)))
        << what << i;
  }
}

template <int N>
void ExpectCovariance(const Eigen::Matrix<double, N, N>& sent,
                      const Eigen::Matrix<double, N, N>& got,
                      const char* what) {
  EXPECT_EQ(got, got.transpose()) << what;
  using Llt = Eigen::LLT<Eigen::Matrix<double, N, N>>;
  EXPECT_EQ(Llt(got).info(), Eigen::Success) << what;
  for (int i = 0; i < N; ++i) {
    EXPECT_LE(got(i, i) / sent(i, i), kVarianceRatio) << what << i;
    EXPECT_GE(got(i, i) / sent(i, i), 1.0 / kVarianceRatio) << what << i;
  }
}

TEST(CodecPrecision, EgoStateFieldsWithinTheDocumentedPrecision) {
  for (uint64_t seed = 1; seed <= 300; ++seed) {
    SCOPED_TRACE(seed);
    const EgoStateMessage m = MakeRawEgoState(static_cast<int>(seed % 64), 3, seed, 2);
    const EgoStateMessage d = RoundTrip(m);
    EXPECT_EQ(d.sender_id, m.sender_id);
    EXPECT_EQ(d.stamp_ns, m.stamp_ns);  // exact
    EXPECT_EQ(d.session_start_ns, m.session_start_ns);
    EXPECT_LT(d.q_Gj_bj.angularDistance(m.q_Gj_bj), kQuaternionAngle);
    ExpectFloat32(m.p_bj_in_Gj, d.p_bj_in_Gj, "p_bj_in_Gj");
    ExpectFloat16(m.v_bj_in_Gj, d.v_bj_in_Gj, "v_bj_in_Gj");
    ExpectFloat16(m.omega_bj_in_bj, d.omega_bj_in_bj, "omega_bj_in_bj");
    ExpectCovariance<3>(m.cov_theta_Gj_bj, d.cov_theta_Gj_bj, "cov_theta");
    ExpectCovariance<3>(m.cov_p_bj_in_Gj, d.cov_p_bj_in_Gj, "cov_p");
    ExpectCovariance<3>(m.cov_v_bj_in_Gj, d.cov_v_bj_in_Gj, "cov_v");
    EXPECT_EQ(d.degenerated, m.degenerated);
    ASSERT_EQ(d.observations.size(), m.observations.size());
    for (size_t i = 0; i < m.observations.size(); ++i) {
      EXPECT_EQ(d.observations[i].observed_id, m.observations[i].observed_id);
      EXPECT_LE((d.observations[i].p_bk_in_bj - m.observations[i].p_bk_in_bj).cwiseAbs().maxCoeff(),
                0.5 * kObservationPositionStepM + 1e-12);
      ExpectCovariance<3>(m.observations[i].cov_p_bk_in_bj, d.observations[i].cov_p_bk_in_bj,
                          "cov_p_bk_in_bj");
    }
    ASSERT_EQ(d.past_observations.size(), m.past_observations.size());
    for (size_t i = 0; i < m.past_observations.size(); ++i) {
      const PastObservation& sent = m.past_observations[i];
      const PastObservation& got = d.past_observations[i];
      EXPECT_EQ(got.observed_id, sent.observed_id);
      EXPECT_LE(std::abs(got.age_ns - sent.age_ns), kPastObservationAgeStepNs / 2);
      EXPECT_EQ(got.age_ns % kPastObservationAgeStepNs, 0);
      // Relative to the float32 position, in 2 mm steps: step / 2 plus the
      // rounding of a few hundred metres in double.
      EXPECT_LE((got.p_bk_in_Gj - sent.p_bk_in_Gj).cwiseAbs().maxCoeff(),
                0.5 * kObservationPositionStepM + 1e-9);
      ExpectCovariance<3>(sent.cov_p_bk_in_Gj, got.cov_p_bk_in_Gj, "cov_p_bk_in_Gj");
    }
  }
}

TEST(CodecPrecision, GlobalExtrinsicFieldsWithinTheDocumentedPrecision) {
  for (uint64_t seed = 1; seed <= 100; ++seed) {
    SCOPED_TRACE(seed);
    const GlobalExtrinsicMessage m =
        MakeRawGlobalExtrinsic(7, GlobalExtrinsicMessage::kMaxEntries, seed);
    const GlobalExtrinsicMessage d = RoundTrip(m);
    EXPECT_EQ(d.stamp_ns, m.stamp_ns);
    ExpectFloat32(m.g_in_Gi, d.g_in_Gi, "g_in_Gi");
    ExpectCovariance<3>(m.cov_g_in_Gi, d.cov_g_in_Gi, "cov_g_in_Gi");
    ASSERT_EQ(d.entries.size(), m.entries.size());
    for (size_t i = 0; i < m.entries.size(); ++i) {
      EXPECT_EQ(d.entries[i].teammate_id, m.entries[i].teammate_id);
      EXPECT_EQ(d.entries[i].source, m.entries[i].source);
      EXPECT_LT(d.entries[i].q_Ga_Gb.angularDistance(m.entries[i].q_Ga_Gb), kQuaternionAngle);
      ExpectFloat32(m.entries[i].p_Gb_in_Ga, d.entries[i].p_Gb_in_Ga, "p_Gb_in_Ga");
      ExpectCovariance<6>(m.entries[i].covariance, d.entries[i].covariance, "covariance");
    }
  }
}

TEST(CodecPrecision, RangeLimitsAreExactAtTheEdges) {
  EgoStateMessage m = MakeRawEgoState(1, 1, 1);
  m.v_bj_in_Gj = Eigen::Vector3d(65504.0, -65504.0, 65519.0);  // the last one rounds to 65504
  m.omega_bj_in_bj = Eigen::Vector3d(std::exp2(-24), -0.0, 1e-9);
  m.observations[0].p_bk_in_bj = Eigen::Vector3d(65.534, -65.534, 65.5349);
  m.cov_p_bj_in_Gj = Eigen::Matrix3d::Zero();                // sent as the smallest variance
  m.session_start_ns = m.stamp_ns + (int64_t{1} << 47) - 1;  // the farthest session start
  const EgoStateMessage d = RoundTrip(m);
  EXPECT_EQ(d.v_bj_in_Gj, Eigen::Vector3d(65504.0, -65504.0, 65504.0));
  EXPECT_EQ(d.omega_bj_in_bj[0], std::exp2(-24));
  EXPECT_TRUE(std::signbit(d.omega_bj_in_bj[1]));
  EXPECT_EQ(d.omega_bj_in_bj[2], 0.0);
  EXPECT_NEAR(d.observations[0].p_bk_in_bj[0], 65.534, 1e-12);
  EXPECT_NEAR(d.observations[0].p_bk_in_bj[1], -65.534, 1e-12);
  EXPECT_NEAR(d.observations[0].p_bk_in_bj[2], 65.534, 1e-12);
  EXPECT_EQ(d.cov_p_bj_in_Gj, std::exp2(kLogVarianceMin) * Eigen::Matrix3d::Identity());
  EXPECT_EQ(d.session_start_ns, m.session_start_ns);
}

}  // namespace
}  // namespace swarmlio::net
