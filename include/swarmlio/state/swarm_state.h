// The per-drone state x_i of the paper (Sec. III-D), on the manifold
//   M = SO(3) x R^15 x (SO(3) x R^3)^(N-1),
// with the paper's boxplus / boxminus (right perturbation):
//   [R; a] (+) [r; b] = [R Exp(r); a + b]
//   [R1; a] (-) [R2; b] = [Log(R2^T R1); a - b]
// The error-state ordering is ErrorStateLayout (state_layout.h).
//
// Ceres parameter blocks (factors/ego_state_manifold.h,
// factors/global_extrinsic_manifold.h) use the ambient layouts
//   ego      (19): [q_G_b (x y z w) | p_b_in_G | v_b_in_G | b_g | b_a | g_in_G]
//   teammate  (7): [q_Ga_Gb (x y z w) | p_Gb_in_Ga] = T_Gi_Gj of teammate j
// whose tangent spaces are exactly the corresponding error-state segments.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "swarmlio/state/state_layout.h"

namespace swarmlio {

/// Ego state of one drone in its own global frame G (= its initial IMU frame).
struct EgoState {
  static constexpr int kAmbientSize = 19;
  static constexpr int kTangentSize = ErrorStateLayout::kEgoDim;

  Eigen::Quaterniond q_G_b = Eigen::Quaterniond::Identity();  // attitude R_G_b
  Eigen::Vector3d p_b_in_G = Eigen::Vector3d::Zero();          // [m]
  Eigen::Vector3d v_b_in_G = Eigen::Vector3d::Zero();          // [m/s]
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();         // [rad/s]
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();        // [m/s^2]
  Eigen::Vector3d g_in_G = Eigen::Vector3d(0.0, 0.0, -9.81);   // gravity [m/s^2]

  Eigen::Matrix3d R_G_b() const { return q_G_b.toRotationMatrix(); }

  /// Writes the 19-double Ceres parameter block.
  void ToParameters(double* x) const;
  /// Reads a 19-double Ceres parameter block.
  static EgoState FromParameters(const double* x);

  EgoState BoxPlus(const Eigen::Matrix<double, kTangentSize, 1>& dx) const;
  /// this (-) other, in the error-state order of ErrorStateLayout.
  Eigen::Matrix<double, kTangentSize, 1> BoxMinus(const EgoState& other) const;
};

/// Global extrinsic T_Ga_Gb between two drones' global frames G_a and G_b:
/// p_in_Ga = R_Ga_Gb p_in_Gb + p_Gb_in_Ga. The names are neutral because the
/// same type holds several pairs: in a SwarmState block a is the owning drone
/// i and b its teammate j (T_Gi_Gj); a composed, inverted or received value
/// says which in its variable name (T_jk, T_Gj_Gk: a = j, b = k).
struct GlobalExtrinsic {
  static constexpr int kAmbientSize = 7;
  static constexpr int kTangentSize = ErrorStateLayout::kTeammateDim;

  Eigen::Quaterniond q_Ga_Gb = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_Gb_in_Ga = Eigen::Vector3d::Zero();  // [m]

  Eigen::Matrix3d R_Ga_Gb() const { return q_Ga_Gb.toRotationMatrix(); }
  Eigen::Isometry3d T_Ga_Gb() const;

  void ToParameters(double* x) const;
  static GlobalExtrinsic FromParameters(const double* x);

  GlobalExtrinsic BoxPlus(const Eigen::Matrix<double, kTangentSize, 1>& dx) const;
  Eigen::Matrix<double, kTangentSize, 1> BoxMinus(const GlobalExtrinsic& other) const;
};

/// Ego state plus one global extrinsic per identified teammate.
class SwarmState {
 public:
  EgoState ego;

  const ErrorStateLayout& layout() const { return layout_; }
  int Dim() const { return layout_.Dim(); }

  bool HasTeammate(int id) const { return layout_.HasTeammate(id); }
  /// Adds teammate `id` at the end of the layout (CHECK-fails when present).
  void AddTeammate(int id, const GlobalExtrinsic& T_Gi_Gj);
  /// Removes teammate `id` (CHECK-fails when absent).
  void RemoveTeammate(int id);
  const GlobalExtrinsic& teammate(int id) const;
  GlobalExtrinsic& teammate(int id);

  /// x (+) dx with dx.size() == Dim().
  SwarmState BoxPlus(const Eigen::VectorXd& dx) const;
  /// this (-) other; both must have the same layout (CHECK).
  Eigen::VectorXd BoxMinus(const SwarmState& other) const;

 private:
  ErrorStateLayout layout_;
  std::vector<GlobalExtrinsic> teammates_;  // in layout slot order
};

}  // namespace swarmlio
