// SO(3) helpers: hat/vee, the exponential and logarithm maps, and the right
// Jacobian with its inverse. Conventions (docs/conventions.md):
//   Exp(w) = I + sin(t)/t [w]x + (1 - cos(t))/t^2 [w]x^2,   t = |w|
//   Log(R) in the ball |w| <= pi (the shortest rotation)
//   Right perturbation: R Exp(dr).  Exp(w + d) ~= Exp(w) Exp(Jr(w) d).
//   Jr(w)    = I - (1 - cos t)/t^2 [w]x + (t - sin t)/t^3 [w]x^2
//   Jr^-1(w) = I + 1/2 [w]x + (1/t^2 - (1 + cos t)/(2 t sin t)) [w]x^2
// All functions are exact to double precision at t -> 0 (Taylor branches) and
// well defined up to t = pi (Log picks either axis at exactly pi).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace swarmlio::so3 {

/// Skew-symmetric matrix [w]x such that [w]x v = w x v.
Eigen::Matrix3d Hat(const Eigen::Vector3d& w);

/// Inverse of Hat (reads the skew part; no check that m is skew).
Eigen::Vector3d Vee(const Eigen::Matrix3d& m);

/// Rotation matrix of the rotation vector w (axis * angle, rad).
Eigen::Matrix3d Exp(const Eigen::Vector3d& w);

/// Unit quaternion of the rotation vector w; its real part is >= 0 for |w| <= pi.
Eigen::Quaterniond ExpQuaternion(const Eigen::Vector3d& w);

/// Rotation vector of R with |w| <= pi. R must be a rotation matrix.
Eigen::Vector3d Log(const Eigen::Matrix3d& R);

/// Rotation vector of the rotation q represents, |w| <= pi (q and -q give the
/// same result). q need not be normalised.
Eigen::Vector3d Log(const Eigen::Quaterniond& q);

/// Logarithm on the unit quaternions S^3 (the double cover): the w with
/// ExpQuaternion(w) == q/|q| exactly, |w| < 2 pi. Equals Log(q) when q.w() >= 0.
Eigen::Vector3d LogQuaternionNoWrap(const Eigen::Quaterniond& q);

/// Right Jacobian Jr(w).
Eigen::Matrix3d RightJacobian(const Eigen::Vector3d& w);

/// Inverse of the right Jacobian, valid for |w| < 2 pi.
Eigen::Matrix3d RightJacobianInverse(const Eigen::Vector3d& w);

/// Left Jacobian Jl(w) = Jr(-w).
Eigen::Matrix3d LeftJacobian(const Eigen::Vector3d& w);

/// Inverse of the left Jacobian, Jl^-1(w) = Jr^-1(-w).
Eigen::Matrix3d LeftJacobianInverse(const Eigen::Vector3d& w);

/// Projects a nearly orthonormal matrix onto SO(3) (via the quaternion).
Eigen::Matrix3d Normalize(const Eigen::Matrix3d& R);

/// The rotation of q after normalizing it (a state's quaternion may drift
/// off the unit sphere by round-off between updates).
inline Eigen::Matrix3d RotationOf(const Eigen::Quaterniond& q) {
  return q.normalized().toRotationMatrix();
}

}  // namespace swarmlio::so3
