#include "swarmlio/math/so3.h"

#include <cmath>

namespace swarmlio::so3 {
namespace {

// Below these angles the closed forms lose digits to cancellation; the Taylor
// series used instead are exact to double precision there.
constexpr double kExpSeriesAngle = 1e-5;       // sin(t)/t, (1-cos t)/t^2
constexpr double kJacobianSeriesAngle = 1e-2;  // (t - sin t)/t^3 and Jr^-1 coefficient

}  // namespace

Eigen::Matrix3d Hat(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0.0, -w.z(), w.y(),  //
      w.z(), 0.0, -w.x(),   //
      -w.y(), w.x(), 0.0;
  return m;
}

Eigen::Vector3d Vee(const Eigen::Matrix3d& m) {
  return Eigen::Vector3d(m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1)) * 0.5;
}

Eigen::Matrix3d Exp(const Eigen::Vector3d& w) {
  const double t2 = w.squaredNorm();
  const double t = std::sqrt(t2);
  double a;  // sin(t)/t
  double b;  // (1 - cos t)/t^2
  if (t < kExpSeriesAngle) {
    a = 1.0 - t2 / 6.0;
    b = 0.5 - t2 / 24.0;
  } else {
    a = std::sin(t) / t;
    const double s = std::sin(0.5 * t);
    b = 2.0 * s * s / t2;
  }
  const Eigen::Matrix3d W = Hat(w);
  return Eigen::Matrix3d::Identity() + a * W + b * W * W;
}

Eigen::Quaterniond ExpQuaternion(const Eigen::Vector3d& w) {
  const double t2 = w.squaredNorm();
  const double t = std::sqrt(t2);
  double real;
  double k;  // sin(t/2)/t
  if (t < kExpSeriesAngle) {
    real = 1.0 - t2 / 8.0;
    k = 0.5 - t2 / 48.0;
  } else {
    real = std::cos(0.5 * t);
    k = std::sin(0.5 * t) / t;
  }
  return Eigen::Quaterniond(real, k * w.x(), k * w.y(), k * w.z());
}

Eigen::Vector3d LogQuaternionNoWrap(const Eigen::Quaterniond& q) {
  const Eigen::Vector3d v = q.vec();
  const double vn = v.norm();
  const double real = q.w();
  if (real > 0.0 && vn < 1e-8 * real) {
    // t = 2 atan2(|v|, w) ~ 2|v|/w (1 - |v|^2/(3 w^2)); the correction is
    // below double precision here.
    return (2.0 / real) * v;
  }
  if (vn == 0.0) {
    // q = -1 (a full turn on S^3, any axis) or q = 0 (not a rotation).
    return real < 0.0 ? Eigen::Vector3d(2.0 * M_PI, 0.0, 0.0) : Eigen::Vector3d::Zero();
  }
  const double t = 2.0 * std::atan2(vn, real);
  return (t / vn) * v;
}

Eigen::Vector3d Log(const Eigen::Quaterniond& q) {
  return q.w() >= 0.0 ? LogQuaternionNoWrap(q) : LogQuaternionNoWrap(Eigen::Quaterniond(
                                                     -q.w(), -q.x(), -q.y(), -q.z()));
}

Eigen::Vector3d Log(const Eigen::Matrix3d& R) {
  // Eigen's matrix-to-quaternion conversion (Shepperd's method) is accurate at
  // every angle, including near pi where the trace formula breaks down.
  return Log(Eigen::Quaterniond(R));
}

Eigen::Matrix3d RightJacobian(const Eigen::Vector3d& w) {
  const double t2 = w.squaredNorm();
  const double t = std::sqrt(t2);
  double b;  // (1 - cos t)/t^2
  double c;  // (t - sin t)/t^3
  if (t < kJacobianSeriesAngle) {
    b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
    c = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
  } else {
    const double s = std::sin(0.5 * t);
    b = 2.0 * s * s / t2;
    c = (t - std::sin(t)) / (t2 * t);
  }
  const Eigen::Matrix3d W = Hat(w);
  return Eigen::Matrix3d::Identity() - b * W + c * W * W;
}

Eigen::Matrix3d RightJacobianInverse(const Eigen::Vector3d& w) {
  const double t2 = w.squaredNorm();
  const double t = std::sqrt(t2);
  double d;  // 1/t^2 - (1 + cos t)/(2 t sin t) = 1/t^2 - cot(t/2)/(2t)
  if (t < kJacobianSeriesAngle) {
    d = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0;
  } else {
    const double half = 0.5 * t;
    d = 1.0 / t2 - std::cos(half) / (2.0 * t * std::sin(half));
  }
  const Eigen::Matrix3d W = Hat(w);
  return Eigen::Matrix3d::Identity() + 0.5 * W + d * W * W;
}

Eigen::Matrix3d LeftJacobian(const Eigen::Vector3d& w) { return RightJacobian(-w); }

Eigen::Matrix3d LeftJacobianInverse(const Eigen::Vector3d& w) {
  return RightJacobianInverse(-w);
}

Eigen::Matrix3d Normalize(const Eigen::Matrix3d& R) {
  return Eigen::Quaterniond(R).normalized().toRotationMatrix();
}

}  // namespace swarmlio::so3
