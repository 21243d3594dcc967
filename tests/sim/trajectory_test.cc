#include "swarmlio/sim/trajectory.h"

#include <gtest/gtest.h>

#include <cmath>

#include "swarmlio/math/so3.h"
#include "swarmlio/sim/trajectory_builder.h"

namespace swarmlio::sim {
namespace {

Trajectory TestFlight(uint64_t seed) {
  TrajectoryBuilder b(Eigen::Vector3d(1, 2, 0.1), 0.3, TrajectoryBuilderOptions(), seed);
  b.Hover(3.0);
  b.Takeoff(1.2);
  b.Excite(8.0, Eigen::Vector3d(1.0, 1.0, 0.4), 0.6, 2.0);
  b.TransitTo(Eigen::Vector3d(6, -2, 1.5), -1.0);
  b.Hover(1.0);
  return b.Build(0.0, 25.0);
}

// The cardinal quintic B-spline (support [0, 6]) from its truncated-power form.
double CardinalBSpline(double x) {
  const double binom[7] = {1, 6, 15, 20, 15, 6, 1};
  double s = 0.0;
  for (int m = 0; m <= 6; ++m) {
    const double d = x - m;
    if (d > 0) s += (m % 2 ? -1.0 : 1.0) * binom[m] * std::pow(d, 5);
  }
  return s / 120.0;
}

TEST(Trajectory, BasisMatchesCardinalBSpline) {
  // One control point set to 1, the others 0: the curve is that point's blend.
  for (int j = 0; j < 6; ++j) {
    std::vector<Eigen::Vector4d> cps(6, Eigen::Vector4d::Zero());
    cps[j] = Eigen::Vector4d::Ones();
    const Trajectory traj(0.0, 1.0, cps);
    for (double u = 0.0; u < 1.0; u += 0.125) {
      EXPECT_NEAR(traj.Derivative(u, 0)[0], CardinalBSpline(u + 5 - j), 1e-12);
    }
  }
}

TEST(Trajectory, DerivativesMatchFiniteDifferences) {
  const Trajectory traj = TestFlight(3);
  const double h = 1e-5;
  for (double t = 0.37; t < 20.0; t += 0.731) {
    for (int k = 0; k < 5; ++k) {
      const Eigen::Vector4d fd = (traj.Derivative(t + h, k) - traj.Derivative(t - h, k)) / (2 * h);
      EXPECT_LT((fd - traj.Derivative(t, k + 1)).norm(), 1e-4 * (1.0 + fd.norm())) << t << " " << k;
    }
  }
}

TEST(Trajectory, AngularRateAndAccelerationMatchAttitude) {
  const Trajectory traj = TestFlight(4);
  const double h = 1e-5;
  for (double t = 3.1; t < 20.0; t += 0.53) {
    const KinematicState s = traj.StateAt(t);
    const Eigen::Matrix3d Rp = traj.PoseAt(t + h).R_W_b;
    const Eigen::Matrix3d Rm = traj.PoseAt(t - h).R_W_b;
    const Eigen::Vector3d omega_fd = so3::Log(Rm.transpose() * Rp) / (2 * h);
    EXPECT_LT((omega_fd - s.omega_b).norm(), 1e-6) << t;
    const Eigen::Vector3d alpha_fd = (traj.StateAt(t + h).omega_b - traj.StateAt(t - h).omega_b) / (2 * h);
    EXPECT_LT((alpha_fd - s.alpha_b).norm(), 1e-4) << t;
    EXPECT_TRUE(s.R_W_b.isApprox(traj.PoseAt(t).R_W_b, 1e-12));
    // Thrust along body z: the specific force has no body x/y component.
    const Eigen::Vector3d f_b = s.R_W_b.transpose() * (s.a_b_in_W + Eigen::Vector3d(0, 0, kGravity));
    EXPECT_NEAR(f_b.x(), 0.0, 1e-9);
    EXPECT_NEAR(f_b.y(), 0.0, 1e-9);
  }
}

TEST(Trajectory, StaticStartPlausibleDynamicsAndDeterminism) {
  const Trajectory traj = TestFlight(5);
  for (double t = 0.0; t <= 3.0; t += 0.1) {
    const KinematicState s = traj.StateAt(t);
    EXPECT_LT(s.v_b_in_W.norm(), 1e-12);
    EXPECT_LT(s.omega_b.norm(), 1e-12);
    EXPECT_LT((s.p_b_in_W - Eigen::Vector3d(1, 2, 0.1)).norm(), 1e-12);
  }
  double v, a, w;
  traj.Extremes(0.01, &v, &a, &w);
  EXPECT_LT(v, 3.0);
  EXPECT_LT(a, 6.0);
  EXPECT_LT(w, 3.0);
  EXPECT_GT(v, 0.3);
  // Continuous acceleration: no jumps between neighbouring samples.
  for (double t = 0.0; t < 20.0; t += 0.001) {
    EXPECT_LT((traj.Derivative(t + 0.001, 2) - traj.Derivative(t, 2)).norm(), 0.05);
  }
  const Trajectory again = TestFlight(5);
  EXPECT_EQ(again.control_points(), traj.control_points());
  EXPECT_NE(TestFlight(6).control_points(), traj.control_points());
  // Transit arrives at the target; the end is clamped hover.
  EXPECT_LT((traj.PositionAt(traj.end_time()) - Eigen::Vector3d(6, -2, 1.5)).norm(), 1e-9);
  EXPECT_LT((traj.PositionAt(1e6) - Eigen::Vector3d(6, -2, 1.5)).norm(), 1e-9);
}

TEST(Trajectory, YawOnlyStaysUpright) {
  TrajectoryBuilder b(Eigen::Vector3d(0, 0, 0), 0.0, TrajectoryBuilderOptions(), 1);
  b.TransitTo(Eigen::Vector3d(5, 0, 0), 1.0);
  const Trajectory traj = b.Build(0.0, 10.0, AttitudeMode::kYawOnly);
  const KinematicState s = traj.StateAt(2.0);
  EXPECT_NEAR(s.R_W_b(2, 2), 1.0, 1e-12);
  EXPECT_NEAR(s.omega_b.head<2>().norm(), 0.0, 1e-12);
}

}  // namespace
}  // namespace swarmlio::sim
