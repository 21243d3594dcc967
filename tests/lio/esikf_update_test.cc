// EsikfUpdate: the Ceres Gauss-Newton formulation against the closed-form
// iterated Kalman update written out here independently (docs/esikf.md):
//
//   e     = x_i (-) x_hat,   J^-1 = blockdiag(Jr(e_R), I, ...)
//   P_J   = J^-1 P_hat J^-T
//   K     = (H^T R^-1 H + P_J^-1)^-1 H^T R^-1
//   dx_i  = -K z_i - (I - K H) J^-1 e,       x_{i+1} = x_i (+) dx_i
//   P     = (I - K H) P_J
//
// with z_i, H the point-to-plane residuals and Jacobian at x_i.
#include "swarmlio/lio/esikf_update.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <string>

#include "esikf_test_util.h"
#include "swarmlio/math/so3.h"

namespace swarmlio::lio {
namespace {

using esikf_test::IekfStep;
using esikf_test::Sampler;

// The closed-form IEKF step at x_i for the point-to-plane rows.
IekfStep ClosedFormIekfStep(const SwarmState& x_hat,
                            const Eigen::MatrixXd& P_hat,
                            const SwarmState& x_i,
                            const std::vector<PlaneCorrespondence>& corr) {
  Eigen::MatrixXd H;
  Eigen::VectorXd z;
  esikf_test::PlaneRows(x_i, corr, &H, &z);
  return esikf_test::ClosedFormIekfStep(x_hat, P_hat, x_i, H, z);
}

PlaneAssociationFn Fixed(const std::vector<PlaneCorrespondence>* corr, int* calls = nullptr) {
  return [corr, calls](const SwarmState&, std::vector<PlaneCorrespondence>* out) {
    if (calls != nullptr) ++*calls;
    *out = *corr;
    return Status::Ok();
  };
}

double MaxAbs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }

std::string Sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3g", v);
  return buf;
}

EsikfUpdate OneStep(ceres::LinearSolverType solver = ceres::DENSE_NORMAL_CHOLESKY) {
  EsikfUpdateOptions options;
  options.max_iterations = 1;
  options.linear_solver = solver;
  return EsikfUpdate(options);
}

TEST(EsikfUpdateOptions, Validate) {
  EXPECT_EQ(EsikfUpdateOptions().Validate(), "");
  EsikfUpdateOptions o;
  o.max_iterations = 0;
  EXPECT_NE(o.Validate(), "");
  o = {};
  o.convergence_rotation_rad = 0.0;
  EXPECT_NE(o.Validate(), "");
  o = {};
  o.convergence_translation_m = -1.0;
  EXPECT_NE(o.Validate().find("convergence_translation_m"), std::string::npos);
  o = {};
  o.linear_solver = ceres::CGNR;
  EXPECT_NE(o.Validate(), "");
}

// Linear-Gaussian: points at the body origin (z = n^T p + d, linear in p) and
// rotations uncorrelated with the rest, so no rotation moves and one Gauss-
// Newton step is the exact Kalman update dx = -K z, P = (I - K H) P_hat.
TEST(EsikfUpdate, LinearGaussianStepIsTheKalmanUpdate) {
  Sampler s(1);
  const SwarmState x_hat = s.State(2);
  const int n = x_hat.Dim();
  Eigen::MatrixXd P = s.Covariance(n, 0.5);
  for (const Segment& rot : {ErrorStateLayout::kRotation,
                             x_hat.layout().TeammateRotation(x_hat.layout().teammate_ids()[0]),
                             x_hat.layout().TeammateRotation(x_hat.layout().teammate_ids()[1])}) {
    P.middleRows(rot.offset, 3).setZero();
    P.middleCols(rot.offset, 3).setZero();
    P.block(rot.offset, rot.offset, 3, 3) = 0.01 * Eigen::Matrix3d::Identity();
  }
  const SwarmState truth = x_hat.BoxPlus(s.Gaussian(n, 0.3));
  std::vector<PlaneCorrespondence> corr = s.Scan(truth.ego, 4, 3, 0.05, 0.05);
  for (PlaneCorrespondence& c : corr) {
    c.offset_m = -c.normal_in_G.dot(truth.ego.p_b_in_G) + 0.05 * s.Normal();
    c.p_in_b.setZero();
  }
  const EsikfUpdateResult result = OneStep().Run(x_hat, P, Fixed(&corr));
  ASSERT_TRUE(result.status.ok()) << result.status.message();

  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(corr.size(), n);
  Eigen::VectorXd z(corr.size()), w(corr.size());
  for (size_t k = 0; k < corr.size(); ++k) {
    H.block<1, 3>(k, 3) = corr[k].normal_in_G.transpose();
    z[k] = corr[k].normal_in_G.dot(x_hat.ego.p_b_in_G) + corr[k].offset_m;
    w[k] = corr[k].weight;
  }
  const Eigen::MatrixXd S = H * P * H.transpose() + Eigen::MatrixXd(w.cwiseInverse().asDiagonal());
  const Eigen::MatrixXd K = P * H.transpose() * S.inverse();  // textbook gain
  const Eigen::VectorXd dx = -K * z;
  const Eigen::MatrixXd P_post = (Eigen::MatrixXd::Identity(n, n) - K * H) * P;

  const double dx_err = MaxAbs(result.state.BoxMinus(x_hat) - dx);
  const double P_err = MaxAbs(result.covariance - P_post);
  RecordProperty("max_abs_dx_diff", Sci(dx_err));
  RecordProperty("max_abs_P_diff", Sci(P_err));
  EXPECT_LT(dx_err, 1e-9);
  EXPECT_LT(P_err, 1e-9);
  EXPECT_EQ(result.iterations, 1);
  EXPECT_EQ(result.num_correspondences, 12);
}

