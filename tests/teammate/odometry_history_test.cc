#include "swarmlio/teammate/odometry_history.h"

#include "swarmlio/common/time.h"

#include <gtest/gtest.h>

namespace swarmlio::teammate {
namespace {

TeammateOdometry Message(double t, const Eigen::Vector3d& p, const Eigen::Vector3d& v) {
  TeammateOdometry m;
  m.stamp_ns = ToNanoseconds(t);
  m.drone_id = 1;
  m.p_bj_in_Gj = p;
  m.v_bj_in_Gj = v;
  return m;
}

TEST(OdometryHistory, SortsReplacesAndForgets) {
  OdometryHistory h;
  h.Add(Message(2.0, Eigen::Vector3d(2, 0, 0), Eigen::Vector3d::Zero()), 10.0);
  h.Add(Message(1.0, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d::Zero()), 10.0);  // late
  h.Add(Message(2.0, Eigen::Vector3d(5, 0, 0), Eigen::Vector3d::Zero()), 10.0);  // same stamp
  ASSERT_EQ(h.size(), 2);
  EXPECT_EQ(h.messages().front().stamp_ns, ToNanoseconds(1.0));
  EXPECT_EQ(h.newest().p_bj_in_Gj.x(), 5.0);
  h.Add(Message(20.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()), 10.0);
  EXPECT_EQ(h.size(), 1);
}

TEST(OdometryHistory, HermiteInterpolationIsExactForCubics) {
  // p(t) = a + b t + c t^2 + d t^3 is reproduced exactly from p and v at the ends.
  auto p = [](double t) { return Eigen::Vector3d(1 + t, 2 * t * t, t * t * t - t); };
  auto v = [](double t) { return Eigen::Vector3d(1, 4 * t, 3 * t * t - 1); };
  OdometryHistory h;
  h.Add(Message(1.0, p(1.0), v(1.0)), 10.0);
  h.Add(Message(1.3, p(1.3), v(1.3)), 10.0);
  Eigen::Vector3d q, w;
  ASSERT_TRUE(h.StateAt(ToNanoseconds(1.17), 0.35, 0.05, &q, &w));
  EXPECT_LT((q - p(1.17)).norm(), 1e-12);
  // Across a gap wider than max_gap_s: only extrapolation near a message.
  EXPECT_FALSE(h.StateAt(ToNanoseconds(1.17), 0.2, 0.05, &q, &w));
  ASSERT_TRUE(h.StateAt(ToNanoseconds(1.33), 0.35, 0.05, &q, &w));
  EXPECT_LT((q - (p(1.3) + 0.03 * v(1.3))).norm(), 1e-12);
  EXPECT_FALSE(h.StateAt(ToNanoseconds(1.4), 0.35, 0.05, &q, &w));
  EXPECT_FALSE(OdometryHistory().StateAt(ToNanoseconds(1.0), 1.0, 1.0, &q, &w));
}

TEST(OdometryHistory, AttitudeOfTheNearestMessage) {
  OdometryHistory h;
  Eigen::Quaterniond q;
  EXPECT_FALSE(h.AttitudeAt(ToNanoseconds(1.0), 0.5, &q));
  TeammateOdometry a = Message(1.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  TeammateOdometry b = Message(2.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  b.q_Gj_bj = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  h.Add(a, 10.0);
  h.Add(b, 10.0);
  ASSERT_TRUE(h.AttitudeAt(ToNanoseconds(1.4), 0.5, &q));
  EXPECT_TRUE(q.isApprox(a.q_Gj_bj));
  ASSERT_TRUE(h.AttitudeAt(ToNanoseconds(1.6), 0.5, &q));
  EXPECT_TRUE(q.isApprox(b.q_Gj_bj));
  ASSERT_TRUE(h.AttitudeAt(ToNanoseconds(2.4), 0.5, &q));
  EXPECT_TRUE(q.isApprox(b.q_Gj_bj));
  EXPECT_FALSE(h.AttitudeAt(ToNanoseconds(2.6), 0.5, &q));  // too old
  EXPECT_FALSE(h.AttitudeAt(ToNanoseconds(0.4), 0.5, &q));
}

}  // namespace
}  // namespace swarmlio::teammate
