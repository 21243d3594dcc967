#include "swarmlio/lio/plane_fit.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

namespace swarmlio::lio {
namespace {

// Points on n^T q + d = 0 around `anchor`, spread over `extent_m`.
std::vector<Eigen::Vector3d> PlanePoints(const Eigen::Vector3d& n, double d, int count,
                                         double extent_m, double noise_m, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-extent_m, extent_m);
  std::normal_distribution<double> noise(0.0, noise_m);
  const Eigen::Vector3d unit = n.normalized();
  Eigen::Vector3d t1 = unit.unitOrthogonal();
  Eigen::Vector3d t2 = unit.cross(t1);
  const Eigen::Vector3d origin = -d * unit;
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    points.push_back(origin + u(rng) * t1 + u(rng) * t2 +
                     (noise_m > 0.0 ? noise(rng) : 0.0) * unit);
  }
  return points;
}

TEST(PlaneFitTest, ExactPlane) {
  const Eigen::Vector3d n = Eigen::Vector3d(1.0, 2.0, 2.0) / 3.0;
  const double d = -4.0;
  const std::vector<Eigen::Vector3d> points = PlanePoints(n, d, 5, 0.5, 0.0, 1);
  Plane plane;
  ASSERT_EQ(FitPlane(points, 0.5, PlaneFitOptions{}, &plane), PlaneFitStatus::kOk);
  EXPECT_NEAR(plane.normal_in_G.norm(), 1.0, 1e-12);
  EXPECT_LT((plane.normal_in_G - n).norm(), 1e-9);  // d < 0 orientation: n as given
  EXPECT_NEAR(plane.offset_m, d, 1e-9);
  EXPECT_LT(plane.max_abs_residual_m, 1e-9);
  EXPECT_LT(plane.curvature, 1e-12);
  for (const auto& q : points) EXPECT_NEAR(plane.SignedDistance(q), 0.0, 1e-9);
}

TEST(PlaneFitTest, OrientationIsDeterministic) {
  // Same plane given with the opposite normal: the fit picks d <= 0.
  const std::vector<Eigen::Vector3d> points =
      PlanePoints(Eigen::Vector3d(0, 0, -1), 2.0, 5, 0.4, 0.0, 2);  // z = 2
  Plane plane;
  ASSERT_EQ(FitPlane(points, 0.5, PlaneFitOptions{}, &plane), PlaneFitStatus::kOk);
  EXPECT_LT((plane.normal_in_G - Eigen::Vector3d::UnitZ()).norm(), 1e-9);
  EXPECT_NEAR(plane.offset_m, -2.0, 1e-9);
}

TEST(PlaneFitTest, PlaneThroughOrigin) {
  // FAST-LIO's A n = -1 form cannot represent d = 0; PCA can.
  const Eigen::Vector3d n = Eigen::Vector3d(0.0, -1.0, 1.0).normalized();
  const std::vector<Eigen::Vector3d> points = PlanePoints(n, 0.0, 5, 0.5, 0.0, 3);
  Plane plane;
  ASSERT_EQ(FitPlane(points, 0.5, PlaneFitOptions{}, &plane), PlaneFitStatus::kOk);
  EXPECT_NEAR(std::abs(plane.normal_in_G.dot(n)), 1.0, 1e-9);
  EXPECT_NEAR(plane.offset_m, 0.0, 1e-9);
}

