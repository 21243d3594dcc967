// ScanAssociator's noisy-plane rule (docs/lio.md, "Noisy map planes"): in a
// corridor whose walls were mapped from afar, planes with normals tilted by
// the noise are dropped along the axis; in a closed room, where the axis is
// constrained, nothing is dropped.
#include "swarmlio/lio/scan_association.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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
  double max_abs_residual_m = 0.0;  // of the scan points to their planes
  double end_wall_x_information = 0.0;  // sum n_x^2 over normals with |n_x| > 0.7
};

// The association options of the tests: a Mid-360's 0.15 deg, the rule's
// drop threshold and projection as given (0 = off).
ScanAssociationOptions RuleOptions(double max_normal_stddev_rad, double tilt_projection_sigma) {
  ScanAssociationOptions options;
  options.plane.map_angular_stddev_deg = 0.15;
  options.max_normal_stddev_rad = max_normal_stddev_rad;
  options.tilt_projection_sigma = tilt_projection_sigma;
  return options;
}

// Map points observed from `map_range_m` (noise along each surface's normal
// of range x 0.15 deg; the end walls from `end_wall_range_m`, 0 = the same),
// a noise-free scan from (0, 0, 1.5).
Result Associate(bool end_walls, double map_range_m, const ScanAssociationOptions& options,
                 double end_wall_range_m = 0.0) {
  LocalMapOptions map_options;
  map_options.leaf_size_m = 0.3;
  LocalMap map(map_options);
  std::mt19937 rng(7);
  const double end_range = end_wall_range_m > 0.0 ? end_wall_range_m : map_range_m;
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<Eigen::Vector3d> mapped;
  std::vector<double> ranges;
  for (Eigen::Vector3d p : CorridorPoints(8.0, end_walls, 0.1)) {
    const bool wall_y = std::abs(std::abs(p.y()) - 1.2) < 1e-9;
    const bool end = std::abs(std::abs(p.x()) - 8.0) < 1e-9 && end_walls;
    const int axis = end ? 0 : wall_y ? 1 : 2;
    const double range = end ? end_range : map_range_m;
    p(axis) += range * 0.15 * M_PI / 180.0 * noise(rng);
    mapped.push_back(p);
    ranges.push_back(range);
  }
  map.Insert(mapped, &ranges);

  std::vector<Eigen::Vector3d> scan;
  for (const Eigen::Vector3d& p : CorridorPoints(8.0, end_walls, 0.37)) {
    scan.push_back(p - Eigen::Vector3d(0.0, 0.0, 1.5));
  }
  ScanAssociator associator(&map, options);
  associator.Reset(&scan);
  SwarmState x;
  x.ego.p_b_in_G = Eigen::Vector3d(0.0, 0.0, 1.5);
  std::vector<PlaneCorrespondence> correspondences;
  EXPECT_TRUE(associator.Associate(x, &correspondences).ok());
  Result r;
  r.stats = associator.stats();
  r.x_information = r.stats.normal_information(0, 0);
  for (const PlaneCorrespondence& c : correspondences) {
    const Eigen::Vector3d q = c.p_in_b + x.ego.p_b_in_G;
    r.max_abs_residual_m = std::max(r.max_abs_residual_m, std::abs(c.normal_in_G.dot(q) + c.offset_m));
    const double n_x = c.normal_in_G.x();
    if (std::abs(n_x) > 0.7) r.end_wall_x_information += n_x * n_x;
  }
  return r;
}

TEST(ScanAssociationTest, TiltedPlanesAreDroppedAlongACorridorAxis) {
  // Mapped from 25 m: 6.5 cm of noise on 0.3 m map leaves.
  const Result off = Associate(/*end_walls=*/false, 25.0, RuleOptions(0.0, 0.0));
  const Result on = Associate(/*end_walls=*/false, 25.0, RuleOptions(0.2, 0.0));
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
  // A room mapped from 3 m (0.8 cm of angular noise): its end walls constrain
  // x; no plane is dropped and the projection leaves the end walls' normals.
  const Result drop = Associate(/*end_walls=*/true, 3.0, RuleOptions(0.2, 0.0));
  const Result project = Associate(/*end_walls=*/true, 3.0, RuleOptions(0.2, 3.0));
  EXPECT_EQ(project.stats.num_tilt_gated, 0);
  EXPECT_GT(project.x_information, 10.0);
  EXPECT_NEAR(project.end_wall_x_information, drop.end_wall_x_information,
              1e-3 * drop.end_wall_x_information);
}

