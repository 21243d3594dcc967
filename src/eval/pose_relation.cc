#include "swarmlio/eval/pose_relation.h"

#include <cmath>

namespace swarmlio::eval {

namespace {

constexpr double kDegreesPerRadian = 180.0 / 3.14159265358979323846;

}  // namespace

bool PoseRelationFromString(const std::string& text, PoseRelation* relation) {
  if (text == "trans" || text == "trans_part") {
    *relation = PoseRelation::kTranslation;
  } else if (text == "rot" || text == "rot_part") {
    *relation = PoseRelation::kRotationPart;
  } else if (text == "angle_rad") {
    *relation = PoseRelation::kRotationAngleRad;
  } else if (text == "angle_deg") {
    *relation = PoseRelation::kRotationAngleDeg;
  } else if (text == "full") {
    *relation = PoseRelation::kFull;
  } else {
    return false;
  }
  return true;
}

const char* PoseRelationName(PoseRelation relation) {
  switch (relation) {
    case PoseRelation::kTranslation:
      return "trans_part";
    case PoseRelation::kRotationPart:
      return "rot_part";
    case PoseRelation::kRotationAngleRad:
      return "angle_rad";
    case PoseRelation::kRotationAngleDeg:
      return "angle_deg";
    case PoseRelation::kFull:
      return "full";
  }
  return "?";
}

const char* PoseRelationUnit(PoseRelation relation) {
  switch (relation) {
    case PoseRelation::kTranslation:
      return "m";
    case PoseRelation::kRotationAngleRad:
      return "rad";
    case PoseRelation::kRotationAngleDeg:
      return "deg";
    case PoseRelation::kRotationPart:
    case PoseRelation::kFull:
      return "";
  }
  return "";
}

double RotationAngleRad(const Eigen::Matrix3d& R) {
  // Via the quaternion (Shepperd's method in Eigen): atan2 keeps full
  // precision near 0 and pi, where acos((tr R - 1) / 2) loses digits.
  Eigen::Quaterniond q(R);
  q.normalize();
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w()));
}

double PoseRelationError(const Eigen::Isometry3d& E, PoseRelation relation) {
  switch (relation) {
    case PoseRelation::kTranslation:
      return E.translation().norm();
    case PoseRelation::kRotationPart:
      return (E.linear() - Eigen::Matrix3d::Identity()).norm();
    case PoseRelation::kRotationAngleRad:
      return RotationAngleRad(E.linear());
    case PoseRelation::kRotationAngleDeg:
      return RotationAngleRad(E.linear()) * kDegreesPerRadian;
    case PoseRelation::kFull:
      return (E.matrix() - Eigen::Matrix4d::Identity()).norm();
  }
  return 0.0;
}

}  // namespace swarmlio::eval
