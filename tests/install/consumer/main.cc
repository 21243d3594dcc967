// A downstream program: uses the installed headers and libraries, including
// the Jacobian checker (swarmlio::swarmlio_testing) on an installed factor.
#include <array>
#include <cstdio>

#include "factors/active_observation_factor.h"
#include "factors/ego_state_manifold.h"
#include "factors/global_extrinsic_manifold.h"
#include "swarmlio/io/bag_options.h"
#include "swarmlio/state/swarm_state.h"
#include "swarmlio/testing/jacobian_check.h"

int main() {
  swarmlio::SwarmState x;
  x.AddTeammate(2, swarmlio::GlobalExtrinsic());
  swarmlio::EgoStateManifold manifold;
  swarmlio::io::BagReaderOptions options;
  bool ok = x.Dim() == 24 && manifold.TangentSize() == 18 && options.Validate().empty();

  // The Jacobian checker accepts the factor and rejects a flipped rotation sign.
  x.ego.q_G_b = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  x.ego.p_b_in_G = Eigen::Vector3d(1.0, -2.0, 0.5);
  x.teammate(2).q_Ga_Gb = Eigen::Quaterniond(Eigen::AngleAxisd(-1.1, Eigen::Vector3d::UnitZ()));
  x.teammate(2).p_Gb_in_Ga = Eigen::Vector3d(4.0, 1.0, -0.3);
  const swarmlio::ActiveObservationFactor factor(
      Eigen::Vector3d(3.0, 0.5, 0.2), Eigen::Vector3d(-1.0, 2.0, 0.4),
      0.01 * Eigen::Matrix3d::Identity(), 0.02 * Eigen::Matrix3d::Identity(), x.ego.R_G_b(),
      x.teammate(2).R_Ga_Gb());
  std::array<double, 19> ego;
  std::array<double, 7> extrinsic;
  x.ego.ToParameters(ego.data());
  x.teammate(2).ToParameters(extrinsic.data());
  swarmlio::GlobalExtrinsicManifold extrinsic_manifold;
  const std::vector<const ceres::Manifold*> manifolds = {&manifold, &extrinsic_manifold};
  const std::vector<const double*> parameters = {ego.data(), extrinsic.data()};
  const swarmlio::testing::FlippedJacobianColumns flipped(&factor, /*block=*/0,
                                                          /*num_columns=*/4);
  const bool accepts = static_cast<bool>(
      swarmlio::testing::CostFunctionJacobiansAreCorrect(factor, manifolds, parameters));
  const bool rejects_flipped = !static_cast<bool>(
      swarmlio::testing::CostFunctionJacobiansAreCorrect(flipped, manifolds, parameters));
  ok = ok && accepts && rejects_flipped;

  std::printf("swarmlio consumer: state dim %d, jacobian check %s/%s, %s\n", x.Dim(),
              accepts ? "accepts" : "REJECTS", rejects_flipped ? "rejects" : "ACCEPTS",
              ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
