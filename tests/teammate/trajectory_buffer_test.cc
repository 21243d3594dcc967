#include "swarmlio/teammate/trajectory_buffer.h"

#include "swarmlio/common/time.h"

#include <gtest/gtest.h>

#include <cmath>

namespace swarmlio::teammate {
namespace {

TEST(TrajectoryBuffer, KeepsTheLastPositions) {
  TrajectoryBuffer buffer(5);
  for (int k = 0; k < 8; ++k) buffer.Push(ToNanoseconds(k), Eigen::Vector3d(k, 0, 0));
  ASSERT_EQ(buffer.size(), 5);
  EXPECT_EQ(buffer.samples().front().stamp_ns, ToNanoseconds(3.0));
  EXPECT_EQ(buffer.samples().back().p.x(), 7.0);
}

TEST(TrajectoryBuffer, ScatterIsEquationSix) {
  // Four corners of a 2 x 1 rectangle: H = diag(4, 1, 0).
  TrajectoryBuffer buffer(10);
  buffer.Push(0, Eigen::Vector3d(-1, -0.5, 2));
  buffer.Push(1, Eigen::Vector3d(1, -0.5, 2));
  buffer.Push(2, Eigen::Vector3d(1, 0.5, 2));
  buffer.Push(3, Eigen::Vector3d(-1, 0.5, 2));
  const Eigen::Vector3d sv = buffer.ScatterSingularValues();
  EXPECT_NEAR(sv(0), 4.0, 1e-12);
  EXPECT_NEAR(sv(1), 1.0, 1e-12);
  EXPECT_NEAR(sv(2), 0.0, 1e-12);
}

TEST(Excitation, AStraightLineIsNotExcitedACurveIs) {
  ExcitationOptions options;  // 6 m^2, 30 positions
  TrajectoryBuffer line(300), curve(300);
  const Eigen::Vector3d direction = Eigen::Vector3d(1, 2, 0.5).normalized();
  for (int k = 0; k < 200; ++k) {
    const double t = 0.1 * k;
    line.Push(ToNanoseconds(t), Eigen::Vector3d(1, 1, 1) + direction * std::sin(0.5 * t) * 2.0);
    curve.Push(ToNanoseconds(t), Eigen::Vector3d(std::cos(0.5 * t), std::sin(0.5 * t), 0.1 * std::sin(t)));
  }
  EXPECT_LT(line.ScatterSingularValues()(1), 1e-9);
  EXPECT_FALSE(IsExcited(line, options));
  // A unit circle over 200 samples: H ~ diag(100, 100, .).
  EXPECT_NEAR(curve.ScatterSingularValues()(1), 100.0, 15.0);
  EXPECT_TRUE(IsExcited(curve, options));
}

TEST(Excitation, NeedsEnoughPositions) {
  ExcitationOptions options;
  options.min_positions = 30;
  options.min_second_singular_value_m2 = 0.1;
  TrajectoryBuffer buffer(300);
  for (int k = 0; k < 29; ++k) {
    buffer.Push(ToNanoseconds(k), Eigen::Vector3d(std::cos(k), std::sin(k), 0) * 3.0);
  }
  EXPECT_FALSE(IsExcited(buffer, options));
  buffer.Push(29, Eigen::Vector3d(3, 0, 0));
  EXPECT_TRUE(IsExcited(buffer, options));
}

TEST(Excitation, SecondSingularValueOfAMatrix) {
  Eigen::Matrix3Xd p(3, 4);
  p << -1, 1, 1, -1, -0.5, -0.5, 0.5, 0.5, 0, 0, 0, 0;
  EXPECT_NEAR(SecondScatterSingularValue(p), 1.0, 1e-12);
}

}  // namespace
}  // namespace swarmlio::teammate