// Nonlinear: random attitude, 2 teammates, dense P_hat, noisy points on 5
// planes. One Gauss-Newton step from x_i (x_hat itself, and points away from
// x_hat so that the J^-1 correction of the prior matters) equals the
// closed-form IEKF step; the returned covariance equals (I - K H) P_J
// evaluated at the new estimate, where Run linearizes for it.
TEST(EsikfUpdate, OneGaussNewtonStepEqualsTheIteratedKalmanStep) {
  Sampler s(2);
  const SwarmState x_hat = s.State(2);
  const int n = x_hat.Dim();
  const Eigen::MatrixXd P = s.Covariance(n, 0.2);
  const SwarmState truth = x_hat.BoxPlus(s.Gaussian(n, 0.1));
  const std::vector<PlaneCorrespondence> corr = s.Scan(truth.ego, 5, 6, 0.05, 0.05);

  double worst_dx = 0.0, worst_P = 0.0;
  for (double start_scale : {0.0, 0.05, 0.3}) {
    SCOPED_TRACE(start_scale);
    const SwarmState x_i = x_hat.BoxPlus(s.Gaussian(n, start_scale));
    for (auto solver : {ceres::DENSE_NORMAL_CHOLESKY, ceres::DENSE_QR}) {
      const EsikfUpdateResult result = OneStep(solver).RunFrom(x_hat, P, x_i, Fixed(&corr));
      ASSERT_TRUE(result.status.ok()) << result.status.message();
      ASSERT_EQ(result.num_rejected_steps, 0);
      const IekfStep step = ClosedFormIekfStep(x_hat, P, x_i, corr);
      const double dx_err = MaxAbs(result.state.BoxMinus(x_i) - step.dx);
      const IekfStep at_solution = ClosedFormIekfStep(x_hat, P, result.state, corr);
      const double P_err = MaxAbs(result.covariance - at_solution.P);
      EXPECT_LT(dx_err, 1e-9);
      EXPECT_LT(P_err, 1e-9);
      EXPECT_GT(step.dx.norm(), 1e-3);  // a real step was compared
      worst_dx = std::max(worst_dx, dx_err);
      worst_P = std::max(worst_P, P_err);
    }
  }
  RecordProperty("max_abs_dx_diff", Sci(worst_dx));
  RecordProperty("max_abs_P_diff", Sci(worst_P));
}

