#include "swarmlio/lio/local_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace swarmlio::lio {
namespace {

// Every point is kept: tiny leaves, many points per leaf.
LocalMapOptions KeepAll() {
  LocalMapOptions o;
  o.leaf_size_m = 0.001;
  o.max_points_per_leaf = 1000;
  o.cell_size_m = 1.0;
  o.half_extent_m = 1000.0;
  o.max_search_radius_m = 3.0;
  return o;
}

std::vector<double> BruteForce(const std::vector<Eigen::Vector3d>& points,
                               const Eigen::Vector3d& q, int k, double radius) {
  std::vector<double> d2;
  for (const auto& p : points) {
    const double d = (p - q).squaredNorm();
    if (d <= radius * radius) d2.push_back(d);
  }
  std::sort(d2.begin(), d2.end());
  if (static_cast<int>(d2.size()) > k) d2.resize(k);
  return d2;
}

void ExpectMatchesBruteForce(const LocalMap& map, const std::vector<Eigen::Vector3d>& points,
                             const std::vector<Eigen::Vector3d>& queries, int k) {
  std::vector<Neighbor> found;
  for (const auto& q : queries) {
    const std::vector<double> expected =
        BruteForce(points, q, k, map.options().max_search_radius_m);
    ASSERT_EQ(map.KNearest(q, k, &found), static_cast<int>(expected.size())) << q.transpose();
    for (size_t i = 0; i < expected.size(); ++i) {
      EXPECT_EQ(found[i].squared_distance_m2, expected[i]) << "query " << q.transpose();
      EXPECT_EQ(found[i].squared_distance_m2, (found[i].point_in_G - q).squaredNorm());
    }
  }
}

TEST(LocalMapTest, KnnEqualsBruteForceOnRandomData) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-6.0, 6.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 3000; ++i) points.emplace_back(u(rng), u(rng), u(rng));
  LocalMap map(KeepAll());
  ASSERT_EQ(map.Insert(points), 3000);
  ASSERT_EQ(map.size(), 3000u);

  std::vector<Eigen::Vector3d> queries;
  for (int i = 0; i < 300; ++i) queries.emplace_back(u(rng), u(rng), u(rng));
  // On and next to cell borders (cell 1 m), and outside the data.
  for (int i = -3; i <= 3; ++i) {
    queries.emplace_back(i, 0.5, -0.5);
    queries.emplace_back(i - 1e-9, i + 1e-9, 0.0);
    queries.emplace_back(0.999999, -2.0, i);
  }
  queries.emplace_back(8.0, 8.0, 8.0);    // some neighbours within the radius only
  queries.emplace_back(20.0, 0.0, 0.0);   // none
  for (int k : {1, 5, 10}) ExpectMatchesBruteForce(map, points, queries, k);
}

TEST(LocalMapTest, KnnEqualsBruteForceOnSurfacesAcrossCellSizes) {
  // Points on two walls and a floor: the realistic, anisotropic case.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 8.0);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 1500; ++i) {
    points.emplace_back(u(rng), u(rng), noise(rng));
    points.emplace_back(noise(rng), u(rng), 0.5 * u(rng));
    points.emplace_back(u(rng), 8.0 + noise(rng), 0.5 * u(rng));
  }
  std::vector<Eigen::Vector3d> queries;
  for (int i = 0; i < 300; ++i) {
    queries.emplace_back(u(rng), u(rng), 0.1 * u(rng));
  }
  for (double cell : {0.3, 1.0, 2.5}) {
    LocalMapOptions o = KeepAll();
    o.cell_size_m = cell;
    o.max_search_radius_m = 2.0;
    LocalMap map(o);
    map.Insert(points);
    ExpectMatchesBruteForce(map, points, queries, 5);
  }
}

