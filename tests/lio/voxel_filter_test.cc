#include "swarmlio/lio/voxel_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <tuple>
#include <vector>

#include "swarmlio/lio/map_voxel_key.h"

namespace swarmlio::lio {
namespace {

PointXYZT MakePoint(double x, double y, double z, double t = 0.0, float refl = 0.f) {
  PointXYZT p;
  p.p_in_b = Eigen::Vector3d(x, y, z);
  p.time_s = t;
  p.reflectivity = refl;
  return p;
}

std::vector<PointXYZT> RandomCloud(int n, double half_extent_m, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-half_extent_m, half_extent_m);
  std::vector<PointXYZT> points;
  for (int i = 0; i < n; ++i) {
    points.push_back(MakePoint(u(rng), u(rng), u(rng), 1e-5 * i, static_cast<float>(i % 256)));
  }
  return points;
}

using KeyTuple = std::tuple<int32_t, int32_t, int32_t>;
KeyTuple Key(const Eigen::Vector3d& p, double leaf) {
  const VoxelKey k = VoxelKeyOf(p, 1.0 / leaf);
  return {k.x, k.y, k.z};
}

TEST(VoxelFilterTest, EmptyInputGivesEmptyOutput) {
  VoxelFilter filter(VoxelFilterOptions{});
  std::vector<PointXYZT> out = {MakePoint(1, 2, 3)};
  filter.Filter({}, &out);
  EXPECT_TRUE(out.empty());
}

TEST(VoxelFilterTest, OnePointPerVoxelClosestToCentre) {
  const double leaf = 0.5;
  VoxelFilter filter(VoxelFilterOptions{leaf});
  const std::vector<PointXYZT> in = RandomCloud(20000, 3.0, 1);
  const std::vector<PointXYZT> out = filter.Filter(in);

  // Reference: best (closest to centre, earliest on ties) input point per voxel.
  std::map<KeyTuple, int> best;
  for (int i = 0; i < static_cast<int>(in.size()); ++i) {
    const KeyTuple key = Key(in[i].p_in_b, leaf);
    const Eigen::Vector3d centre = VoxelCenter(VoxelKeyOf(in[i].p_in_b, 1.0 / leaf), leaf);
    auto it = best.find(key);
    if (it == best.end() ||
        (in[i].p_in_b - centre).squaredNorm() < (in[it->second].p_in_b - centre).squaredNorm()) {
      best[key] = i;
    }
  }
  ASSERT_EQ(out.size(), best.size());
  std::map<KeyTuple, int> seen;
  for (const PointXYZT& p : out) {
    const KeyTuple key = Key(p.p_in_b, leaf);
    ASSERT_EQ(seen.count(key), 0u) << "two points in one voxel";
    seen[key] = 1;
    const PointXYZT& ref = in[best.at(key)];
    EXPECT_EQ(p.p_in_b, ref.p_in_b);
    EXPECT_EQ(p.time_s, ref.time_s);  // time and reflectivity travel with the point
    EXPECT_EQ(p.reflectivity, ref.reflectivity);
  }
}

TEST(VoxelFilterTest, Deterministic) {
  const std::vector<PointXYZT> in = RandomCloud(5000, 10.0, 7);
  VoxelFilter a(VoxelFilterOptions{0.3});
  VoxelFilter b(VoxelFilterOptions{0.3});
  const std::vector<PointXYZT> first = a.Filter(in);
  const std::vector<PointXYZT> second = a.Filter(in);  // reused internal map
  const std::vector<PointXYZT> third = b.Filter(in);
  ASSERT_EQ(first.size(), second.size());
  ASSERT_EQ(first.size(), third.size());
  for (size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(first[i].p_in_b, second[i].p_in_b);
    EXPECT_EQ(first[i].p_in_b, third[i].p_in_b);
  }
}

TEST(VoxelFilterTest, LeafBoundariesAreHalfOpen) {
  VoxelFilter filter(VoxelFilterOptions{0.5});
  // 1.0 belongs to [1.0, 1.5), 0.999 to [0.5, 1.0); -0.25 to [-0.5, 0), 0.25 to [0, 0.5).
  EXPECT_EQ(filter.Filter({MakePoint(1.0, 0.1, 0.1), MakePoint(0.999, 0.1, 0.1)}).size(), 2u);
  EXPECT_EQ(filter.Filter({MakePoint(-0.25, 0.1, 0.1), MakePoint(0.25, 0.1, 0.1)}).size(), 2u);
  EXPECT_EQ(filter.Filter({MakePoint(1.0, 0.1, 0.1), MakePoint(1.49, 0.4, 0.4)}).size(), 1u);
  EXPECT_EQ(filter.Filter({MakePoint(0.1, 0.1, -1e-9), MakePoint(0.1, 0.1, 0.0)}).size(), 2u);
}

TEST(VoxelFilterTest, OutputOrderFollowsFirstPointOfEachVoxel) {
  VoxelFilter filter(VoxelFilterOptions{1.0});
  const std::vector<PointXYZT> out =
      filter.Filter({MakePoint(5.9, 0.5, 0.5, 0.0), MakePoint(0.1, 0.1, 0.1, 0.1),
                     MakePoint(5.5, 0.5, 0.5, 0.2)});
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].time_s, 0.2);  // voxel of the first point; its centre-closest point
  EXPECT_EQ(out[1].time_s, 0.1);
}

TEST(VoxelFilterTest, TieKeepsEarlierPointAndSkipsNonFinite) {
  VoxelFilter filter(VoxelFilterOptions{1.0});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<PointXYZT> out =
      filter.Filter({MakePoint(nan, 0, 0), MakePoint(0.25, 0.5, 0.5, 1.0),
                     MakePoint(0.75, 0.5, 0.5, 2.0),
                     MakePoint(std::numeric_limits<double>::infinity(), 0, 0)});
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].time_s, 1.0);
}

}  // namespace
}  // namespace swarmlio::lio
