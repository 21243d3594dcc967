// PoseInformationFactor: the information form of a scan's point rows. Its
// Jacobian is checked in the tangent space (random, near-identity and
// near-pi attitudes, linearization point away from the evaluation point) and
// fails on a flipped sign; its squared norm equals the sum of the point
// rows' squares up to a constant to first order around the linearization
// point, and exactly for the Gauss-Newton model there (same gradient and
// Hessian); a singular information (degenerate scan) gives zero rows, not NaN.
#include "factors/pose_information_factor.h"

#include <gtest/gtest.h>

#include <random>

#include "factors/ego_state_manifold.h"
#include "factors/point_to_plane_factor.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/testing/jacobian_check.h"

namespace swarmlio {
namespace {

EgoState RandomEgo(std::mt19937* rng, double angle) {
  std::normal_distribution<double> n;
  const Eigen::Vector3d axis = Eigen::Vector3d(n(*rng), n(*rng), n(*rng)).normalized();
  EgoState ego;
  ego.q_G_b = so3::ExpQuaternion(axis * angle);
  ego.p_b_in_G = Eigen::Vector3d(n(*rng), n(*rng), n(*rng)) * 3.0;
  ego.v_b_in_G = Eigen::Vector3d(n(*rng), n(*rng), n(*rng));
  return ego;
}

std::vector<PlaneCorrespondence> Planes(std::mt19937* rng, int count) {
  std::normal_distribution<double> n;
  std::vector<PlaneCorrespondence> out(static_cast<size_t>(count));
  for (PlaneCorrespondence& c : out) {
    c.p_in_b = Eigen::Vector3d(n(*rng), n(*rng), n(*rng)) * 5.0;
    c.normal_in_G = Eigen::Vector3d(n(*rng), n(*rng), n(*rng)).normalized();
    c.offset_m = 0.3 * n(*rng);
    c.weight = 100.0;
  }
  return out;
}

// The factor built from the point rows of `corr` at `lin`.
void Build(const std::vector<PlaneCorrespondence>& corr, const EgoState& lin,
           PoseInformationFactor* f) {
  PointToPlaneFactor points(&corr);
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
  points.AccumulateNormalEquations(lin, &A, &b);
  f->Set(A, b, lin.q_G_b, lin.p_b_in_G);
}

TEST(PoseInformationFactor, JacobianIsCorrectAndFailsOnAFlippedSign) {
  std::mt19937 rng(3);
  const EgoStateManifold manifold;
  for (double angle : {0.7, 1e-9, M_PI - 1e-4}) {
    SCOPED_TRACE(angle);
    const EgoState lin = RandomEgo(&rng, angle);
    const std::vector<PlaneCorrespondence> corr = Planes(&rng, 40);
    PoseInformationFactor f;
    Build(corr, lin, &f);
    // Evaluate away from the linearization point (Jr^-1 matters there) and at it.
    for (double away : {0.0, 0.2}) {
      EgoState at = lin;
      at.q_G_b = lin.q_G_b * so3::ExpQuaternion(Eigen::Vector3d(away, -away, 0.5 * away));
      at.p_b_in_G += Eigen::Vector3d::Constant(away);
      std::array<double, EgoState::kAmbientSize> x{};
      at.ToParameters(x.data());
      EXPECT_TRUE(testing::CostFunctionJacobiansAreCorrect(f, {&manifold}, {x.data()}));
      const testing::FlippedJacobianColumns rot(&f, 0, 4);
      EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(rot, {&manifold}, {x.data()}));
      const testing::FlippedJacobianColumns pos(&f, 0, 3, 4);
      EXPECT_FALSE(testing::CostFunctionJacobiansAreCorrect(pos, {&manifold}, {x.data()}));
    }
  }
}

// At the linearization point the factor and the point rows have the same
// gradient J^T r and Gauss-Newton Hessian J^T J over the tangent space.
TEST(PoseInformationFactor, SameNormalEquationsAsThePointRows) {
  std::mt19937 rng(4);
  const EgoState lin = RandomEgo(&rng, 1.1);
  const std::vector<PlaneCorrespondence> corr = Planes(&rng, 60);
  PoseInformationFactor f;
  Build(corr, lin, &f);
  PointToPlaneFactor points(&corr);
  std::array<double, EgoState::kAmbientSize> x{};
  lin.ToParameters(x.data());
  const EgoStateManifold manifold;
  Eigen::Matrix<double, EgoState::kAmbientSize, EgoState::kTangentSize, Eigen::RowMajor> plus;
  ASSERT_TRUE(manifold.PlusJacobian(x.data(), plus.data()));
  const auto normal_equations = [&](const ceres::CostFunction& cost, Eigen::MatrixXd* H,
                                    Eigen::VectorXd* g) {
    const int m = cost.num_residuals();
    Eigen::VectorXd r(m);
    Eigen::Matrix<double, Eigen::Dynamic, EgoState::kAmbientSize, Eigen::RowMajor> J(m, 19);
    double* jac[1] = {J.data()};
    const double* params[1] = {x.data()};
    ASSERT_TRUE(cost.Evaluate(params, r.data(), jac));
    const Eigen::MatrixXd Jt = J * plus;
    *H = Jt.transpose() * Jt;
    *g = Jt.transpose() * r;
  };
  Eigen::MatrixXd H1, H2;
  Eigen::VectorXd g1, g2;
  normal_equations(points, &H1, &g1);
  normal_equations(f, &H2, &g2);
  EXPECT_LT((H1 - H2).cwiseAbs().maxCoeff(), 1e-9 * H1.cwiseAbs().maxCoeff());
  EXPECT_LT((g1 - g2).cwiseAbs().maxCoeff(), 1e-9 * g1.cwiseAbs().maxCoeff());
}

// Points on one plane constrain 3 of the 6 directions: no NaN, zero rows.
TEST(PoseInformationFactor, SingularInformationGivesFiniteResiduals) {
  std::mt19937 rng(5);
  const EgoState lin = RandomEgo(&rng, 0.3);
  std::vector<PlaneCorrespondence> corr = Planes(&rng, 30);
  for (PlaneCorrespondence& c : corr) c.normal_in_G = Eigen::Vector3d::UnitZ();
  PoseInformationFactor f;
  Build(corr, lin, &f);
  const Eigen::Matrix<double, 6, 1> r = f.Residual(lin);
  ASSERT_TRUE(r.allFinite());
  int zero_rows = 0;
  for (int k = 0; k < 6; ++k) zero_rows += r[k] == 0.0;
  EXPECT_GE(zero_rows, 3);
}

}  // namespace
}  // namespace swarmlio