TEST(LocalMapTest, InsertionDownsamplingRule) {
  LocalMapOptions o;
  o.leaf_size_m = 0.5;
  o.max_points_per_leaf = 1;
  LocalMap map(o);
  EXPECT_TRUE(map.Insert(Eigen::Vector3d(0.1, 0.1, 0.1)));
  EXPECT_FALSE(map.Insert(Eigen::Vector3d(0.4, 0.4, 0.4)));  // same leaf [0, 0.5)^3: full
  EXPECT_TRUE(map.Insert(Eigen::Vector3d(0.5, 0.1, 0.1)));   // next leaf
  EXPECT_FALSE(map.Insert(Eigen::Vector3d(0.1, 0.1, 0.1)));  // duplicate
  EXPECT_FALSE(map.Insert(Eigen::Vector3d(std::nan(""), 0, 0)));
  EXPECT_EQ(map.size(), 2u);
  std::vector<Neighbor> nn;
  map.KNearest(Eigen::Vector3d(0.3, 0.3, 0.3), 1, &nn);
  ASSERT_EQ(nn.size(), 1u);
  EXPECT_EQ(nn[0].point_in_G, Eigen::Vector3d(0.1, 0.1, 0.1));  // first come, first kept

  o.max_points_per_leaf = 3;
  LocalMap three(o);
  int added = 0;
  for (int i = 0; i < 10; ++i) added += three.Insert(Eigen::Vector3d(0.01 * i, 0.2, 0.2)) ? 1 : 0;
  EXPECT_EQ(added, 3);
}

TEST(LocalMapTest, StaysBoundedWhenMovingFar) {
  LocalMapOptions o;
  o.leaf_size_m = 0.5;
  o.cell_size_m = 1.0;
  o.half_extent_m = 20.0;
  o.prune_distance_m = 2.0;
  LocalMap map(o);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-25.0, 25.0);
  size_t max_size = 0;
  for (int step = 0; step < 300; ++step) {
    const Eigen::Vector3d drone(1.0 * step, 0.5 * step, 0.0);  // 335 m in total
    map.UpdateCenter(drone);
    std::vector<Eigen::Vector3d> scan;
    for (int i = 0; i < 500; ++i) scan.push_back(drone + Eigen::Vector3d(u(rng), u(rng), 0.0));
    map.Insert(scan);
    max_size = std::max(max_size, map.size());
    const double bound = o.half_extent_m + o.prune_distance_m + o.cell_size_m / 2;
    for (const auto& p : map.Points()) {
      ASSERT_LE((p - drone).cwiseAbs().maxCoeff(), bound) << "step " << step;
    }
  }
  // A 40 m x 40 m (+ prune slack) square at one point per 0.25 m^2 leaf.
  const double side = 2 * (o.half_extent_m + o.prune_distance_m + 1.0);
  EXPECT_LE(max_size, static_cast<size_t>(side * side / (0.5 * 0.5)));
  EXPECT_GT(map.size(), 3000u);
}

TEST(LocalMapTest, RemovalFreesLeavesAndCells) {
  LocalMapOptions o;
  o.leaf_size_m = 0.5;
  o.half_extent_m = 10.0;
  o.prune_distance_m = 100.0;  // only explicit RemoveOutside prunes
  LocalMap map(o);
  EXPECT_TRUE(map.Insert(Eigen::Vector3d(9.0, 0.0, 0.0)));
  EXPECT_TRUE(map.Insert(Eigen::Vector3d(-9.0, 0.0, 0.0)));
  EXPECT_FALSE(map.Insert(Eigen::Vector3d(11.0, 0.0, 0.0)));  // outside the box at the origin
  EXPECT_EQ(map.UpdateCenter(Eigen::Vector3d(5.0, 0.0, 0.0)), 0);  // moved < prune distance
  EXPECT_EQ(map.size(), 2u);
  EXPECT_EQ(map.RemoveOutside(Eigen::Vector3d(5.0, 0.0, 0.0)), 1);  // -9 is 14 m away
  EXPECT_EQ(map.size(), 1u);
  EXPECT_EQ(map.num_cells(), 1u);
  std::vector<Neighbor> nn;
  EXPECT_EQ(map.KNearest(Eigen::Vector3d(-9.0, 0.0, 0.0), 5, &nn), 0);
  // Back home: the removed point's leaf is free again.
  map.RemoveOutside(Eigen::Vector3d::Zero());
  EXPECT_TRUE(map.Insert(Eigen::Vector3d(-9.1, 0.1, 0.1)));
  EXPECT_EQ(map.size(), 2u);
  map.Clear();
  EXPECT_TRUE(map.empty());
  EXPECT_EQ(map.num_cells(), 0u);
  EXPECT_TRUE(map.Insert(Eigen::Vector3d(9.0, 0.0, 0.0)));
}

