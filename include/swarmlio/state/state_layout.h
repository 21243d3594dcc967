// Named layout of the per-drone error state (paper Sec. III-D, eq. (5)):
//
//   dx = [ dtheta  dp  dv  dbg  dba  dg | dtheta_Gj1 dp_Gj1 | dtheta_Gj2 ... ]
//          0       3   6   9    12   15   18                  24
//
// The first 18 entries are the ego state (rotation R_G_b, position p_b_in_G,
// velocity v_b_in_G, gyro bias, accelerometer bias, gravity g_in_G); then one
// 6-dimensional block (rotation R_Gi_Gj, translation p_Gj_in_Gi) per
// identified teammate, in the order teammates were added. Teammates can be
// added and removed at run time; the layout hands out offsets so that no
// code writes `18 + 6 * id`.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace swarmlio {

/// A contiguous range [offset, offset + size) of the error-state vector.
struct Segment {
  int offset = 0;
  int size = 0;
  int end() const { return offset + size; }
};

class ErrorStateLayout {
 public:
  // Ego-state segments (fixed, identical for every drone).
  static constexpr Segment kRotation{0, 3};
  static constexpr Segment kPosition{3, 3};
  static constexpr Segment kVelocity{6, 3};
  static constexpr Segment kGyroBias{9, 3};
  static constexpr Segment kAccelBias{12, 3};
  static constexpr Segment kGravity{15, 3};
  static constexpr int kEgoDim = 18;
  // Per-teammate global extrinsic T_Gi_Gj: rotation then translation.
  static constexpr int kTeammateDim = 6;
  static constexpr int kTeammateRotationOffset = 0;
  static constexpr int kTeammateTranslationOffset = 3;

  /// Dimension of the whole error state: 18 + 6 * NumTeammates().
  int Dim() const { return kEgoDim + kTeammateDim * NumTeammates(); }
  int NumTeammates() const { return static_cast<int>(teammate_ids_.size()); }
  bool HasTeammate(int id) const { return SlotOf(id) >= 0; }
  /// Teammate ids in slot (error-state) order.
  const std::vector<int>& teammate_ids() const { return teammate_ids_; }
  /// Slot of teammate `id`, or -1 when absent.
  int SlotOf(int id) const;

  /// The 6-dim block of teammate `id` (CHECK-fails when absent).
  Segment TeammateBlock(int id) const;
  Segment TeammateRotation(int id) const;
  Segment TeammateTranslation(int id) const;

  /// Appends teammate `id` (CHECK-fails when present); returns its block.
  Segment AddTeammate(int id);
  /// Removes teammate `id` (CHECK-fails when absent); returns the block it
  /// occupied before removal. Later teammates move down by kTeammateDim.
  Segment RemoveTeammate(int id);

  bool operator==(const ErrorStateLayout& other) const {
    return teammate_ids_ == other.teammate_ids_;
  }
  bool operator!=(const ErrorStateLayout& other) const { return !(*this == other); }

 private:
  std::vector<int> teammate_ids_;
};

/// Grows a covariance for a block appended at the end: P becomes
/// [P 0; 0 P_new]. Pairs with ErrorStateLayout::AddTeammate.
void AppendCovarianceBlock(const Eigen::MatrixXd& P_new, Eigen::MatrixXd* P);

/// Removes rows and columns `segment` from a covariance (the marginal of the
/// remaining variables). Pairs with ErrorStateLayout::RemoveTeammate.
void EraseCovarianceBlock(const Segment& segment, Eigen::MatrixXd* P);

}  // namespace swarmlio
