// ScanAssociator's noisy-plane rule (docs/lio.md, "Noisy map planes"): in a
// corridor whose walls were mapped from afar, planes with normals tilted by
// the noise are dropped along the axis; in a closed room, where the axis is
// constrained, nothing is dropped.
#include "swarmlio/lio/scan_association.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace swarmlio::lio {
namespace {

// Points on the box surfaces |y| = 1.2, z = 0, z = 3 for |x| <= half_length
// (and, with end walls, x = +-half_length), on a grid of `step`.
std::vector<Eigen::Vector3d> CorridorPoints(double half_length, bool end_walls, double step) {
  std::vector<Eigen::Vector3d> points;
  for (double x = -half_length; x <= half_length; x += step) {
    for (double s = -1.2; s <= 1.2; s += step) {
      points.emplace_back(x, s, 0.0);
      points.emplace_back(x, s, 3.0);
    }
    for (double z = 0.0; z <= 3.0; z += step) {
      points.emplace_back(x, -1.2, z);
      points.emplace_back(x, 1.2, z);
    }
  }
  if (end_walls) {
    for (double y = -1.2; y <= 1.2; y += step) {
      for (double z = 0.0; z <= 3.0; z += step) {
        points.emplace_back(-half_length, y, z);
        points.emplace_back(half_length, y, z);
      }
    }
  }
  return points;
}

struct Result {
  AssociationStats stats;
  double x_information = 0.0;  // e_x^T sum n n^T e_x
};

// Map points observed from `map_range_m` (noise along each surface's normal
// of range x 0.15 deg), a noise-free scan from (0, 0, 1.5).
Result Associate(bool end_walls, double map_range_m, double max_normal_stddev_rad) {
  LocalMapOptions map_options;
  map_options.leaf_size_m = 0.3;
  LocalMap map(map_options);
  std::mt19937 rng(7);
  const double sigma = map_range_m * 0.15 * M_PI / 180.0;
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<Eigen::Vector3d> mapped;
  std::vector<double> ranges;
  for (Eigen::Vector3d p : CorridorPoints(8.0, end_walls, 0.1)) {
    const bool wall_y = std::abs(std::abs(p.y()) - 1.2) < 1e-9;
    const bool end = std::abs(std::abs(p.x()) - 8.0) < 1e-9 && end_walls;
    const int axis = end ? 0 : wall_y ? 1 : 2;
    p(axis) += noise(rng);
    mapped.push_back(p);
    ranges.push_back(map_range_m);
  }
  map.Insert(mapped, &ranges);

  std::vector<Eigen::Vector3d> scan;
  for (const Eigen::Vector3d& p : CorridorPoints(8.0, end_walls, 0.37)) {
    scan.push_back(p - Eigen::Vector3d(0.0, 0.0, 1.5));
  }
  AssociationOptions options;
  options.plane.map_angular_stddev_deg = 0.15;
  options.max_normal_stddev_rad = max_normal_stddev_rad;
  ScanAssociator associator(&map, options);
  associator.Reset(&scan);
  SwarmState x;
  x.ego.p_b_in_G = Eigen::Vector3d(0.0, 0.0, 1.5);
  std::vector<PlaneCorrespondence> correspondences;
  EXPECT_TRUE(associator.Associate(x, &correspondences).ok());
  Result r;
  r.stats = associator.stats();
  r.x_information = r.stats.normal_information(0, 0);
  return r;
}

TEST(ScanAssociationTest, TiltedPlanesAreDroppedAlongACorridorAxis) {
  // Mapped from 25 m: 6.5 cm of noise on 0.3 m map leaves.
  const Result off = Associate(/*end_walls=*/false, 25.0, 0.0);
  const Result on = Associate(/*end_walls=*/false, 25.0, 0.2);
  std::printf("[ figures  ] corridor: %d correspondences, x information %.1f; with the rule %d "
              "(%d dropped), x information %.1f\n",
              off.stats.num_correspondences, off.x_information, on.stats.num_correspondences,
              on.stats.num_tilt_gated, on.x_information);
  EXPECT_EQ(off.stats.num_tilt_gated, 0);
  EXPECT_GT(on.stats.num_tilt_gated, 0);
  // What is left along the axis is a fraction of the noise-made information,
  // while the walls, floor and ceiling still constrain y and z.
  EXPECT_LT(on.x_information, 0.2 * off.x_information);
  EXPECT_GT(on.stats.normal_information(1, 1), 10.0);
  EXPECT_GT(on.stats.normal_information(2, 2), 10.0);
}

TEST(ScanAssociationTest, NothingIsDroppedWhereTheAxisIsConstrained) {
  // A room mapped from 3 m (1.9 cm of noise): its end walls constrain x.
  const Result on = Associate(/*end_walls=*/true, 3.0, 0.2);
  EXPECT_EQ(on.stats.num_tilt_gated, 0);
  EXPECT_GT(on.x_information, 10.0);
}

}  // namespace
}  // namespace swarmlio::lio
