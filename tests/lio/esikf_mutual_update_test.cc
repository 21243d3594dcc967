// EsikfUpdate with several measurement models: point-to-plane, active and
// passive mutual observations over teammate blocks (docs/swarm.md). One
// Gauss-Newton step equals the closed-form iterated Kalman step with the
// observation rows written out here from the paper's equations
// (independently of the factors' code), covariance included; an update that
// estimates only some teammate blocks equals the Schmidt-Kalman update
// (zero gain for the blocks left out, Joseph-form covariance), also with
// considered blocks in the gain.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>

#include "esikf_test_util.h"
#include "factors/active_observation_factor.h"
#include "factors/passive_observation_factor.h"
#include "swarmlio/lio/esikf_update.h"
#include "swarmlio/math/so3.h"

namespace swarmlio::lio {
namespace {

using esikf_test::Sampler;

double MaxAbs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }

// A model with fixed residual blocks (the factors own their linearization
// of the noise; the residuals are re-evaluated at every iteration).
class FixedTerms final : public MeasurementModel {
 public:
  const char* name() const override { return "fixed"; }
  Status Linearize(const SwarmState&, std::vector<ResidualTerm>* terms) override {
    for (const ResidualTerm& t : terms_) terms->push_back(t);
    return Status::Ok();
  }
  std::vector<ResidualTerm> terms_;
};

struct Active {
  int j;
  Eigen::Vector3d z, p_bj_in_Gj;
  Eigen::Matrix3d S;  // innovation covariance (at x_hat)
};
struct Passive {
  int j;
  Eigen::Vector3d z, p_bj_in_Gj;
  Eigen::Matrix3d R_Gj_bj, S;
  double dt;
};

// Whitening W with W^T W = S^-1.
Eigen::Matrix3d Whitening(const Eigen::Matrix3d& S) {
  const Eigen::Matrix3d L = S.llt().matrixL();
  return L.inverse();
}

// Rows of the active observation (paper eq. z_ao) at x, whitened.
void ActiveRows(const SwarmState& x, const Active& a, Eigen::MatrixXd* H, Eigen::VectorXd* z) {
  const Eigen::Matrix3d R_bi = x.ego.R_G_b();
  const GlobalExtrinsic& T = x.teammate(a.j);
  const Eigen::Vector3d h =
      R_bi.transpose() * (T.R_Ga_Gb() * a.p_bj_in_Gj + T.p_Gb_in_Ga - x.ego.p_b_in_G);
  Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(3, x.Dim());
  rows.block<3, 3>(0, 0) = so3::Hat(h);
  rows.block<3, 3>(0, 3) = -R_bi.transpose();
  const int o = x.layout().TeammateBlock(a.j).offset;
  rows.block<3, 3>(0, o) = -R_bi.transpose() * T.R_Ga_Gb() * so3::Hat(a.p_bj_in_Gj);
  rows.block<3, 3>(0, o + 3) = R_bi.transpose();
  const Eigen::Matrix3d W = Whitening(a.S);
  H->conservativeResize(H->rows() + 3, x.Dim());
  H->bottomRows(3) = W * rows;
  z->conservativeResize(z->size() + 3);
  z->tail(3) = W * (h - a.z);
}

// Rows of the passive observation (paper eq. z_po, time-compensated).
void PassiveRows(const SwarmState& x, const Passive& p, Eigen::MatrixXd* H, Eigen::VectorXd* z) {
  const GlobalExtrinsic& T = x.teammate(p.j);
  const Eigen::Vector3d w =
      T.R_Ga_Gb().transpose() * (x.ego.p_b_in_G + x.ego.v_b_in_G * p.dt - T.p_Gb_in_Ga);
  const Eigen::Vector3d h = p.R_Gj_bj.transpose() * (w - p.p_bj_in_Gj);
  const Eigen::Matrix3d M = p.R_Gj_bj.transpose() * T.R_Ga_Gb().transpose();
  Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(3, x.Dim());
  rows.block<3, 3>(0, 3) = M;
  rows.block<3, 3>(0, 6) = M * p.dt;
  const int o = x.layout().TeammateBlock(p.j).offset;
  rows.block<3, 3>(0, o) = p.R_Gj_bj.transpose() * so3::Hat(w);
  rows.block<3, 3>(0, o + 3) = -M;
  const Eigen::Matrix3d W = Whitening(p.S);
  H->conservativeResize(H->rows() + 3, x.Dim());
  H->bottomRows(3) = W * rows;
  z->conservativeResize(z->size() + 3);
  z->tail(3) = W * (h - p.z);
}

struct Problem {
  SwarmState x_hat, truth;
  Eigen::MatrixXd P;
  std::vector<PlaneCorrespondence> planes;
  std::vector<Active> active;
  std::vector<Passive> passive;
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  FixedTerms terms;
};

Eigen::Matrix3d Spd(Sampler* s, double sigma) {
  const Eigen::Matrix3d A = Eigen::Map<const Eigen::Matrix3d>(s->Gaussian(9, sigma).data());
  return A * A.transpose() + sigma * sigma * Eigen::Matrix3d::Identity();
}

// x_hat with teammates 2, 7 (and 11 when `third`), observations of the
// teammates in `observed`: two active ones and one passive one each.
void MakeProblem(unsigned seed, bool third, const std::vector<int>& observed, Problem* pr) {
  Sampler s(seed);
  pr->x_hat = s.State(third ? 3 : 2);  // ids 2, 7, 12
  const int n = pr->x_hat.Dim();
  pr->P = s.Covariance(n, 0.1);
  pr->truth = pr->x_hat.BoxPlus(s.Gaussian(n, 0.05));
  pr->planes = s.Scan(pr->truth.ego, 4, 5, 0.05, 0.02);
  const EgoState& e = pr->truth.ego;
  for (int j : observed) {
    const GlobalExtrinsic& T = pr->truth.teammate(j);
    for (int k = 0; k < 2; ++k) {
      Active a;
      a.j = j;
      const Eigen::Vector3d p_bj_in_Gi = e.p_b_in_G + s.Gaussian(3, 4.0);
      a.p_bj_in_Gj = T.R_Ga_Gb().transpose() * (p_bj_in_Gi - T.p_Gb_in_Ga);
      a.z = e.R_G_b().transpose() * (p_bj_in_Gi - e.p_b_in_G) + s.Gaussian(3, 0.02);
      const Eigen::Matrix3d obs = Spd(&s, 0.03), cov_p = Spd(&s, 0.02);
      auto f = std::make_unique<ActiveObservationFactor>(
          a.z, a.p_bj_in_Gj, obs, cov_p, pr->x_hat.ego.R_G_b(), pr->x_hat.teammate(j).R_Ga_Gb());
      const Eigen::Matrix3d A = pr->x_hat.ego.R_G_b().transpose() * pr->x_hat.teammate(j).R_Ga_Gb();
      a.S = obs + A * cov_p * A.transpose();
      pr->terms.terms_.push_back({f.get(), {StateKey::Ego(), StateKey::Extrinsic(j)}});
      pr->costs.push_back(std::move(f));
      pr->active.push_back(a);
    }
    Passive p;
    p.j = j;
    p.dt = -0.04;
    p.R_Gj_bj = s.Rotation().toRotationMatrix();
    const Eigen::Vector3d p_bi_at_tj = e.p_b_in_G + e.v_b_in_G * p.dt;
    const Eigen::Vector3d p_bj_in_Gi = p_bi_at_tj + s.Gaussian(3, 4.0);
    p.p_bj_in_Gj = T.R_Ga_Gb().transpose() * (p_bj_in_Gi - T.p_Gb_in_Ga);
    p.z = p.R_Gj_bj.transpose() *
              (T.R_Ga_Gb().transpose() * (p_bi_at_tj - T.p_Gb_in_Ga) - p.p_bj_in_Gj) +
          s.Gaussian(3, 0.02);
    const Eigen::Matrix3d obs = Spd(&s, 0.03), cov_th = Spd(&s, 0.005), cov_p = Spd(&s, 0.02);
    auto f = std::make_unique<PassiveObservationFactor>(p.z, p.dt, p.R_Gj_bj, p.p_bj_in_Gj, obs,
                                                        cov_th, cov_p, pr->x_hat.ego,
                                                        pr->x_hat.teammate(j));
    const SwarmState& xh = pr->x_hat;
    const Eigen::Vector3d w0 =
        xh.teammate(j).R_Ga_Gb().transpose() *
        (xh.ego.p_b_in_G + xh.ego.v_b_in_G * p.dt - xh.teammate(j).p_Gb_in_Ga);
    const Eigen::Vector3d h0 = p.R_Gj_bj.transpose() * (w0 - p.p_bj_in_Gj);
    p.S = obs + so3::Hat(h0) * cov_th * so3::Hat(h0).transpose() +
          p.R_Gj_bj.transpose() * cov_p * p.R_Gj_bj;
    pr->terms.terms_.push_back({f.get(), {StateKey::Ego(), StateKey::Extrinsic(j)}});
    pr->costs.push_back(std::move(f));
    pr->passive.push_back(p);
  }
}

void AllRows(const Problem& pr, const SwarmState& x, Eigen::MatrixXd* H, Eigen::VectorXd* z) {
  esikf_test::PlaneRows(x, pr.planes, H, z);
  for (const Active& a : pr.active) ActiveRows(x, a, H, z);
  for (const Passive& p : pr.passive) PassiveRows(x, p, H, z);
}

EsikfUpdate OneStep() {
  EsikfUpdateOptions o;
  o.max_iterations = 1;
  return EsikfUpdate(o);
}

// The Schmidt-Kalman step with the full observation rows at `at`: gain
// K = P_J[kept,:] H^T (H P_J H^T + I)^-1 on the rows `kept`, zero elsewhere,
// P_J the prior in the tangent at `at` (J^-1 P J^-T), Joseph-form covariance.
void SchmidtStep(const Problem& pr, const SwarmState& at, const std::vector<int>& kept,
                 Eigen::VectorXd* dx, Eigen::MatrixXd* P_plus) {
  const int n = pr.x_hat.Dim();
  Eigen::MatrixXd H;
  Eigen::VectorXd z;
  AllRows(pr, at, &H, &z);
  const Eigen::VectorXd e = at.BoxMinus(pr.x_hat);
  Eigen::MatrixXd J_inv = Eigen::MatrixXd::Identity(n, n);
  J_inv.block<3, 3>(0, 0) = so3::RightJacobian(e.head<3>());
  for (int id : pr.x_hat.layout().teammate_ids()) {
    const int o = pr.x_hat.layout().TeammateRotation(id).offset;
    J_inv.block<3, 3>(o, o) = so3::RightJacobian(e.segment<3>(o));
  }
  const Eigen::MatrixXd P_J = J_inv * pr.P * J_inv.transpose();
  const Eigen::MatrixXd S = H * P_J * H.transpose() + Eigen::MatrixXd::Identity(H.rows(), H.rows());
  const Eigen::MatrixXd K_all = P_J * H.transpose() * S.inverse();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, H.rows());
  for (int r : kept) K.row(r) = K_all.row(r);
  const Eigen::MatrixXd I_KH = Eigen::MatrixXd::Identity(n, n) - K * H;
  *P_plus = I_KH * P_J * I_KH.transpose() + K * K.transpose();
  *dx = -K * z;
}

