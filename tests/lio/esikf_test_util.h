// Shared by the EsikfUpdate tests: a seeded sampler of states, covariances
// and plane scans, and the closed-form iterated Kalman step written out
// independently of Ceres (docs/esikf.md):
//
//   e     = x_i (-) x_hat,   J^-1 = blockdiag(Jr(e_R), I, ...)
//   P_J   = J^-1 P_hat J^-T
//   K     = (H^T H + P_J^-1)^-1 H^T          (H, z whitened)
//   dx_i  = -K z_i - (I - K H) J^-1 e,       x_{i+1} = x_i (+) dx_i
//   P     = (I - K H) P_J
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

#include "factors/point_to_plane_factor.h"
#include "swarmlio/math/so3.h"
#include "swarmlio/state/swarm_state.h"

namespace swarmlio::lio::esikf_test {

class Sampler {
 public:
  explicit Sampler(unsigned seed) : rng_(seed) {}
  double Normal() { return n_(rng_); }
  double Uniform(double lo, double hi) { return std::uniform_real_distribution<>(lo, hi)(rng_); }
  Eigen::VectorXd Gaussian(int n, double scale) {
    Eigen::VectorXd v(n);
    for (int i = 0; i < n; ++i) v[i] = scale * Normal();
    return v;
  }
  Eigen::Vector3d Axis() { return Eigen::Vector3d(Gaussian(3, 1.0)).normalized(); }
  Eigen::Quaterniond Rotation() {
    return Eigen::Quaterniond(Eigen::Vector4d(Gaussian(4, 1.0)).normalized());
  }
  SwarmState State(int num_teammates) {
    SwarmState x;
    x.ego.q_G_b = Rotation();
    x.ego.p_b_in_G = Gaussian(3, 5.0);
    x.ego.v_b_in_G = Gaussian(3, 1.0);
    x.ego.gyro_bias = Gaussian(3, 0.01);
    x.ego.accel_bias = Gaussian(3, 0.1);
    x.ego.g_in_G = Eigen::Vector3d(0.1, -0.2, -9.8);
    for (int j = 0; j < num_teammates; ++j) {
      GlobalExtrinsic T;
      T.q_Ga_Gb = Rotation();
      T.p_Gb_in_Ga = Gaussian(3, 10.0);
      x.AddTeammate(2 + 5 * j, T);
    }
    return x;
  }
  // Dense SPD covariance with standard deviations of order `scale`.
  Eigen::MatrixXd Covariance(int n, double scale) {
    const Eigen::VectorXd a = Gaussian(n * n, scale / std::sqrt(n));
    const Eigen::MatrixXd A = Eigen::Map<const Eigen::MatrixXd>(a.data(), n, n);
    return A * A.transpose() + 0.1 * scale * scale * Eigen::MatrixXd::Identity(n, n);
  }
  // Points on `num_planes` random planes around the body of `truth`, with
  // noise `noise_m` along the normal; weight 1/sigma_m^2.
  std::vector<PlaneCorrespondence> Scan(
      const EgoState& truth, int num_planes, int per_plane, double sigma_m, double noise_m) {
    std::vector<PlaneCorrespondence> out;
    for (int k = 0; k < num_planes; ++k) {
      const Eigen::Vector3d n = Axis();
      const Eigen::Vector3d q = truth.p_b_in_G + Gaussian(3, 6.0);
      const Eigen::Vector3d t1 = n.unitOrthogonal();
      const Eigen::Vector3d t2 = n.cross(t1);
      for (int i = 0; i < per_plane; ++i) {
        const Eigen::Vector3d y =
            q + Uniform(-4, 4) * t1 + Uniform(-4, 4) * t2 + noise_m * Normal() * n;
        PlaneCorrespondence c;
        c.p_in_b = truth.R_G_b().transpose() * (y - truth.p_b_in_G);
        c.normal_in_G = n;
        c.offset_m = -n.dot(q);
        c.weight = 1.0 / (sigma_m * sigma_m);
        out.push_back(c);
      }
    }
    return out;
  }

 private:
  std::mt19937 rng_;
  std::normal_distribution<double> n_;
};

struct IekfStep {
  Eigen::VectorXd dx;
  Eigen::MatrixXd P;
};

// The closed-form IEKF step at x_i with whitened residuals z and Jacobian H
// (rows: measurements, columns: x_hat's error state), explicit inverses.
inline IekfStep ClosedFormIekfStep(const SwarmState& x_hat, const Eigen::MatrixXd& P_hat,
                                   const SwarmState& x_i, const Eigen::MatrixXd& H,
                                   const Eigen::VectorXd& z) {
  const int n = x_hat.Dim();
  const Eigen::VectorXd e = x_i.BoxMinus(x_hat);
  Eigen::MatrixXd J_inv = Eigen::MatrixXd::Identity(n, n);
  J_inv.block<3, 3>(0, 0) = so3::RightJacobian(e.head<3>());
  for (int id : x_hat.layout().teammate_ids()) {
    const int o = x_hat.layout().TeammateRotation(id).offset;
    J_inv.block<3, 3>(o, o) = so3::RightJacobian(e.segment<3>(o));
  }
  const Eigen::MatrixXd P_J = J_inv * P_hat * J_inv.transpose();
  const Eigen::MatrixXd K = (H.transpose() * H + P_J.inverse()).inverse() * H.transpose();
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(n, n);
  IekfStep step;
  step.dx = -K * z - (I - K * H) * J_inv * e;
  step.P = (I - K * H) * P_J;
  return step;
}

// Whitened point-to-plane residuals and Jacobian at x (eq. (4)).
inline void PlaneRows(const SwarmState& x, const std::vector<PlaneCorrespondence>& corr,
                      Eigen::MatrixXd* H, Eigen::VectorXd* z) {
  const int m = static_cast<int>(corr.size());
  *H = Eigen::MatrixXd::Zero(m, x.Dim());
  *z = Eigen::VectorXd(m);
  const Eigen::Matrix3d R = x.ego.R_G_b();
  for (int k = 0; k < m; ++k) {
    const PlaneCorrespondence& c = corr[k];
    const double s = std::sqrt(c.weight);
    (*z)[k] = s * (c.normal_in_G.dot(R * c.p_in_b + x.ego.p_b_in_G) + c.offset_m);
    H->block<1, 3>(k, 0) = -s * c.normal_in_G.transpose() * R * so3::Hat(c.p_in_b);
    H->block<1, 3>(k, 3) = s * c.normal_in_G.transpose();
  }
}

}  // namespace swarmlio::lio::esikf_test
