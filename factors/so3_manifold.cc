#include "factors/so3_manifold.h"

#include <Eigen/Geometry>

#include "swarmlio/math/so3.h"

namespace swarmlio {
namespace {

// Eigen's quaternion coefficient order is (x, y, z, w), the ambient layout.
using ConstQuaternionMap = Eigen::Map<const Eigen::Quaterniond>;
using QuaternionMap = Eigen::Map<Eigen::Quaterniond>;

}  // namespace

bool SO3Manifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Map<const Eigen::Vector3d> dr(delta);
  QuaternionMap out(x_plus_delta);
  out = (ConstQuaternionMap(x) * so3::ExpQuaternion(dr)).normalized();
  return true;
}

bool SO3Manifold::PlusJacobian(const double* x, double* jacobian) const {
  const Eigen::Vector3d v(x[0], x[1], x[2]);
  const double w = x[3];
  Eigen::Map<Eigen::Matrix<double, 4, 3, Eigen::RowMajor>> J(jacobian);
  J.topRows<3>() = 0.5 * (w * Eigen::Matrix3d::Identity() + so3::Hat(v));
  J.row(3) = -0.5 * v.transpose();
  return true;
}

bool SO3Manifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Eigen::Map<Eigen::Vector3d> out(y_minus_x);
  out = so3::LogQuaternionNoWrap(ConstQuaternionMap(x).conjugate() * ConstQuaternionMap(y));
  return true;
}

Eigen::Matrix<double, 3, 4> SO3Manifold::MinusJacobianAt(const double* x) {
  const Eigen::Vector3d v(x[0], x[1], x[2]);
  const double w = x[3];
  Eigen::Matrix<double, 3, 4> J;
  J.leftCols<3>() = 2.0 * (w * Eigen::Matrix3d::Identity() - so3::Hat(v));
  J.col(3) = -2.0 * v;
  return J;
}

bool SO3Manifold::MinusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> J(jacobian);
  J = MinusJacobianAt(x);
  return true;
}

}  // namespace swarmlio
