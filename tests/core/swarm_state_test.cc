#include "swarmlio/state/swarm_state.h"

#include <gtest/gtest.h>

#include <random>

#include "swarmlio/math/so3.h"

namespace swarmlio {
namespace {

Eigen::Quaterniond RandomRotation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
}

Eigen::Vector3d RandomVector(std::mt19937& rng, double scale) {
  std::normal_distribution<double> n(0.0, scale);
  return Eigen::Vector3d(n(rng), n(rng), n(rng));
}

SwarmState RandomState(std::mt19937& rng, const std::vector<int>& ids) {
  SwarmState x;
  x.ego.q_G_b = RandomRotation(rng);
  x.ego.p_b_in_G = RandomVector(rng, 10);
  x.ego.v_b_in_G = RandomVector(rng, 2);
  x.ego.gyro_bias = RandomVector(rng, 0.01);
  x.ego.accel_bias = RandomVector(rng, 0.1);
  x.ego.g_in_G = RandomVector(rng, 1) + Eigen::Vector3d(0, 0, -9.81);
  for (int id : ids) {
    GlobalExtrinsic e;
    e.q_Ga_Gb = RandomRotation(rng);
    e.p_Gb_in_Ga = RandomVector(rng, 5);
    x.AddTeammate(id, e);
  }
  return x;
}

TEST(SwarmState, DimensionIs18Plus6PerTeammate) {
  std::mt19937 rng(1);
  EXPECT_EQ(RandomState(rng, {}).Dim(), 18);
  EXPECT_EQ(RandomState(rng, {4, 9, 2}).Dim(), 18 + 6 * 3);
}

TEST(SwarmState, BoxPlusMatchesThePaperDefinition) {
  std::mt19937 rng(2);
  const SwarmState x = RandomState(rng, {5, 1});
  Eigen::VectorXd dx = Eigen::VectorXd::Random(x.Dim());
  const SwarmState y = x.BoxPlus(dx);
  using L = ErrorStateLayout;
  // R (+) r = R Exp(r): right perturbation.
  EXPECT_NEAR((y.ego.R_G_b() - x.ego.R_G_b() * so3::Exp(dx.segment<3>(L::kRotation.offset)))
                  .norm(),
              0.0, 1e-14);
  EXPECT_TRUE(y.ego.p_b_in_G.isApprox(x.ego.p_b_in_G + dx.segment<3>(L::kPosition.offset)));
  EXPECT_TRUE(y.ego.g_in_G.isApprox(x.ego.g_in_G + dx.segment<3>(L::kGravity.offset)));
  const Segment rot1 = x.layout().TeammateRotation(1);
  const Segment trans1 = x.layout().TeammateTranslation(1);
  EXPECT_NEAR(
      (y.teammate(1).R_Ga_Gb() - x.teammate(1).R_Ga_Gb() * so3::Exp(dx.segment<3>(rot1.offset)))
          .norm(),
      0.0, 1e-14);
  EXPECT_TRUE(
      y.teammate(1).p_Gb_in_Ga.isApprox(x.teammate(1).p_Gb_in_Ga + dx.segment<3>(trans1.offset)));
}

TEST(SwarmState, BoxMinusInvertsBoxPlus) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const SwarmState x = RandomState(rng, {3, 8});
    // (x (+) d) (-) x = d for |d_rot| < pi.
    Eigen::VectorXd d = Eigen::VectorXd::Random(x.Dim());
    EXPECT_NEAR((x.BoxPlus(d).BoxMinus(x) - d).norm(), 0.0, 1e-12);
    // x (+) (y (-) x) = y.
    SwarmState y = RandomState(rng, {});
    y.AddTeammate(3, x.teammate(3).BoxPlus(Eigen::Matrix<double, 6, 1>::Random()));
    y.AddTeammate(8, RandomState(rng, {8}).teammate(8));
    const SwarmState y2 = x.BoxPlus(y.BoxMinus(x));
    EXPECT_NEAR(y2.BoxMinus(y).norm(), 0.0, 1e-12);
    EXPECT_NEAR(y.BoxMinus(x).norm(), x.BoxMinus(y).norm(), 1e-9);
  }
}

TEST(SwarmState, BoxMinusRotationIsTheShortestRotation) {
  SwarmState x;
  SwarmState y;
  y.ego.q_G_b = so3::ExpQuaternion(Eigen::Vector3d(0.2, 0, 0));
  y.ego.q_G_b.coeffs() *= -1.0;  // same rotation, other hemisphere
  EXPECT_NEAR((y.BoxMinus(x).head<3>() - Eigen::Vector3d(0.2, 0, 0)).norm(), 0.0, 1e-15);
}

TEST(SwarmState, ParameterBlocksRoundTrip) {
  std::mt19937 rng(4);
  const SwarmState x = RandomState(rng, {6});
  double ego[EgoState::kAmbientSize];
  x.ego.ToParameters(ego);
  EXPECT_EQ(EgoState::FromParameters(ego).BoxMinus(x.ego).norm(), 0.0);
  double ext[GlobalExtrinsic::kAmbientSize];
  x.teammate(6).ToParameters(ext);
  EXPECT_EQ(GlobalExtrinsic::FromParameters(ext).BoxMinus(x.teammate(6)).norm(), 0.0);
}

TEST(SwarmState, RemovingATeammateKeepsTheOthers) {
  std::mt19937 rng(5);
  SwarmState x = RandomState(rng, {1, 2, 3});
  const GlobalExtrinsic e3 = x.teammate(3);
  x.RemoveTeammate(2);
  EXPECT_EQ(x.Dim(), 30);
  EXPECT_FALSE(x.HasTeammate(2));
  EXPECT_EQ(x.teammate(3).p_Gb_in_Ga, e3.p_Gb_in_Ga);
  EXPECT_EQ(x.layout().TeammateBlock(3).offset, 24);
}

}  // namespace
}  // namespace swarmlio
