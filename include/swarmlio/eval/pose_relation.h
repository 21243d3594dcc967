// Which scalar of an error pose E is evaluated, as evo's PoseRelation:
//   kTranslation     |t(E)|                                   (m)
//   kRotationPart    |R(E) - I|_F                             (unitless)
//   kRotationAngleRad  angle of R(E) in [0, pi]               (rad)
//   kRotationAngleDeg  the same in degrees                    (deg)
//   kFull            |E - I|_F of the 4 x 4 matrix            (unitless)
// All are invariant under E -> E^-1, so evo's APE (which forms P^-1 Q) and
// the Q^-1 P used here give the same numbers.
#pragma once

#include <Eigen/Geometry>
#include <string>

namespace swarmlio::eval {

enum class PoseRelation {
  kTranslation,
  kRotationPart,
  kRotationAngleRad,
  kRotationAngleDeg,
  kFull
};

/// Accepts evo's names and short forms: "trans" / "trans_part",
/// "rot" / "rot_part", "angle_rad", "angle_deg", "full".
bool PoseRelationFromString(const std::string& text, PoseRelation* relation);
/// evo's name: "trans_part", "rot_part", "angle_rad", "angle_deg", "full".
const char* PoseRelationName(PoseRelation relation);
/// "m", "rad", "deg" or "" (unitless).
const char* PoseRelationUnit(PoseRelation relation);

/// The scalar error of the error pose E (see above).
double PoseRelationError(const Eigen::Isometry3d& E, PoseRelation relation);

/// Rotation angle of R in [0, pi] (rad), accurate near 0 and pi.
double RotationAngleRad(const Eigen::Matrix3d& R);

}  // namespace swarmlio::eval