TEST(EsikfMutualUpdate, OneStepEqualsTheIteratedKalmanStepWithBothObservationTypes) {
  Problem pr;
  MakeProblem(11, false, {2, 7}, &pr);
  const std::vector<PlaneCorrespondence> planes = pr.planes;
  double worst_dx = 0.0, worst_P = 0.0;
  Sampler s(5);
  for (double start_scale : {0.0, 0.03, 0.2}) {
    SCOPED_TRACE(start_scale);
    const SwarmState x_i = pr.x_hat.BoxPlus(s.Gaussian(pr.x_hat.Dim(), start_scale));
    PlaneMeasurementModel plane_model(
        [&planes](const SwarmState&, std::vector<PlaneCorrespondence>* out) {
          *out = planes;
          return Status::Ok();
        });
    const EsikfUpdateResult result =
        OneStep().RunFrom(pr.x_hat, pr.P, x_i, {&plane_model, &pr.terms});
    ASSERT_TRUE(result.status.ok()) << result.status.message();
    ASSERT_EQ(result.num_rejected_steps, 0);
    EXPECT_EQ(result.num_residual_blocks, 1 + 6);
    Eigen::MatrixXd H;
    Eigen::VectorXd z;
    AllRows(pr, x_i, &H, &z);
    const esikf_test::IekfStep step = esikf_test::ClosedFormIekfStep(pr.x_hat, pr.P, x_i, H, z);
    AllRows(pr, result.state, &H, &z);
    const esikf_test::IekfStep at_solution =
        esikf_test::ClosedFormIekfStep(pr.x_hat, pr.P, result.state, H, z);
    const double dx_err = MaxAbs(result.state.BoxMinus(x_i) - step.dx);
    const double P_err = MaxAbs(result.covariance - at_solution.P);
    EXPECT_LT(dx_err, 1e-9);
    EXPECT_LT(P_err, 1e-9);
    // The observations moved the teammate blocks (a real comparison).
    EXPECT_GT(step.dx.segment<6>(18).norm(), 1e-3);
    EXPECT_GT(step.dx.segment<6>(24).norm(), 1e-3);
    worst_dx = std::max(worst_dx, dx_err);
    worst_P = std::max(worst_P, P_err);
  }
  RecordProperty("max_abs_dx_diff", std::to_string(worst_dx));
  RecordProperty("max_abs_P_diff", std::to_string(worst_P));
}