TEST(LocalMapTest, OptionsValidate) {
  LocalMapOptions o;
  EXPECT_EQ(o.Validate(), "");
  o.half_extent_m = 0.5;
  EXPECT_NE(o.Validate().find("half_extent_m"), std::string::npos);
  o = LocalMapOptions();
  o.leaf_size_m = -1.0;
  EXPECT_NE(o.Validate().find("leaf_size_m"), std::string::npos);
  o = LocalMapOptions();
  o.replace_range_ratio = 1.5;
  EXPECT_NE(o.Validate().find("replace_range_ratio"), std::string::npos);
}

TEST(LocalMapTest, KNearestReturnsTheRangeEachPointWasObservedFrom) {
  LocalMap map(LocalMapOptions{});
  const std::vector<Eigen::Vector3d> points = {{0.1, 0.1, 0.1}, {1.1, 0.1, 0.1}, {2.1, 0.1, 0.1}};
  const std::vector<double> ranges = {12.5, -1.0, std::nan("")};  // invalid -> 0 (unknown)
  ASSERT_EQ(map.Insert(points, &ranges), 3);
  EXPECT_TRUE(map.Insert(Eigen::Vector3d(3.1, 0.1, 0.1)));  // no range given -> 0
  std::vector<Neighbor> nn;
  ASSERT_EQ(map.KNearest(Eigen::Vector3d(1.6, 0.1, 0.1), 4, &nn), 4);
  for (const Neighbor& nb : nn) {
    const bool observed = nb.point_in_G.x() < 0.5;
    EXPECT_FLOAT_EQ(nb.observed_range_m, observed ? 12.5f : 0.0f) << nb.point_in_G.transpose();
  }
}

// replace_range_ratio: a full leaf's farthest-observed point gives way to one
// observed from closer than ratio x its range; nothing else changes.
TEST(LocalMapTest, ANearerObservationReplacesTheFarthestInAFullLeaf) {
  LocalMapOptions o;
  o.leaf_size_m = 0.5;
  o.max_points_per_leaf = 2;
  o.replace_range_ratio = 0.5;
  LocalMap map(o);
  ASSERT_TRUE(map.Insert(Eigen::Vector3d(0.1, 0.1, 0.1), 40.0));
  ASSERT_TRUE(map.Insert(Eigen::Vector3d(0.2, 0.1, 0.1), 30.0));
  ASSERT_TRUE(map.Insert(Eigen::Vector3d(0.6, 0.1, 0.1), 40.0));        // the next leaf
  EXPECT_FALSE(map.Insert(Eigen::Vector3d(0.3, 0.1, 0.1), 20.0));       // not below 0.5 x 40
  EXPECT_FALSE(map.Insert(Eigen::Vector3d(0.3, 0.1, 0.1)));             // range unknown
  EXPECT_TRUE(map.Insert(Eigen::Vector3d(0.4, 0.1, 0.1), 19.0));        // replaces the 40 m one
  EXPECT_EQ(map.size(), 3u);
  std::vector<Neighbor> nn;
  ASSERT_EQ(map.KNearest(Eigen::Vector3d(0.25, 0.1, 0.1), 3, &nn), 3);
  std::vector<float> ranges;
  for (const Neighbor& nb : nn) {
    EXPECT_NE(nb.point_in_G, Eigen::Vector3d(0.1, 0.1, 0.1));          // the one replaced
    ranges.push_back(static_cast<float>(nb.observed_range_m));
  }
  std::sort(ranges.begin(), ranges.end());
  EXPECT_EQ(ranges, (std::vector<float>{19.0f, 30.0f, 40.0f}));         // 40: the other leaf
  EXPECT_TRUE(map.Insert(Eigen::Vector3d(0.1, 0.4, 0.1), 14.0));        // now the 30 m one
  EXPECT_FALSE(map.Insert(Eigen::Vector3d(0.1, 0.3, 0.1), 10.0));       // 10 >= 0.5 x 19
  EXPECT_EQ(map.size(), 3u);

  o.replace_range_ratio = 0.0;  // off: first come, first kept
  LocalMap off(o);
  ASSERT_TRUE(off.Insert(Eigen::Vector3d(0.1, 0.1, 0.1), 40.0));
  ASSERT_TRUE(off.Insert(Eigen::Vector3d(0.2, 0.1, 0.1), 30.0));
  EXPECT_FALSE(off.Insert(Eigen::Vector3d(0.4, 0.1, 0.1), 1.0));
}

}  // namespace
}  // namespace swarmlio::lio
