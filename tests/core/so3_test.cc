#include "swarmlio/math/so3.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "swarmlio/testing/jacobian_check.h"

namespace swarmlio {
namespace {

using so3::Exp;
using so3::Log;

constexpr int kNumTrials = 500;

// Rotation vectors covering random points, 1e-8 from identity and near pi.
std::vector<Eigen::Vector3d> TestVectors() {
  std::mt19937 rng(42);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.0, M_PI);
  std::vector<Eigen::Vector3d> out;
  auto random_axis = [&] {
    return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  };
  for (int i = 0; i < kNumTrials; ++i) out.push_back(random_axis() * uniform(rng));
  for (int i = 0; i < 20; ++i) {
    out.push_back(random_axis() * 1e-8);
    out.push_back(random_axis() * 1e-12);
    out.push_back(random_axis() * (M_PI - 1e-6));
    out.push_back(random_axis() * (M_PI - 1e-9));
    out.push_back(random_axis() * 1e-3);  // around the series switch points
    out.push_back(random_axis() * 1e-2);
  }
  out.push_back(Eigen::Vector3d::Zero());
  return out;
}

TEST(So3, HatIsCrossProductAndVeeInvertsIt) {
  const Eigen::Vector3d w(0.3, -1.2, 2.0);
  const Eigen::Vector3d v(-0.7, 0.1, 0.4);
  EXPECT_TRUE((so3::Hat(w) * v).isApprox(w.cross(v), 1e-15));
  EXPECT_TRUE(so3::Vee(so3::Hat(w)).isApprox(w, 1e-15));
}

TEST(So3, ExpIsARotationAndMatchesEigenAngleAxis) {
  for (const auto& w : TestVectors()) {
    const Eigen::Matrix3d R = Exp(w);
    EXPECT_NEAR((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-14);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
    const double t = w.norm();
    const Eigen::Matrix3d R_ref =
        t > 0 ? Eigen::AngleAxisd(t, w / t).toRotationMatrix() : Eigen::Matrix3d::Identity();
    EXPECT_NEAR((R - R_ref).norm(), 0.0, 1e-14) << w.transpose();
    EXPECT_NEAR((so3::ExpQuaternion(w).toRotationMatrix() - R).norm(), 0.0, 1e-14);
  }
}

TEST(So3, LogOfExpIsIdentityInsideTheBall) {
  for (const auto& w : TestVectors()) {
    const Eigen::Vector3d w_back = Log(Exp(w));
    // Absolute error: near pi, Log(Exp(w)) is conditioned like 1/sin(t), and
    // the rotation itself only holds ~1e-16 of information.
    EXPECT_NEAR((w_back - w).norm(), 0.0, w.norm() > 3.0 ? 1e-7 : 1e-13 * std::max(1.0, w.norm()))
        << w.transpose();
    if (w.norm() < 1e-6) {
      EXPECT_NEAR((w_back - w).norm() / std::max(w.norm(), 1e-300), 0.0, 1e-7) << "relative";
    }
    EXPECT_NEAR((Log(so3::ExpQuaternion(w)) - w).norm(), 0.0, 1e-9);
  }
}

TEST(So3, ExpOfLogIsIdentity) {
  for (const auto& w : TestVectors()) {
    const Eigen::Matrix3d R = Exp(w);
    EXPECT_NEAR((Exp(Log(R)) - R).norm(), 0.0, 1e-14) << w.transpose();
  }
  // Exactly pi: either axis direction is a valid log.
  const Eigen::Matrix3d R_pi = Exp(Eigen::Vector3d(0, 0, M_PI));
  EXPECT_NEAR(Log(R_pi).norm(), M_PI, 1e-12);
  EXPECT_NEAR((Exp(Log(R_pi)) - R_pi).norm(), 0.0, 1e-14);
}

TEST(So3, LogPicksShortestRotationAndIgnoresQuaternionSign) {
  const Eigen::Vector3d w(0.1, 0.2, -0.3);
  const Eigen::Quaterniond q = so3::ExpQuaternion(w);
  const Eigen::Quaterniond minus_q(-q.w(), -q.x(), -q.y(), -q.z());
  EXPECT_NEAR((Log(minus_q) - w).norm(), 0.0, 1e-15);
  // The S^3 logarithm keeps the sign: a rotation of 2 pi - |w| about -w/|w|.
  const Eigen::Vector3d no_wrap = so3::LogQuaternionNoWrap(minus_q);
  EXPECT_NEAR(no_wrap.norm(), 2 * M_PI - w.norm(), 1e-12);
  EXPECT_NEAR((so3::ExpQuaternion(no_wrap).coeffs() - minus_q.coeffs()).norm(), 0.0, 1e-14);
}

// Exp(w + d) = Exp(w) Exp(Jr(w) d) to first order.
TEST(So3, RightJacobianMatchesNumericDifferentiation) {
  for (const auto& w : TestVectors()) {
    if (w.norm() > M_PI - 1e-3) continue;  // central differences cross the cut at pi
    const Eigen::Matrix3d R = Exp(w);
    const auto f = [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
      return Log(R.transpose() * Exp(w + d));
    };
    EXPECT_TRUE(testing::MatricesNear(so3::RightJacobian(w), testing::NumericJacobian(f, 3, 1e-6),
                                      1e-8))
        << w.transpose();
    // Left Jacobian: Exp(w + d) = Exp(Jl(w) d) Exp(w).
    const auto g = [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
      return Log(Exp(w + d) * R.transpose());
    };
    EXPECT_TRUE(testing::MatricesNear(so3::LeftJacobian(w), testing::NumericJacobian(g, 3, 1e-6),
                                      1e-8));
  }
}

TEST(So3, RightJacobianNearPiMatchesOneSidedDifferences) {
  // Shrink the step so that w +- d stays inside the ball.
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d w =
        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized() * (M_PI - 1e-3);
    const Eigen::Matrix3d R = Exp(w);
    const auto f = [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
      return Log(R.transpose() * Exp(w + d));
    };
    EXPECT_TRUE(testing::MatricesNear(so3::RightJacobian(w), testing::NumericJacobian(f, 3, 1e-7),
                                      1e-6));
  }
}

TEST(So3, InverseJacobiansAreInverses) {
  for (const auto& w : TestVectors()) {
    EXPECT_NEAR((so3::RightJacobian(w) * so3::RightJacobianInverse(w) -
                 Eigen::Matrix3d::Identity())
                    .norm(),
                0.0, 1e-12)
        << w.transpose();
    EXPECT_NEAR((so3::LeftJacobian(w) * so3::LeftJacobianInverse(w) -
                 Eigen::Matrix3d::Identity())
                    .norm(),
                0.0, 1e-12);
  }
}

// Log(Exp(w) Exp(d)) = w + Jr^-1(w) d to first order.
TEST(So3, RightJacobianInverseMatchesNumericDifferentiation) {
  for (const auto& w : TestVectors()) {
    if (w.norm() > M_PI - 1e-3) continue;
    const Eigen::Matrix3d R = Exp(w);
    const auto f = [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
      return Log(R * Exp(d)) - w;
    };
    EXPECT_TRUE(testing::MatricesNear(so3::RightJacobianInverse(w),
                                      testing::NumericJacobian(f, 3, 1e-6), 1e-8))
        << w.transpose();
  }
}

TEST(So3, JacobianTestFailsOnFlippedSign) {
  const Eigen::Vector3d w(0.4, -0.2, 0.9);
  const Eigen::Matrix3d R = Exp(w);
  const auto f = [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
    return Log(R.transpose() * Exp(w + d));
  };
  // Jr with the sign of the first-order term flipped is Jl: must be rejected.
  EXPECT_FALSE(
      testing::MatricesNear(so3::LeftJacobian(w), testing::NumericJacobian(f, 3, 1e-6), 1e-8));
}

}  // namespace
}  // namespace swarmlio