// Only teammate 7 observed; teammates 2 and 12 left out of the update.
TEST(EsikfMutualUpdate, SubsetUpdateIsTheSchmidtKalmanUpdate) {
  Problem pr;
  MakeProblem(12, true, {7}, &pr);
  const std::vector<PlaneCorrespondence> planes = pr.planes;
  PlaneMeasurementModel plane_model([&planes](const SwarmState&, std::vector<PlaneCorrespondence>* out) {
    *out = planes;
    return Status::Ok();
  });
  const std::vector<int> estimated = {7};
  const EsikfUpdateResult result =
      OneStep().Run(pr.x_hat, pr.P, {&plane_model, &pr.terms}, &estimated);
  ASSERT_TRUE(result.status.ok()) << result.status.message();

  // Full-state rows, gain zeroed for the blocks left out, Joseph form. The
  // step from the rows at x_hat; the covariance from the rows and the prior
  // correction J at the solution (as the IEKF reports it, see the first test).
  std::vector<int> kept;
  for (int k = 0; k < 18; ++k) kept.push_back(k);
  for (int k = 0; k < 6; ++k) kept.push_back(pr.x_hat.layout().TeammateBlock(7).offset + k);
  Eigen::VectorXd dx, unused_dx;
  Eigen::MatrixXd unused_P, P_plus;
  SchmidtStep(pr, pr.x_hat, kept, &dx, &unused_P);
  SchmidtStep(pr, result.state, kept, &unused_dx, &P_plus);
  const double dx_err = MaxAbs(result.state.BoxMinus(pr.x_hat) - dx);
  const double P_err = MaxAbs(result.covariance - P_plus);
  EXPECT_LT(dx_err, 1e-9);
  EXPECT_LT(P_err, 1e-9);
  // The blocks left out kept their estimate and marginal covariance.
  for (int id : {2, 12}) {
    const Segment b = pr.x_hat.layout().TeammateBlock(id);
    EXPECT_EQ(result.state.teammate(id).p_Gb_in_Ga, pr.x_hat.teammate(id).p_Gb_in_Ga);
    EXPECT_EQ(MaxAbs(result.covariance.block(b.offset, b.offset, 6, 6) -
                     pr.P.block(b.offset, b.offset, 6, 6)),
              0.0);
  }
  // ... and their cross-covariance with the ego state changed.
  const Segment b2 = pr.x_hat.layout().TeammateBlock(2);
  EXPECT_GT(MaxAbs(result.covariance.block(0, b2.offset, 18, 6) - pr.P.block(0, b2.offset, 18, 6)),
            1e-6);
}

