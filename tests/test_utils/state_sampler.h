// Test helper: seeded random states for factor and estimator tests: an ego
// state, a global extrinsic, a swarm state with teammates, SPD covariances.
// One copy for every test that needs a random point on the state manifold.
#pragma once

#include <Eigen/Core>

#include "swarmlio/state/swarm_state.h"
#include "test_utils/random_sampler.h"

namespace swarmlio::testing {

class StateSampler : public RandomSampler {
 public:
  using RandomSampler::RandomSampler;

  // Attitude rotated by `angle` about a random axis (uniform when < 0);
  // position within ~5 m, velocity ~1 m/s, small biases, |g| = 9.81 m/s^2
  // in a random direction (every block is exercised by the Jacobian checks).
  EgoState Ego(double angle) {
    EgoState ego;
    ego.q_G_b = Rotation(angle);
    ego.p_b_in_G = Gaussian3(5.0);
    ego.v_b_in_G = Gaussian3(1.0);
    ego.gyro_bias = Gaussian3(0.01);
    ego.accel_bias = Gaussian3(0.1);
    ego.g_in_G = 9.81 * Gaussian3(1.0).normalized();
    return ego;
  }

  // T_Gi_Gj rotated by `angle` (uniform when < 0), origin within ~10 m.
  GlobalExtrinsic Extrinsic(double angle) {
    GlobalExtrinsic T;
    T.q_Ga_Gb = Rotation(angle);
    T.p_Gb_in_Ga = Gaussian3(10.0);
    return T;
  }

  // An ego state with `num_teammates` extrinsics (ids 3, 7, 11, ...: ids
  // need not be slots).
  SwarmState State(int num_teammates, double angle) {
    SwarmState x;
    x.ego = Ego(angle);
    for (int j = 0; j < num_teammates; ++j) x.AddTeammate(3 + 4 * j, Extrinsic(angle));
    return x;
  }

  // A random SPD n x n matrix A A^T + floor I, A with entries ~ N(0, scale^2).
  Eigen::MatrixXd Covariance(int n, double scale, double floor) {
    const Eigen::VectorXd a = Gaussian(n * n, scale);
    const Eigen::MatrixXd A = Eigen::Map<const Eigen::MatrixXd>(a.data(), n, n);
    return A * A.transpose() + floor * Eigen::MatrixXd::Identity(n, n);
  }
  Eigen::Matrix3d Covariance3(double scale, double floor) { return Covariance(3, scale, floor); }
};

}  // namespace swarmlio::testing
