// PointToPlaneFactor: all point-to-plane residuals of one LiDAR scan in ONE
// Ceres cost function over the ego block (paper Sec. III-D, eq. (4);
// docs/esikf.md).
//
// For correspondence n (body point p_n = p_n_in_b, plane normal u_n = n_n in
// G with |n_n| = 1 and offset d_n = -n_n^T q_n for a point q_n on the plane,
// weight w_n = 1/sigma_n^2 [1/m^2]):
//
//   z_n = sqrt(w_n) (n_n^T (R_G_b p_n + p_b_in_G) + d_n)
//       = sqrt(w_n) n_n^T (R_G_b p_n + p_b_in_G - q_n)          (eq. (4))
//
// Tangent Jacobian (right perturbation R_G_b Exp(dtheta), p + dp):
//   dz_n/d dtheta = -sqrt(w_n) n_n^T R_G_b [p_n]x = sqrt(w_n) (p_n x (R_G_b^T n_n))^T
//   dz_n/d dp     =  sqrt(w_n) n_n^T
//   zero for v, b_g, b_a, g.
// The rotation columns are lifted to the quaternion's ambient coordinates
// with SO3Manifold::LiftTangentJacobian; the Jacobian is (N x 19).
//
// Re-association without rebuilding the problem: the factor reads the
// correspondences through a pointer to a container owned by the caller (the
// update loop). The number of residuals is captured by SyncNumResiduals().
// Ceres 2.1 reads a residual block's size from its cost function while it
// builds the program for every Solve, but does not document that the size
// may change while the block is in a Problem, so the update loop removes
// this one residual block, calls SyncNumResiduals(), and adds it again
// (RemoveResidualBlock/AddResidualBlock cost microseconds for a problem with
// two residual blocks; docs/esikf.md). Evaluate CHECKs that the container
// size still matches.
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <vector>

#include "swarmlio/state/swarm_state.h"

namespace swarmlio {

/// One LiDAR point matched to a plane of the map (frames in the names).
struct PlaneCorrespondence {
  Eigen::Vector3d p_in_b = Eigen::Vector3d::Zero();        // undistorted point in b [m]
  Eigen::Vector3d normal_in_G = Eigen::Vector3d::UnitZ();  // unit plane normal u_n in G
  double offset_m = 0.0;  // d_n: plane {y : normal_in_G^T y + offset_m = 0} [m]
  double weight = 1.0;    // w_n = 1 / sigma_n^2 [1/m^2]
};

class PointToPlaneFactor final : public ceres::CostFunction {
 public:
  /// `correspondences` must outlive the factor. Captures its current size.
  explicit PointToPlaneFactor(const std::vector<PlaneCorrespondence>* correspondences);

  /// Re-reads the container size into num_residuals(). Call only while the
  /// factor is in no ceres::Problem (see the header comment).
  void SyncNumResiduals();

  bool Evaluate(double const* const* parameters,
                double* residuals,
                double** jacobians) const override;

  /// Adds H^T H (6x6, over [dtheta, dp] of the ego block) and H^T z of all
  /// correspondences at `ego`, for the posterior covariance and for tests.
  void AccumulateNormalEquations(const EgoState& ego,
                                 Eigen::Matrix<double, 6, 6>* HtH,
                                 Eigen::Matrix<double, 6, 1>* Htz) const;

 private:
  const std::vector<PlaneCorrespondence>* correspondences_;
};

}  // namespace swarmlio
