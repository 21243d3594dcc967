#include "swarmlio/teammate/observation.h"

#include "swarmlio/common/time.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

namespace swarmlio::teammate {
namespace {

PointCluster ClusterAt(const Eigen::Vector3d& c, double time_offset_s) {
  PointCluster cluster;
  cluster.centroid_in_b = c;
  cluster.min_in_b = c - Eigen::Vector3d::Constant(0.1);
  cluster.max_in_b = c + Eigen::Vector3d::Constant(0.1);
  cluster.mean_time_offset_s = time_offset_s;
  cluster.num_points = 10;
  return cluster;
}

TEST(Observation, DepthOffsetAlongTheLineOfSight) {
  ObservationOptions options;
  options.compensate_target_motion = false;
  const TeammateObservation o =
      MakeObservation(2, ToNanoseconds(10.0), ClusterAt(Eigen::Vector3d(3, 4, 0), -0.05), Eigen::Vector3d(1, 0, 0), options);
  EXPECT_EQ(o.drone_id, 2);
  EXPECT_EQ(o.stamp_ns, ToNanoseconds(10.0));
  EXPECT_TRUE(o.p_bj_in_bi.isApprox(Eigen::Vector3d(3, 4, 0) * (5.07 / 5.0)));
}

TEST(Observation, TargetMotionToTheScanStamp) {
  ObservationOptions options;
  options.centroid_depth_offset_m = 0.0;
  // Seen 0.05 s before the stamp, moving at 1 m/s along y: 5 cm further at the stamp.
  const TeammateObservation o =
      MakeObservation(1, 0, ClusterAt(Eigen::Vector3d(4, 0, 0), -0.05), Eigen::Vector3d(0, 1, 0), options);
  EXPECT_TRUE(o.p_bj_in_bi.isApprox(Eigen::Vector3d(4, 0.05, 0)));
  EXPECT_DOUBLE_EQ(o.capture_offset_s, -0.05);
}

TEST(Observation, TapeCentroidPreferred) {
  ObservationOptions options;
  options.centroid_depth_offset_m = 0.0;
  options.compensate_target_motion = false;
  PointCluster cluster = ClusterAt(Eigen::Vector3d(4, 0.1, 0), -0.02);
  cluster.reflective_centroid_in_b = Eigen::Vector3d(4, 0, 0);
  cluster.reflective_mean_time_offset_s = -0.03;
  cluster.num_reflective_points = 2;
  EXPECT_TRUE(EstimateCentre(cluster, options).p_in_b.isApprox(Eigen::Vector3d(4, 0.1, 0)));
  cluster.num_reflective_points = 3;
  const ClusterCentre centre = EstimateCentre(cluster, options);
  EXPECT_TRUE(centre.p_in_b.isApprox(Eigen::Vector3d(4, 0, 0)));
  EXPECT_DOUBLE_EQ(centre.time_offset_s, -0.03);
}

TEST(Observation, CovarianceGrowsWithRange) {
  ObservationOptions options;
  const Eigen::Matrix3d near = ObservationCovariance(Eigen::Vector3d(2, 0, 0), options);
  const Eigen::Matrix3d far = ObservationCovariance(Eigen::Vector3d(10, 0, 0), options);
  // Along the line of sight: range_sigma_m^2; across: (lateral + r * per_range)^2.
  EXPECT_NEAR(near(0, 0), options.range_sigma_m * options.range_sigma_m, 1e-15);
  const double lateral_far = options.lateral_sigma_m + 10 * options.lateral_sigma_per_range_rad;
  EXPECT_NEAR(far(1, 1), lateral_far * lateral_far, 1e-15);
  EXPECT_GT(far(1, 1), near(1, 1));
  EXPECT_GT(far.determinant(), near.determinant());
  EXPECT_TRUE(far.isApprox(far.transpose()));
}

TEST(Observation, TapeBandCentroidFromTheViewingDirection) {
  const double a = 0.10, b = 0.07;
  // Face on: the centroid is the face centre.
  EXPECT_TRUE(TapeCentroidInBody(Eigen::Vector3d(1, 0, 0), a, b).isApprox(Eigen::Vector3d(a, 0, 0)));
  EXPECT_TRUE(TapeCentroidInBody(Eigen::Vector3d(0, -1, 0), a, b).isApprox(Eigen::Vector3d(0, -b, 0)));
  // At 45 deg in the plane both faces weigh by their projected width: on the
  // line of sight, a b / (b cos + a sin) from the centre.
  const Eigen::Vector3d u = Eigen::Vector3d(1, 1, 0).normalized();
  const double depth = a * b / ((a + b) / std::sqrt(2.0));
  EXPECT_TRUE(TapeCentroidInBody(u, a, b).isApprox(depth * u));
  // Seen from above at 45 deg: the same side faces, so the offset stays
  // horizontal (not along the line of sight).
  const Eigen::Vector3d from_above = Eigen::Vector3d(1, 0, 1).normalized();
  const Eigen::Vector3d c = TapeCentroidInBody(from_above, a, b);
  EXPECT_NEAR(c.z(), 0.0, 1e-15);
  EXPECT_NEAR(c.x(), a, 1e-12);
  // Straight above: no side face visible, no offset.
  EXPECT_TRUE(TapeCentroidInBody(Eigen::Vector3d(0, 0, 1), a, b).isZero());
}

TEST(Observation, TapeBandModelUsesTheTeammateAttitude) {
  ObservationOptions options;
  options.tape_half_length_m = 0.10;
  options.tape_half_width_m = 0.07;
  PointCluster cluster = ClusterAt(Eigen::Vector3d(5, 0, 0), 0.0);
  cluster.num_reflective_points = 5;
  // The teammate 5 m ahead, yawed by 90 deg: its body y axis points back at
  // the observer, so the visible face is y = +b, 0.07 m in front of its centre.
  const Eigen::Matrix3d R_bi_bj =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  cluster.reflective_centroid_in_b = Eigen::Vector3d(5.0 - 0.07, 0, 0);
  EXPECT_TRUE(EstimateCentre(cluster, options, &R_bi_bj).p_in_b.isApprox(Eigen::Vector3d(5, 0, 0)));
  // Facing the observer with its nose (x): the face x = +a, 0.10 m in front.
  const Eigen::Matrix3d R_facing = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  cluster.reflective_centroid_in_b = Eigen::Vector3d(5.0 - 0.10, 0, 0);
  EXPECT_TRUE(EstimateCentre(cluster, options, &R_facing).p_in_b.isApprox(Eigen::Vector3d(5, 0, 0)));
  // Without the attitude, or with too few tape points: the constant offset.
  EXPECT_TRUE(EstimateCentre(cluster, options).p_in_b.isApprox(Eigen::Vector3d(4.90 + 0.07, 0, 0)));
  cluster.num_reflective_points = 2;
  EXPECT_TRUE(EstimateCentre(cluster, options, &R_facing)
                  .p_in_b.isApprox(Eigen::Vector3d(5.0 + 0.07, 0, 0)));
}

}  // namespace
}  // namespace swarmlio::teammate
