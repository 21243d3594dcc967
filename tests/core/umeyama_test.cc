#include "swarmlio/math/umeyama.h"

#include <gtest/gtest.h>

#include <random>

#include "swarmlio/math/so3.h"

namespace swarmlio {
namespace {

Eigen::Matrix3Xd RandomPoints(int n, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  Eigen::Matrix3Xd p(3, n);
  for (int i = 0; i < n; ++i) p.col(i) = Eigen::Vector3d(u(*rng), u(*rng), u(*rng));
  return p;
}

TEST(Umeyama, RecoversRigidAndSimilarityTransforms) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Matrix3Xd src = RandomPoints(20, &rng);
    std::normal_distribution<double> normal;
    const Eigen::Matrix3d R = so3::Exp(Eigen::Vector3d(normal(rng), normal(rng), normal(rng)));
    const Eigen::Vector3d t(normal(rng), normal(rng), normal(rng));
    for (const bool with_scale : {false, true}) {
      const double s = with_scale ? 1.7 : 1.0;
      Eigen::Matrix3Xd dst = (s * R) * src;
      dst.colwise() += t;
      UmeyamaOptions options;
      options.with_scale = with_scale;
      UmeyamaResult result;
      ASSERT_TRUE(AlignUmeyama(src, dst, options, &result).ok());
      EXPECT_LT((result.R_dst_src - R).norm(), 1e-9);
      EXPECT_LT((result.t_dst_src - t).norm(), 1e-9);
      EXPECT_NEAR(result.scale, s, 1e-9);
      EXPECT_LT(result.rms_residual_m, 1e-9);
      EXPECT_LT((result.Apply(src.col(3)) - dst.col(3)).norm(), 1e-9);
    }
  }
}

// Without translation: the rotation (and scale) about the origin, t = 0; an
// offset between the sets is left in the residual, not absorbed.
TEST(Umeyama, AboutTheOriginWithoutTranslation) {
  std::mt19937 rng(11);
  const Eigen::Matrix3Xd src = RandomPoints(20, &rng);
  const Eigen::Matrix3d R = so3::Exp(Eigen::Vector3d(0.3, -0.2, 1.1));
  UmeyamaOptions options;
  options.with_translation = false;
  for (const bool with_scale : {false, true}) {
    options.with_scale = with_scale;
    const double s = with_scale ? 0.8 : 1.0;
    const Eigen::Matrix3Xd dst = (s * R) * src;
    UmeyamaResult result;
    ASSERT_TRUE(AlignUmeyama(src, dst, options, &result).ok());
    EXPECT_LT((result.R_dst_src - R).norm(), 1e-9);
    EXPECT_EQ(result.t_dst_src, Eigen::Vector3d::Zero());
    EXPECT_NEAR(result.scale, s, 1e-9);
    EXPECT_LT(result.rms_residual_m, 1e-9);
  }
  options.with_scale = false;
  Eigen::Matrix3Xd shifted = R * src;
  shifted.colwise() += Eigen::Vector3d(0.5, 0.0, 0.0);
  UmeyamaResult result;
  ASSERT_TRUE(AlignUmeyama(src, shifted, options, &result).ok());
  EXPECT_GT(result.rms_residual_m, 0.1);
}

TEST(Umeyama, NeverReturnsAReflection) {
  std::mt19937 rng(3);
  const Eigen::Matrix3Xd src = RandomPoints(10, &rng);
  const Eigen::Matrix3Xd dst = Eigen::Vector3d(1, 1, -1).asDiagonal() * src;  // mirror image
  UmeyamaResult result;
  ASSERT_TRUE(AlignUmeyama(src, dst, {}, &result).ok());
  EXPECT_NEAR(result.R_dst_src.determinant(), 1.0, 1e-12);
  EXPECT_GT(result.rms_residual_m, 0.1);
}

TEST(Umeyama, RejectsBadInput) {
  UmeyamaResult result;
  Eigen::Matrix3Xd two(3, 2);
  two.setRandom();
  EXPECT_FALSE(AlignUmeyama(two, two, {}, &result).ok());
  Eigen::Matrix3Xd a(3, 5), b(3, 4);
  a.setRandom();
  b.setRandom();
  EXPECT_FALSE(AlignUmeyama(a, b, {}, &result).ok());
  Eigen::Matrix3Xd nan_points = a;
  nan_points(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(AlignUmeyama(nan_points, a, {}, &result).ok());
  // Collinear points: rotation about the line is undetermined.
  Eigen::Matrix3Xd line(3, 6);
  for (int i = 0; i < 6; ++i) line.col(i) = Eigen::Vector3d(i, 2.0 * i, 0.5);
  UmeyamaOptions options;
  options.min_second_singular_value_m2 = 1e-6;
  const Status status = AlignUmeyama(line, line, options, &result);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("degenerate"), std::string::npos);
}

}  // namespace
}  // namespace swarmlio