// Teammates 7 and 12 observed; 7 estimated, 12 considered (the degeneracy
// policy "freeze extrinsics"), 2 left out. The Schmidt-Kalman update with the
// full observation rows: gain K_s = P_J[s,:] H^T (H P_J H^T + I)^-1 for the
// ego and block 7, zero elsewhere, Joseph-form covariance. Block 12's
// covariance enters the gain; its mean, its marginal covariance and its
// cross-covariance with block 2 stay.
TEST(EsikfMutualUpdate, ConsideredBlocksEnterTheGainAndStayUncorrected) {
  Problem pr;
  MakeProblem(14, true, {7, 12}, &pr);
  const std::vector<PlaneCorrespondence> planes = pr.planes;
  PlaneMeasurementModel plane_model([&planes](const SwarmState&, std::vector<PlaneCorrespondence>* out) {
    *out = planes;
    return Status::Ok();
  });
  const std::vector<int> estimated = {7};
  const std::vector<int> considered = {12};
  const EsikfUpdateResult result =
      OneStep().Run(pr.x_hat, pr.P, {&plane_model, &pr.terms}, &estimated, &considered);
  ASSERT_TRUE(result.status.ok()) << result.status.message();
  // Letting block 12 move in the solve (estimating it) moves the ego state
  // differently from the considered update (the rows of the next iteration
  // would be linearized there), so the comparison below can tell.
  const std::vector<int> both = {7, 12};
  const EsikfUpdateResult joint =
      EsikfUpdate().Run(pr.x_hat, pr.P, {&plane_model, &pr.terms}, &both);
  ASSERT_TRUE(joint.status.ok());
  EXPECT_GT((joint.state.teammate(12).p_Gb_in_Ga - pr.x_hat.teammate(12).p_Gb_in_Ga).norm(), 1e-3);

  const int n = pr.x_hat.Dim();
  const ErrorStateLayout& layout = pr.x_hat.layout();
  std::vector<int> kept;
  for (int k = 0; k < 18; ++k) kept.push_back(k);
  for (int k = 0; k < 6; ++k) kept.push_back(layout.TeammateBlock(7).offset + k);
  Eigen::VectorXd dx, unused_dx;
  Eigen::MatrixXd unused_P, P_plus;
  SchmidtStep(pr, pr.x_hat, kept, &dx, &unused_P);
  SchmidtStep(pr, result.state, kept, &unused_dx, &P_plus);
  const double dx_err = MaxAbs(result.state.BoxMinus(pr.x_hat) - dx);
  EXPECT_LT(dx_err, 1e-9);
  // Rows of the ego state and block 7 against every block.
  double P_err = 0.0;
  for (int r : kept) P_err = std::max(P_err, MaxAbs(result.covariance.row(r) - P_plus.row(r)));
  EXPECT_LT(P_err, 1e-9);
  RecordProperty("max_abs_dx_diff", std::to_string(dx_err));
  RecordProperty("max_abs_P_diff", std::to_string(P_err));
  // Block 12: mean, marginal covariance, cross-covariance with block 2 kept.
  const Segment b12 = layout.TeammateBlock(12);
  const Segment b2 = layout.TeammateBlock(2);
  EXPECT_EQ(result.state.teammate(12).p_Gb_in_Ga, pr.x_hat.teammate(12).p_Gb_in_Ga);
  EXPECT_EQ(result.state.teammate(12).q_Ga_Gb.coeffs(), pr.x_hat.teammate(12).q_Ga_Gb.coeffs());
  EXPECT_EQ(MaxAbs(result.covariance.block(b12.offset, b12.offset, 6, 6) -
                   pr.P.block(b12.offset, b12.offset, 6, 6)),
            0.0);
  EXPECT_EQ(MaxAbs(result.covariance.block(b12.offset, b2.offset, 6, 6) -
                   pr.P.block(b12.offset, b2.offset, 6, 6)),
            0.0);
  // Iterated: block 12 stays at its prior mean through every iteration.
  const EsikfUpdateResult iterated =
      EsikfUpdate().Run(pr.x_hat, pr.P, {&plane_model, &pr.terms}, &estimated, &considered);
  ASSERT_TRUE(iterated.status.ok());
  EXPECT_GT(iterated.iterations, 1);
  EXPECT_EQ(iterated.state.teammate(12).p_Gb_in_Ga, pr.x_hat.teammate(12).p_Gb_in_Ga);
  EXPECT_EQ(iterated.state.teammate(12).q_Ga_Gb.coeffs(), pr.x_hat.teammate(12).q_Ga_Gb.coeffs());
  // The considered block mattered: leaving its covariance out (block 12
  // held exact, the former "frozen" form) gives another ego step.
  EXPECT_GT(dx.head<6>().norm(), 1e-3);
  Eigen::MatrixXd P_exact = pr.P;
  P_exact.block(b12.offset, 0, 6, n).setZero();
  P_exact.block(0, b12.offset, n, 6).setZero();
  P_exact.block(b12.offset, b12.offset, 6, 6) = 1e-12 * Eigen::Matrix<double, 6, 6>::Identity();
  const EsikfUpdateResult exact =
      OneStep().Run(pr.x_hat, P_exact, {&plane_model, &pr.terms}, &estimated, &considered);
  ASSERT_TRUE(exact.status.ok());
  EXPECT_GT((exact.state.BoxMinus(pr.x_hat) - dx).head<6>().norm(), 1e-4);
}

