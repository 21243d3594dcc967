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

// Five neighbours on z = 0 in a strip 2 m long (x) and +-0.1 m wide (y), all
// observed from `range_m`.
std::vector<Neighbor> Strip(double range_m, double noise_m, std::mt19937* rng) {
  std::normal_distribution<double> noise(0.0, noise_m);
  const double xs[5] = {-1.0, -0.5, 0.0, 0.5, 1.0};
  const double ys[5] = {0.1, -0.1, 0.0, -0.1, 0.1};  // uncorrelated with x
  std::vector<Neighbor> strip;
  for (int i = 0; i < 5; ++i) {
    Neighbor nb;
    nb.point_in_G = Eigen::Vector3d(xs[i], ys[i], noise_m > 0.0 ? noise(*rng) : 0.0);
    nb.squared_distance_m2 = 0.5;
    nb.observed_range_m = range_m;
    strip.push_back(nb);
  }
  return strip;
}

PlaneFitOptions StripNoise() {
  PlaneFitOptions o;
  o.max_neighbor_sq_distance_m2 = 1.0;
  o.map_range_stddev_m = 0.02;
  o.map_angular_stddev_deg = 0.15;
  return o;
}

TEST(PlaneFitTest, NormalUncertaintyScalesWithTheObservationRange) {
  std::mt19937 rng(3);
  Plane plane;
  // lambda_mid = mean y^2 = 0.008 m^2. From 2 m: sigma_i = 0.0207 m, sigma_n =
  // 0.0207 / sqrt(5 * 0.008) = 0.103 rad. From 30 m: 0.081 m, 0.40 rad.
  const double angular = 0.15 * M_PI / 180.0;
  ASSERT_EQ(FitPlane(Strip(2.0, 0.0, &rng), StripNoise(), &plane), PlaneFitStatus::kOk);
  EXPECT_NEAR(plane.normal_stddev_rad,
              std::sqrt((0.02 * 0.02 + 4.0 * angular * angular) / (5.0 * 0.008)), 1e-9);
  // The strip is narrow along y: the uncertain tilt moves the normal along y.
  EXPECT_NEAR(std::abs(plane.tilt_axis_in_G.y()), 1.0, 1e-9);
  ASSERT_EQ(FitPlane(Strip(30.0, 0.0, &rng), StripNoise(), &plane), PlaneFitStatus::kOk);
  EXPECT_NEAR(plane.normal_stddev_rad, 0.40, 0.01);
  // An unknown range (0) counts as range noise only.
  ASSERT_EQ(FitPlane(Strip(0.0, 0.0, &rng), StripNoise(), &plane), PlaneFitStatus::kOk);
  EXPECT_NEAR(plane.normal_stddev_rad, 0.02 / std::sqrt(5.0 * 0.008), 1e-9);
}

TEST(PlaneFitTest, TiltTowardADirectionCombinesBothInPlaneAxes) {
  std::mt19937 rng(5);
  Plane plane;
  ASSERT_EQ(FitPlane(Strip(10.0, 0.0, &rng), StripNoise(), &plane), PlaneFitStatus::kOk);
  // lambda_mid = 0.008 m^2 (y), lambda_max = mean x^2 = 0.5 m^2 (x).
  const double angular = 0.15 * M_PI / 180.0;
  const double var = 0.02 * 0.02 + 100.0 * angular * angular;
  EXPECT_NEAR(plane.TiltStddevToward(Eigen::Vector3d::UnitY()), std::sqrt(var / (5.0 * 0.008)),
              1e-9);
  EXPECT_NEAR(plane.TiltStddevToward(Eigen::Vector3d::UnitX()), std::sqrt(var / (5.0 * 0.5)),
              1e-9);
  EXPECT_NEAR(plane.TiltStddevToward(Eigen::Vector3d::UnitZ()), 0.0, 1e-9);  // along n
  const Eigen::Vector3d diagonal = Eigen::Vector3d(1.0, 1.0, 0.0).normalized();
  EXPECT_NEAR(plane.TiltStddevToward(diagonal),
              std::sqrt(0.5 * var / (5.0 * 0.008) + 0.5 * var / (5.0 * 0.5)), 1e-9);
  // The centroid: the strip moved to (3, -2, 1) has it there.
  std::vector<Eigen::Vector3d> moved;
  for (const Neighbor& nb : Strip(10.0, 0.0, &rng)) {
    moved.push_back(nb.point_in_G + Eigen::Vector3d(3.0, -2.0, 1.0));
  }
  ASSERT_EQ(FitPlane(moved, 0.5, StripNoise(), &plane), PlaneFitStatus::kOk);
  EXPECT_LT((plane.centroid_in_G - Eigen::Vector3d(3.0, -2.0, 1.0)).norm(), 1e-12);
}

TEST(PlaneFitTest, ModelledNormalStddevMatchesTheScatterOfFittedNormals) {
  // Points with the modelled noise (range 10 m: sigma = sqrt(0.02^2 +
  // (10 * 0.15 deg)^2) = 0.033 m): the RMS of tilt / sigma_n over many fits
  // is 1 when sigma_n is right (a factor sqrt(2) off fails the band).
  std::mt19937 rng(11);
  const double angular = 0.15 * M_PI / 180.0;
  const double sigma = std::sqrt(0.02 * 0.02 + 100.0 * angular * angular);
  PlaneFitOptions o = StripNoise();
  o.max_point_to_plane_m = 1.0;
  double sum_sq = 0.0;
  int n = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    Plane plane;
    ASSERT_EQ(FitPlane(Strip(10.0, sigma, &rng), o, &plane), PlaneFitStatus::kOk);
    // Tilt about the strip's long axis x: the normal's y component.
    const double tilt = std::atan2(plane.normal_in_G.y(), std::abs(plane.normal_in_G.z()));
    sum_sq += (tilt / plane.normal_stddev_rad) * (tilt / plane.normal_stddev_rad);
    ++n;
  }
  const double rms = std::sqrt(sum_sq / n);
  EXPECT_GT(rms, 0.85);
  EXPECT_LT(rms, 1.2);
}

}  // namespace
}  // namespace swarmlio::lio
