// The field encodings of wire version 3 on their own: float16, smallest-three
// quaternions, log-variance / partial-correlation covariances (every code
// vector decodes to a symmetric positive-definite matrix).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "src/net/covariance_codec.h"
#include "src/net/half_float.h"
#include "src/net/quaternion_codec.h"
#include "swarmlio/net/wire_format.h"
#include "tests/net/net_test_util.h"

namespace swarmlio::net::internal {
namespace {

using net_test::ValueSource;

// --- float16 -----------------------------------------------------------------

TEST(HalfFloat, EveryFiniteHalfRoundTripsExactly) {
  int finite = 0;
  for (uint32_t bits = 0; bits <= 0xFFFF; ++bits) {
    const auto h = static_cast<uint16_t>(bits);
    if (!IsFiniteHalf(h)) continue;
    ++finite;
    const double x = DoubleFromHalf(h);
    ASSERT_TRUE(FitsHalf(x)) << bits;
    ASSERT_EQ(HalfFromDouble(x), h) << bits;
  }
  EXPECT_EQ(finite, 63488);  // 2 * 31 * 1024
  EXPECT_EQ(DoubleFromHalf(0x7BFF), kHalfMax);
  EXPECT_EQ(DoubleFromHalf(0x0001), std::ldexp(1.0, -24));
  EXPECT_EQ(DoubleFromHalf(0x3C00), 1.0);
  EXPECT_EQ(DoubleFromHalf(0xC000), -2.0);
  EXPECT_FALSE(IsFiniteHalf(0x7C00));  // +Inf
  EXPECT_FALSE(IsFiniteHalf(0xFE00));  // NaN
}

TEST(HalfFloat, RoundsToNearestTiesToEven) {
  // Between consecutive halves a < b: below the midpoint -> a, above -> b, at
  // it -> the one with an even significand; normal and subnormal alike.
  for (uint16_t a : {uint16_t{0x0000}, uint16_t{0x0001}, uint16_t{0x03FF}, uint16_t{0x0400},
                     uint16_t{0x3C00}, uint16_t{0x3C01}, uint16_t{0x57FF}, uint16_t{0x7BFE}}) {
    const auto b = static_cast<uint16_t>(a + 1);
    const double lo = DoubleFromHalf(a);
    const double hi = DoubleFromHalf(b);
    const double mid = 0.5 * (lo + hi);
    EXPECT_EQ(HalfFromDouble(std::nextafter(mid, lo)), a) << a;
    EXPECT_EQ(HalfFromDouble(std::nextafter(mid, hi)), b) << a;
    EXPECT_EQ(HalfFromDouble(mid), (a & 1) == 0 ? a : b) << a;
    EXPECT_EQ(HalfFromDouble(-mid), static_cast<uint16_t>(0x8000 | ((a & 1) == 0 ? a : b)));
  }
  EXPECT_EQ(HalfFromDouble(65519.99), 0x7BFF);  // rounds down to 65504
  EXPECT_TRUE(FitsHalf(65519.99));
  EXPECT_FALSE(FitsHalf(65520.0));
  EXPECT_FALSE(FitsHalf(std::numeric_limits<double>::quiet_NaN()));
}

TEST(HalfFloat, RelativeErrorWithinHalfAnUlp) {
  ValueSource v(11);
  for (int i = 0; i < 100000; ++i) {
    const double x = std::ldexp(v.Uniform(-1.0, 1.0), static_cast<int>(v.Uniform(-20, 16)));
    const double y = DoubleFromHalf(HalfFromDouble(x));
    const double bound = std::max(std::abs(x) * std::ldexp(1.0, -11), std::ldexp(1.0, -25));
    ASSERT_LE(std::abs(y - x), bound) << x;
  }
}

// --- quaternions -----------------------------------------------------------

double AngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.normalized().angularDistance(b.normalized());
}

TEST(QuaternionCodes, RoundTripWithinTheDocumentedAngle) {
  ValueSource v(5);
  double worst = 0.0;
  double sum = 0.0;
  constexpr int kTrials = 200000;
  for (int i = 0; i < kTrials; ++i) {
    Eigen::Vector4d c(v.Uniform(-1, 1), v.Uniform(-1, 1), v.Uniform(-1, 1), v.Uniform(-1, 1));
    const Eigen::Quaterniond q(c[3], c[0], c[1], c[2]);
    const QuaternionCodes codes = EncodeQuaternion(q);
    Eigen::Quaterniond d;
    ASSERT_TRUE(DecodeQuaternion(codes, &d));
    EXPECT_NEAR(d.norm(), 1.0, 1e-15);
    const double angle = AngleBetween(q, d);
    worst = std::max(worst, angle);
    sum += angle;
    // Canonical: the decoded quaternion encodes to the same codes.
    const QuaternionCodes again = EncodeQuaternion(d);
    ASSERT_EQ(again.largest, codes.largest);
    ASSERT_EQ(again.sent, codes.sent);
  }
  std::printf("[ figures  ] smallest three: max %.2e rad, mean %.2e rad over %d rotations\n", worst,
              sum / kTrials, kTrials);
  EXPECT_LT(worst, 1.2e-4);  // docs/network.md §2.1
}

TEST(QuaternionCodes, TiesAndSignsAreCanonical) {
  const double h = std::sqrt(0.5);
  for (const Eigen::Vector4d& c :
       {Eigen::Vector4d(0.5, 0.5, 0.5, 0.5), Eigen::Vector4d(-0.5, 0.5, -0.5, 0.5),
        Eigen::Vector4d(h, h, 0, 0), Eigen::Vector4d(0, 0, -h, h), Eigen::Vector4d(0, 0, 0, 1),
        Eigen::Vector4d(0, 0, 0, -1), Eigen::Vector4d(1, 0, 0, 0)}) {
    const Eigen::Quaterniond q(c[3], c[0], c[1], c[2]);
    const QuaternionCodes codes = EncodeQuaternion(q);
    const QuaternionCodes negated =
        EncodeQuaternion(Eigen::Quaterniond(-c[3], -c[0], -c[1], -c[2]));
    EXPECT_EQ(codes.largest, negated.largest);
    EXPECT_EQ(codes.sent, negated.sent);
    Eigen::Quaterniond d;
    ASSERT_TRUE(DecodeQuaternion(codes, &d)) << c.transpose();
    EXPECT_LT(AngleBetween(q, d), 1.2e-4) << c.transpose();
    const QuaternionCodes again = EncodeQuaternion(d);
    EXPECT_EQ(again.largest, codes.largest);
    EXPECT_EQ(again.sent, codes.sent);
  }
}

TEST(QuaternionCodes, DecoderRejectsNonCanonicalCodes) {
  Eigen::Quaterniond q;
  QuaternionCodes codes;
  codes.sent = {kQuaternionMaxCode, kQuaternionMaxCode, 0};  // sum c^2 = 1: restored 0
  EXPECT_FALSE(DecodeQuaternion(codes, &q));
  codes.sent = {kQuaternionMaxCode, kQuaternionMaxCode, kQuaternionMaxCode};  // sum > 1
  EXPECT_FALSE(DecodeQuaternion(codes, &q));
  codes.sent = {-32768, 0, 0};
  EXPECT_FALSE(DecodeQuaternion(codes, &q));
  codes.sent = {0, 0, 0};
  codes.largest = 4;
  EXPECT_FALSE(DecodeQuaternion(codes, &q));
  codes.largest = 2;
  ASSERT_TRUE(DecodeQuaternion(codes, &q));
  EXPECT_EQ(q.coeffs(), Eigen::Vector4d(0, 0, 1, 0));
}

// --- covariances -------------------------------------------------------------

/// Symmetric, and Cholesky succeeds with every pivot of the correlation
/// matrix >= 1e-12 (the parametrization's floor is (1 - tanh(127/40)^2)^(N-1):
/// 4.9e-5 for 3x3, 1.6e-11 for 6x6, far above double rounding).
template <int N>
void ExpectSymmetricPositiveDefinite(const Eigen::Matrix<double, N, N>& m) {
  ASSERT_TRUE(m.allFinite());
  ASSERT_EQ(m, m.transpose());
  const Eigen::LLT<Eigen::Matrix<double, N, N>> llt(m);
  ASSERT_EQ(llt.info(), Eigen::Success) << m;
  const Eigen::Matrix<double, N, 1> d = m.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::Matrix<double, N, N> r = d.asDiagonal() * m * d.asDiagonal();
  const Eigen::LLT<Eigen::Matrix<double, N, N>> llt_r(r);
  ASSERT_EQ(llt_r.info(), Eigen::Success) << r;
  const Eigen::Matrix<double, N, N> l = llt_r.matrixL();
  EXPECT_GT(l.diagonal().cwiseAbs2().minCoeff(), 1e-12) << r;
}

/// Decodes valid codes and checks that the matrix encodes to the same codes
/// (every valid code vector is canonical, as the fuzz target requires).
template <int N>
Eigen::Matrix<double, N, N> Decode(const std::array<uint8_t, CovarianceBytes(N)>& codes) {
  Eigen::Matrix<double, N, N> m;
  int bad = -1;
  EXPECT_TRUE(DecodeCovariance<N>(codes.data(), &m, &bad)) << bad;
  std::array<uint8_t, CovarianceBytes(N)> again{};
  EncodeCovariance<N>(m, again.data());
  EXPECT_EQ(again, codes);
  return m;
}

TEST(CovarianceCodes, EveryCodeDecodesSymmetricPositiveDefiniteAndEncodesBack) {
  // 3x3: every combination of correlation codes in {-127, -64, 0, 64, 127}
  // with the smallest and largest variances.
  const int levels[] = {-127, -64, 0, 64, 127};
  for (uint8_t variance : {uint8_t{0}, uint8_t{255}}) {
    for (int a : levels) {
      for (int b : levels) {
        for (int c : levels) {
          const std::array<uint8_t, 6> codes = {variance,
                                                128,
                                                variance,
                                                static_cast<uint8_t>(a),
                                                static_cast<uint8_t>(b),
                                                static_cast<uint8_t>(c)};
          const Eigen::Matrix3d m = Decode<3>(codes);
          ExpectSymmetricPositiveDefinite<3>(m);
          EXPECT_EQ(m(0, 0), VarianceFromCode(variance));
          EXPECT_EQ(m(1, 1), VarianceFromCode(128));
        }
      }
    }
  }
  // 6x6: all correlations at +127, at -127, alternating, and random codes.
  std::array<uint8_t, 21> codes{};
  for (int pattern = 0; pattern < 3; ++pattern) {
    for (int i = 0; i < 6; ++i) codes[i] = static_cast<uint8_t>(40 * i);
    for (int i = 6; i < 21; ++i) {
      const int code = pattern == 0 ? 127 : pattern == 1 ? -127 : (i % 2 == 0 ? 127 : -127);
      codes[i] = static_cast<uint8_t>(static_cast<int8_t>(code));
    }
    ExpectSymmetricPositiveDefinite<6>(Decode<6>(codes));
  }
  std::mt19937_64 rng(17);
  for (int trial = 0; trial < 20000; ++trial) {
    for (int i = 0; i < 6; ++i) codes[i] = static_cast<uint8_t>(rng());
    for (int i = 6; i < 21; ++i) {
      codes[i] = static_cast<uint8_t>(static_cast<int8_t>(static_cast<int>(rng() % 255) - 127));
    }
    ExpectSymmetricPositiveDefinite<6>(Decode<6>(codes));
    if (HasFatalFailure()) return;
  }
}

TEST(CovarianceCodes, CorrelationCodeMinus128IsRejected) {
  std::array<uint8_t, 6> codes = {10, 20, 30, 0, 0x80, 0};
  Eigen::Matrix3d m = Eigen::Matrix3d::Constant(7.0);
  int bad = -1;
  EXPECT_FALSE(DecodeCovariance<3>(codes.data(), &m, &bad));
  EXPECT_EQ(bad, 4);
}

TEST(CovarianceCodes, VariancesKeepAQuarterOctave) {
  const double worst = std::exp2(0.5 * kLogVarianceStep);  // half a step
  for (double variance = std::exp2(kLogVarianceMin); variance < MaxEncodableVariance();
       variance *= 1.0137) {
    const double decoded = VarianceFromCode(VarianceCode(variance));
    EXPECT_LE(decoded / variance, worst * (1 + 1e-12)) << variance;
    EXPECT_GE(decoded / variance, 1.0 / worst / (1 + 1e-12)) << variance;
  }
  EXPECT_EQ(VarianceCode(0.0), 0);
  EXPECT_EQ(VarianceCode(1e-300), 0);  // below the range: the smallest variance
  EXPECT_EQ(VarianceFromCode(0), std::exp2(kLogVarianceMin));
  EXPECT_EQ(VarianceCode(MaxEncodableVariance()), kLogVarianceMaxCode);
  EXPECT_EQ(VarianceFromCode(kLogVarianceMaxCode), std::exp2(23.75));
  for (int code = 0; code <= kLogVarianceMaxCode; ++code) {
    EXPECT_EQ(VarianceCode(VarianceFromCode(static_cast<uint8_t>(code))), code);
  }
}

template <int N>
void CheckRoundTrip(const Eigen::Matrix<double, N, N>& m, double* worst_rho) {
  uint8_t codes[CovarianceBytes(N)];
  EncodeCovariance<N>(m, codes);
  Eigen::Matrix<double, N, N> d;
  int bad = -1;
  ASSERT_TRUE(DecodeCovariance<N>(codes, &d, &bad));
  ExpectSymmetricPositiveDefinite<N>(d);
  const double step = std::exp2(0.5 * kLogVarianceStep) * (1 + 1e-12);
  for (int i = 0; i < N; ++i) {
    ASSERT_LE(d(i, i) / m(i, i), step);
    ASSERT_GE(d(i, i) / m(i, i), 1.0 / step);
    for (int j = 0; j < i; ++j) {
      const double rho = m(i, j) / std::sqrt(m(i, i) * m(j, j));
      const double rho_d = d(i, j) / std::sqrt(d(i, i) * d(j, j));
      *worst_rho = std::max(*worst_rho, std::abs(rho_d - rho));
    }
  }
  // Canonical: the decoded matrix encodes to the same codes.
  uint8_t again[CovarianceBytes(N)];
  EncodeCovariance<N>(d, again);
  for (size_t i = 0; i < CovarianceBytes(N); ++i) ASSERT_EQ(again[i], codes[i]) << i << "\n" << m;
}

TEST(CovarianceCodes, CorrelationsWithinHalfAStep) {
  // Random covariances D (A A^T + I) D: correlation matrices with condition
  // numbers up to ~40 (no partial correlation beyond 0.99, so none is
  // clamped) and variances spread over 1e-10 .. 1e2.
  ValueSource v(23);
  double worst3 = 0.0;
  double worst6 = 0.0;
  for (int trial = 0; trial < 20000; ++trial) {
    Eigen::Matrix3d a3;
    for (int i = 0; i < 9; ++i) a3(i) = v.Uniform(-1, 1);
    const Eigen::Vector3d s3(std::pow(10.0, v.Uniform(-5, 1)), std::pow(10.0, v.Uniform(-5, 1)),
                             std::pow(10.0, v.Uniform(-5, 1)));
    const Eigen::Matrix3d m3 =
        s3.asDiagonal() * (a3 * a3.transpose() + Eigen::Matrix3d::Identity()) * s3.asDiagonal();
    CheckRoundTrip<3>(m3, &worst3);
    Eigen::Matrix<double, 6, 6> a6;
    for (int i = 0; i < 36; ++i) a6(i) = v.Uniform(-1, 1);
    Eigen::Matrix<double, 6, 1> s6;
    for (int i = 0; i < 6; ++i) s6[i] = std::pow(10.0, v.Uniform(-4, 0));
    const Eigen::Matrix<double, 6, 6> m6 =
        s6.asDiagonal() * (a6 * a6.transpose() + Eigen::Matrix<double, 6, 6>::Identity()) *
        s6.asDiagonal();
    CheckRoundTrip<6>(m6, &worst6);
    if (HasFatalFailure()) return;
  }
  std::printf("[ figures  ] covariance correlations: max error %.4f (3x3), %.4f (6x6)\n", worst3,
              worst6);
  // Half a step of the Fisher code is 1/80 at rho = 0 and less elsewhere.
  EXPECT_LE(worst3, 0.5 * kCorrelationStep + 1e-9);
  EXPECT_LE(worst6, 0.5 * kCorrelationStep + 1e-9);
}

TEST(CovarianceCodes, IndefiniteZeroAndTinyInputsBecomePositiveDefinite) {
  double worst = 0.0;
  Eigen::Matrix3d indefinite = 1e-5 * Eigen::Matrix3d::Identity();
  indefinite(0, 1) = indefinite(1, 0) = 0.5;  // |rho| = 50000
  indefinite(1, 2) = indefinite(2, 1) = -0.3;
  uint8_t codes[6];
  EncodeCovariance<3>(indefinite, codes);
  Eigen::Matrix3d d;
  int bad = -1;
  ASSERT_TRUE(DecodeCovariance<3>(codes, &d, &bad));
  ExpectSymmetricPositiveDefinite<3>(d);
  EXPECT_NEAR(d(0, 1) / std::sqrt(d(0, 0) * d(1, 1)), std::tanh(127 * kCorrelationStep), 1e-12);

  EncodeCovariance<3>(Eigen::Matrix3d::Zero(), codes);
  ASSERT_TRUE(DecodeCovariance<3>(codes, &d, &bad));
  EXPECT_EQ(d, std::exp2(kLogVarianceMin) * Eigen::Matrix3d::Identity());

  Eigen::Matrix<double, 6, 6> singular = Eigen::Matrix<double, 6, 6>::Ones() * 1e-4;  // rank 1
  uint8_t codes6[21];
  EncodeCovariance<6>(singular, codes6);
  Eigen::Matrix<double, 6, 6> d6;
  ASSERT_TRUE(DecodeCovariance<6>(codes6, &d6, &bad));
  ExpectSymmetricPositiveDefinite<6>(d6);
  CheckRoundTrip<6>(d6, &worst);
}

}  // namespace
}  // namespace swarmlio::net::internal