// Several iterations with re-association: recovers a perturbed pose from
// noise-free points, converges within the default 4 iterations, calls the
// association once per iteration, and the covariance is the IEKF one at the
// solution.
TEST(EsikfUpdate, ConvergedUpdateRecoversAPerturbedPose) {
  Sampler s(3);
  const SwarmState truth = s.State(2);
  const int n = truth.Dim();
  Eigen::VectorXd sigma(n);
  sigma << 0.1 * Eigen::Vector3d::Ones(), 1.0 * Eigen::Vector3d::Ones(),
      0.5 * Eigen::Vector3d::Ones(), 0.01 * Eigen::Vector3d::Ones(), 0.1 * Eigen::Vector3d::Ones(),
      0.1 * Eigen::Vector3d::Ones(), 0.05 * Eigen::VectorXd::Ones(12);
  const Eigen::MatrixXd P_hat = sigma.cwiseAbs2().asDiagonal();
  Eigen::VectorXd perturbation = Eigen::VectorXd::Zero(n);
  perturbation.head<3>() = s.Axis() * 0.08;     // 4.6 deg
  perturbation.segment<3>(3) = s.Axis() * 0.4;  // 0.4 m
  const SwarmState x_hat = truth.BoxPlus(perturbation);
  const std::vector<PlaneCorrespondence> all = s.Scan(truth.ego, 8, 25, 0.01, 0.0);

  int calls = 0;
  std::vector<PlaneCorrespondence> last;
  const PlaneAssociationFn associate = [&](const SwarmState&,
                                           std::vector<PlaneCorrespondence>* out) {
    // A different subset per call, as a map would re-associate.
    const size_t drop = calls % 2 == 0 ? 17 : 0;
    out->assign(all.begin(), all.end() - drop);
    last = *out;
    ++calls;
    return Status::Ok();
  };
  const EsikfUpdateResult result = EsikfUpdate().Run(x_hat, P_hat, associate);
  ASSERT_TRUE(result.status.ok()) << result.status.message();
  EXPECT_TRUE(result.converged);
  EXPECT_LE(result.iterations, 4);
  EXPECT_EQ(calls, result.iterations);
  EXPECT_EQ(result.num_correspondences, static_cast<int>(last.size()));
  const Eigen::VectorXd err = result.state.BoxMinus(truth);
  EXPECT_LT(err.head<3>().norm(), 1e-4);      // rad
  EXPECT_LT(err.segment<3>(3).norm(), 1e-4);  // m
  EXPECT_LT(MaxAbs(result.covariance - ClosedFormIekfStep(x_hat, P_hat, result.state, last).P),
            1e-9);
  // The pose is observed: posterior rotation/position std far below the prior.
  const Eigen::MatrixXd pose_covariance = result.covariance.topLeftCorner(6, 6);
  EXPECT_LT(pose_covariance.diagonal().maxCoeff(), 1e-5);
  EXPECT_GE(result.solve_time_s, 0.0);
  EXPECT_GE(result.total_time_s, result.solve_time_s + result.association_time_s);
}

TEST(EsikfUpdate, NoCorrespondencesReturnsThePrior) {
  Sampler s(4);
  const SwarmState x_hat = s.State(2);
  const Eigen::MatrixXd P = s.Covariance(x_hat.Dim(), 0.3);
  const std::vector<PlaneCorrespondence> none;
  const EsikfUpdateResult result = EsikfUpdate().Run(x_hat, P, Fixed(&none));
  ASSERT_TRUE(result.status.ok()) << result.status.message();
  EXPECT_TRUE(result.converged);
  EXPECT_EQ(result.num_correspondences, 0);
  EXPECT_LT(result.state.BoxMinus(x_hat).norm(), 1e-12);
  EXPECT_LT(MaxAbs(result.covariance - P), 1e-10 * MaxAbs(P));
}

TEST(EsikfUpdate, AssociationErrorIsReturned) {
  Sampler s(5);
  const SwarmState x_hat = s.State(1);
  const Eigen::MatrixXd P = s.Covariance(x_hat.Dim(), 0.3);
  const PlaneAssociationFn failing = [](const SwarmState&, std::vector<PlaneCorrespondence>*) {
    return Status::FailedPrecondition("map is empty");
  };
  const EsikfUpdateResult result = EsikfUpdate().Run(x_hat, P, failing);
  EXPECT_EQ(result.status.code(), Status::Code::kFailedPrecondition);
  EXPECT_NE(result.status.message().find("map is empty"), std::string::npos);
  EXPECT_LT(result.state.BoxMinus(x_hat).norm(), 1e-15);
}

TEST(EsikfUpdate, RejectsABadCovarianceOrLayout) {
  Sampler s(6);
  const SwarmState x_hat = s.State(1);
  const std::vector<PlaneCorrespondence> none;
  EXPECT_EQ(EsikfUpdate().Run(x_hat, Eigen::MatrixXd::Identity(18, 18), Fixed(&none)).status.code(),
            Status::Code::kInvalidArgument);
  EXPECT_EQ(EsikfUpdate()
                .Run(x_hat, -Eigen::MatrixXd::Identity(x_hat.Dim(), x_hat.Dim()), Fixed(&none))
                .status.code(),
            Status::Code::kInvalidArgument);
  EXPECT_EQ(EsikfUpdate()
                .RunFrom(x_hat, Eigen::MatrixXd::Identity(x_hat.Dim(), x_hat.Dim()), s.State(2),
                         Fixed(&none))
                .status.code(),
            Status::Code::kInvalidArgument);
  EsikfUpdateOptions bad;
  bad.max_iterations = 0;
  EXPECT_EQ(EsikfUpdate(bad)
                .Run(x_hat, Eigen::MatrixXd::Identity(x_hat.Dim(), x_hat.Dim()), Fixed(&none))
                .status.code(),
            Status::Code::kInvalidArgument);
}

}  // namespace
}  // namespace swarmlio::lio