TEST(ScanAssociationTest, KeptPlanesAreProjectedOffACorridorAxis) {
  // The drop alone leaves the kept planes' tilts along the axis; projecting
  // them (3 sigma) removes what noise made there and keeps every plane's
  // information across the axis.
  const Result drop = Associate(/*end_walls=*/false, 25.0, RuleOptions(0.2, 0.0));
  const Result project = Associate(/*end_walls=*/false, 25.0, RuleOptions(0.2, 3.0));
  std::printf("[ figures  ] corridor: x information %.2f dropping, %.3f also projecting (%d of %d "
              "projected)\n",
              drop.x_information, project.x_information, project.stats.num_tilt_projected,
              project.stats.num_correspondences);
  // (A plane whose normal leans mostly along the axis, within its noise, is
  // dropped: it says little across the axis.)
  EXPECT_GT(project.stats.num_correspondences, 0.9 * drop.stats.num_correspondences);
  EXPECT_GT(project.stats.num_tilt_projected, project.stats.num_correspondences / 2);
  EXPECT_LT(project.x_information, 0.1 * drop.x_information);
  // The walls, floor and ceiling keep their information across the axis.
  EXPECT_GT(project.stats.normal_information(1, 1), 0.9 * drop.stats.normal_information(1, 1));
  EXPECT_GT(project.stats.normal_information(2, 2), 0.9 * drop.stats.normal_information(2, 2));
  // A projected plane still passes through its neighbours: a scan point on
  // the true surface is within the map noise of it (checked by the residual
  // of the correspondences, below 3 x 6.5 cm).
  EXPECT_LT(project.max_abs_residual_m, 0.2);
}

TEST(ScanAssociationTest, AnEndWallKeepsItsInformationAlongTheAxis) {
  // Long walls mapped from 25 m, end walls 8 m away mapped from 3 m: the
  // axis is constrained by the end walls only. The projection takes what the
  // long walls' tilts added along it and nothing of the end walls'.
  const Result drop = Associate(/*end_walls=*/true, 25.0, RuleOptions(0.2, 0.0), 3.0);
  const Result project = Associate(/*end_walls=*/true, 25.0, RuleOptions(0.2, 3.0), 3.0);
  std::printf("[ figures  ] corridor with end walls: x information %.2f dropping (end walls "
              "%.2f), %.2f also projecting (end walls %.2f)\n",
              drop.x_information, drop.end_wall_x_information, project.x_information,
              project.end_wall_x_information);
  EXPECT_GT(project.end_wall_x_information, 10.0);
  // (Projections off the other directions may straighten an end wall's
  // normal: its x information may grow, never shrink.)
  EXPECT_GT(project.end_wall_x_information, 0.99 * drop.end_wall_x_information);
  EXPECT_LT(project.x_information - project.end_wall_x_information,
            0.1 * (drop.x_information - drop.end_wall_x_information));
}

// matched_point_indices(): for each correspondence, its scan point, also after
// the noisy-plane rule dropped some (the odometry keeps those points out of
// the map, odometry_options.h insert_matched_points).
TEST(ScanAssociationTest, MatchedPointIndicesNameEachCorrespondencesScanPoint) {
  LocalMapOptions map_options;
  map_options.leaf_size_m = 0.3;
  LocalMap map(map_options);
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.065);  // mapped from 25 m
  std::vector<Eigen::Vector3d> mapped;
  std::vector<double> ranges;
  for (Eigen::Vector3d p : CorridorPoints(8.0, false, 0.1)) {
    p(std::abs(std::abs(p.y()) - 1.2) < 1e-9 ? 1 : 2) += noise(rng);
    mapped.push_back(p);
    ranges.push_back(25.0);
  }
  map.Insert(mapped, &ranges);
  std::vector<Eigen::Vector3d> scan;
  for (const Eigen::Vector3d& p : CorridorPoints(8.0, false, 0.37)) {
    scan.push_back(p - Eigen::Vector3d(0.0, 0.0, 1.5));
  }
  scan.push_back(Eigen::Vector3d(0.0, 0.0, 40.0));  // far from the map: no plane
  ScanAssociator associator(&map, RuleOptions(0.2, 3.0));
  associator.Reset(&scan);
  SwarmState x;
  x.ego.p_b_in_G = Eigen::Vector3d(0.0, 0.0, 1.5);
  std::vector<PlaneCorrespondence> correspondences;
  ASSERT_TRUE(associator.Associate(x, &correspondences).ok());
  ASSERT_GT(associator.stats().num_tilt_gated, 0);  // the rule dropped some
  const std::vector<int>& matched = associator.matched_point_indices();
  ASSERT_EQ(matched.size(), correspondences.size());
  ASSERT_GT(matched.size(), 10u);
  for (size_t k = 0; k < matched.size(); ++k) {
    ASSERT_GE(matched[k], 0);
    ASSERT_LT(static_cast<size_t>(matched[k]), scan.size() - 1);  // never the far point
    EXPECT_EQ(scan[static_cast<size_t>(matched[k])], correspondences[k].p_in_b) << k;
    if (k > 0) {
      EXPECT_LT(matched[k - 1], matched[k]);
    }
  }
}

}  // namespace
}  // namespace swarmlio::lio
