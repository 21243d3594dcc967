// PointToPlaneFactor: eq. (4) residuals of a whole scan in one cost function,
// its analytic Jacobian over the ego block in the tangent space (random and
// near-pi attitudes), re-association through the shared container, and the
// normal-equation helper used for the posterior covariance.
#include "factors/point_to_plane_factor.h"

#include <gtest/gtest.h>

#include <array>
#include <random>

#include "factors/ego_state_manifold.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/testing/jacobian_check.h"
#include "test_utils/state_sampler.h"

namespace swarmlio {
namespace {

class Sampler : public swarmlio::testing::StateSampler {
 public:
  using StateSampler::StateSampler;
  // Correspondences built from explicit plane points q_n (eq. (4) form).
  std::vector<PlaneCorrespondence> Correspondences(int n, std::vector<Eigen::Vector3d>* q) {
    std::vector<PlaneCorrespondence> out(n);
    q->resize(n);
    for (int i = 0; i < n; ++i) {
      out[i].p_in_b = Gaussian3(8.0);
      out[i].normal_in_G = Axis();
      (*q)[i] = Gaussian3(10.0);
      out[i].offset_m = -out[i].normal_in_G.dot((*q)[i]);
      out[i].weight = Uniform(10.0, 1000.0);
    }
    return out;
  }
};

TEST(PointToPlaneFactor, ResidualIsEquationFour) {
  Sampler s(1);
  std::vector<Eigen::Vector3d> q;
  const std::vector<PlaneCorrespondence> corr = s.Correspondences(25, &q);
  const PointToPlaneFactor factor(&corr);
  ASSERT_EQ(factor.num_residuals(), 25);
  ASSERT_EQ(factor.parameter_block_sizes(), std::vector<int32_t>{19});
  const EgoState ego = s.Ego(-1.0);
  std::array<double, 19> x;
  ego.ToParameters(x.data());
  const double* params[] = {x.data()};
  std::vector<double> r(25);
  ASSERT_TRUE(factor.Evaluate(params, r.data(), nullptr));
  for (int i = 0; i < 25; ++i) {
    const Eigen::Vector3d p_in_G = ego.R_G_b() * corr[i].p_in_b + ego.p_b_in_G;
    EXPECT_NEAR(r[i], std::sqrt(corr[i].weight) * corr[i].normal_in_G.dot(p_in_G - q[i]), 1e-9);
  }
}

TEST(PointToPlaneFactor, JacobianIsCorrectAtRandomAndNearPiAttitudes) {
  Sampler s(2);
  const double angles[] = {-1.0, M_PI - 1e-7, M_PI - 1e-3, 1e-9, 0.0};
  EgoStateManifold manifold;
  for (double angle : angles) {
    SCOPED_TRACE(angle);
    for (int trial = 0; trial < 10; ++trial) {
      std::vector<Eigen::Vector3d> q;
      const std::vector<PlaneCorrespondence> corr = s.Correspondences(30, &q);
      const PointToPlaneFactor factor(&corr);
      std::array<double, 19> x;
      s.Ego(angle).ToParameters(x.data());
      EXPECT_TRUE(testing::CostFunctionJacobiansAreCorrect(factor, {&manifold}, {x.data()}));
    }
  }
}

TEST(PointToPlaneFactor, FlippedSignIsRejected) {
  Sampler s(3);
  std::vector<Eigen::Vector3d> q;
  const std::vector<PlaneCorrespondence> corr = s.Correspondences(30, &q);
  const PointToPlaneFactor factor(&corr);
  const testing::FlippedJacobianColumns flipped(&factor, /*block=*/0, /*num_columns=*/4);
  EgoStateManifold manifold;
  std::array<double, 19> x;
  s.Ego(-1.0).ToParameters(x.data());
  EXPECT_TRUE(testing::CostFunctionJacobiansAreCorrect(factor, {&manifold}, {x.data()}));
  EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(flipped, {&manifold}, {x.data()}));
}

TEST(PointToPlaneFactor, ReadsTheContainerAfterReassociation) {
  Sampler s(4);
  std::vector<Eigen::Vector3d> q;
  std::vector<PlaneCorrespondence> corr = s.Correspondences(10, &q);
  PointToPlaneFactor factor(&corr);
  EXPECT_EQ(factor.num_residuals(), 10);
  corr = s.Correspondences(17, &q);
  factor.SyncNumResiduals();
  EXPECT_EQ(factor.num_residuals(), 17);
  std::array<double, 19> x;
  s.Ego(-1.0).ToParameters(x.data());
  EgoStateManifold manifold;
  EXPECT_TRUE(testing::CostFunctionJacobiansAreCorrect(factor, {&manifold}, {x.data()}));
}

TEST(PointToPlaneFactor, NormalEquationsMatchTheTangentJacobian) {
  Sampler s(5);
  std::vector<Eigen::Vector3d> q;
  const std::vector<PlaneCorrespondence> corr = s.Correspondences(40, &q);
  const PointToPlaneFactor factor(&corr);
  const EgoState ego = s.Ego(-1.0);
  std::array<double, 19> x;
  ego.ToParameters(x.data());
  const double* params[] = {x.data()};
  Eigen::VectorXd z(40);
  Eigen::Matrix<double, Eigen::Dynamic, 19, Eigen::RowMajor> J(40, 19);
  double* jac[] = {J.data()};
  ASSERT_TRUE(factor.Evaluate(params, z.data(), jac));
  Eigen::Matrix<double, 19, 18, Eigen::RowMajor> plus_jacobian;
  ASSERT_TRUE(EgoStateManifold().PlusJacobian(x.data(), plus_jacobian.data()));
  const Eigen::MatrixXd H = J * plus_jacobian;  // tangent Jacobian (40 x 18)
  EXPECT_NEAR(H.rightCols<12>().norm(), 0.0, 0.0);
  Eigen::Matrix<double, 6, 6> HtH = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> Htz = Eigen::Matrix<double, 6, 1>::Zero();
  factor.AccumulateNormalEquations(ego, &HtH, &Htz);
  const Eigen::MatrixXd H6 = H.leftCols<6>();
  EXPECT_NEAR((HtH - H6.transpose() * H6).norm(), 0.0, 1e-9 * HtH.norm());
  EXPECT_NEAR((Htz - H6.transpose() * z).norm(), 0.0, 1e-9 * Htz.norm());
}

TEST(PointToPlaneFactor, ResidualsWithoutJacobianMatchFullEvaluation) {
  Sampler s(6);
  std::vector<Eigen::Vector3d> q;
  const std::vector<PlaneCorrespondence> corr = s.Correspondences(12, &q);
  const PointToPlaneFactor factor(&corr);
  std::array<double, 19> x;
  s.Ego(-1.0).ToParameters(x.data());
  const double* params[] = {x.data()};
  std::vector<double> r1(12), r2(12), j(12 * 19);
  double* no_block[] = {nullptr};
  double* with_block[] = {j.data()};
  ASSERT_TRUE(factor.Evaluate(params, r1.data(), no_block));
  ASSERT_TRUE(factor.Evaluate(params, r2.data(), with_block));
  EXPECT_EQ(r1, r2);
}

}  // namespace
}  // namespace swarmlio