TEST(PlaneFitTest, NoisyPlaneWithinTolerance) {
  const Eigen::Vector3d n = Eigen::Vector3d(0.3, -0.2, 0.9).normalized();
  const double d = -3.0;
  PlaneFitOptions many;
  many.min_neighbors = 5;
  for (int count : {5, 30}) {
    int accepted = 0;
    for (uint32_t seed = 0; seed < 200; ++seed) {
      const std::vector<Eigen::Vector3d> points = PlanePoints(n, d, count, 0.5, 0.01, 100 + seed);
      Plane plane;
      if (FitPlane(points, 1.0, many, &plane) != PlaneFitStatus::kOk) continue;
      ++accepted;
      EXPECT_LE(plane.max_abs_residual_m, 0.1);
      EXPECT_LT(plane.rms_residual_m, 0.03);
      // The fitted plane reproduces the true surface where the neighbours are.
      for (const Eigen::Vector3d& q : points) {
        const Eigen::Vector3d on_true_plane = q - (n.dot(q) + d) * n;
        EXPECT_LT(std::abs(plane.SignedDistance(on_true_plane)), 0.05);
      }
      // 5 points: within ~11 deg (random, sometimes thin layouts); 30 points: within ~3 deg.
      EXPECT_GT(std::abs(plane.normal_in_G.dot(n)), std::cos(count == 5 ? 0.2 : 0.05));
    }
    EXPECT_EQ(accepted, 200);  // 1 cm noise is far inside the 0.1 m planarity gate
  }
}

TEST(PlaneFitTest, NonPlanarRejected) {
  // Five points on the corner of a box: no plane within 0.1 m.
  const std::vector<Eigen::Vector3d> corner = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1},
                                               {0.5, 0.5, 0}};
  Plane plane;
  plane.offset_m = 42.0;
  EXPECT_EQ(FitPlane(corner, 1.0, PlaneFitOptions{}, &plane), PlaneFitStatus::kNotPlanar);
  EXPECT_EQ(plane.offset_m, 42.0);  // untouched on failure
  // A looser gate accepts the same points.
  PlaneFitOptions loose;
  loose.max_point_to_plane_m = 1.0;
  EXPECT_EQ(FitPlane(corner, 1.0, loose, &plane), PlaneFitStatus::kOk);
}

TEST(PlaneFitTest, FarNeighboursRejected) {
  const std::vector<Eigen::Vector3d> points =
      PlanePoints(Eigen::Vector3d::UnitZ(), -1.0, 5, 2.0, 0.0, 4);
  Plane plane;
  EXPECT_EQ(FitPlane(points, 5.0, PlaneFitOptions{}, &plane), PlaneFitStatus::kOk);  // <= 5 m^2
  EXPECT_EQ(FitPlane(points, 5.01, PlaneFitOptions{}, &plane), PlaneFitStatus::kNeighborsTooFar);
  // Neighbor form takes the farthest of the given squared distances.
  std::vector<Neighbor> neighbors;
  for (size_t i = 0; i < points.size(); ++i) {
    neighbors.push_back({points[i], i == 4 ? 6.0 : 1.0});
  }
  EXPECT_EQ(FitPlane(neighbors, PlaneFitOptions{}, &plane), PlaneFitStatus::kNeighborsTooFar);
  neighbors[4].squared_distance_m2 = 2.0;
  EXPECT_EQ(FitPlane(neighbors, PlaneFitOptions{}, &plane), PlaneFitStatus::kOk);
}

TEST(PlaneFitTest, TooFewAndDegenerate) {
  Plane plane;
  const std::vector<Eigen::Vector3d> four = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  EXPECT_EQ(FitPlane(four, 1.0, PlaneFitOptions{}, &plane), PlaneFitStatus::kTooFewPoints);
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 5; ++i) line.emplace_back(0.1 * i, 0.2 * i, 1.0);
  EXPECT_EQ(FitPlane(line, 1.0, PlaneFitOptions{}, &plane), PlaneFitStatus::kDegenerate);
  EXPECT_STREQ(ToString(PlaneFitStatus::kDegenerate), "degenerate");
}

TEST(PlaneFitTest, OptionsValidate) {
  PlaneFitOptions options;
  EXPECT_EQ(options.Validate(), "");
  options.max_point_to_plane_m = 0.0;
  EXPECT_NE(options.Validate().find("max_point_to_plane_m"), std::string::npos);
}

}  // namespace
}  // namespace swarmlio::lio
