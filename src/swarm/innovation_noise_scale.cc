#include "innovation_noise_scale.h"

#include <Eigen/Cholesky>
#include <algorithm>

namespace swarmlio::swarm::internal {

double ActiveObservationNis(const ActiveObservationFactor& factor,
                            const SwarmState& x,
                            const Eigen::MatrixXd& P,
                            int id,
                            const Eigen::Vector3d& e,
                            const Eigen::Matrix3d& factor_R,
                            const Eigen::Matrix3d& true_R) {
  constexpr int kE = EgoState::kTangentSize;
  constexpr int kT = GlobalExtrinsic::kTangentSize;
  Eigen::Matrix<double, 3, kE> J_ego;
  Eigen::Matrix<double, 3, kT> J_ext;
  factor.TangentJacobian(x.ego, x.teammate(id), &J_ego, &J_ext);
  // The factor's Jacobians are whitened by U^-1 (S_factor = U U^T).
  const Eigen::Matrix3d U_inv = factor.sqrt_information();
  Eigen::Matrix<double, 3, kE + kT> J;
  J << U_inv.triangularView<Eigen::Lower>().solve(J_ego),
      U_inv.triangularView<Eigen::Lower>().solve(J_ext);
  const Segment b = x.layout().TeammateBlock(id);
  Eigen::Matrix<double, kE + kT, kE + kT> P_sub;
  P_sub.topLeftCorner<kE, kE>() = P.topLeftCorner(kE, kE);
  P_sub.topRightCorner<kE, kT>() = P.block(0, b.offset, kE, kT);
  P_sub.bottomLeftCorner<kT, kE>() = P.block(b.offset, 0, kT, kE);
  P_sub.bottomRightCorner<kT, kT>() = P.block(b.offset, b.offset, kT, kT);
  const Eigen::Matrix3d S = J * P_sub * J.transpose() + factor.covariance() - factor_R + true_R;
  return e.dot(S.ldlt().solve(e));
}

double UpdatedNoiseScale(double scale, double nis, const SwarmOptions& options) {
  const double cap = options.gate_sigma > 0.0 ? options.gate_sigma * options.gate_sigma : 25.0;
  const double ratio = std::min(nis, cap) / 3.0;
  const double next = scale * (1.0 + options.noise_adaptation_rate * (ratio - 1.0));
  return std::clamp(next, options.min_noise_scale, options.max_noise_scale);
}

}  // namespace swarmlio::swarm::internal