TEST(EsikfMutualUpdate, ABlockBothEstimatedAndConsideredIsAnError) {
  Problem pr;
  MakeProblem(15, true, {7}, &pr);
  const std::vector<int> estimated = {7};
  const std::vector<int> considered = {7};
  EXPECT_EQ(OneStep().Run(pr.x_hat, pr.P, {&pr.terms}, &estimated, &considered).status.code(),
            Status::Code::kInvalidArgument);
  const std::vector<int> absent = {5};
  EXPECT_EQ(OneStep().Run(pr.x_hat, pr.P, {&pr.terms}, &estimated, &absent).status.code(),
            Status::Code::kInvalidArgument);
}

TEST(EsikfMutualUpdate, ResidualBlockNamingAnAbsentTeammateIsAnError) {
  Problem pr;
  MakeProblem(13, false, {2}, &pr);
  const std::vector<int> estimated = {7};  // 2 is observed but left out
  const EsikfUpdateResult result = OneStep().Run(pr.x_hat, pr.P, {&pr.terms}, &estimated);
  EXPECT_EQ(result.status.code(), Status::Code::kInvalidArgument);
  const std::vector<int> unknown = {3};
  EXPECT_EQ(OneStep().Run(pr.x_hat, pr.P, {&pr.terms}, &unknown).status.code(),
            Status::Code::kInvalidArgument);
}

}  // namespace
}  // namespace swarmlio::lio
