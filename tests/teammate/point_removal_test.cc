#include "swarmlio/teammate/point_removal.h"

#include <gtest/gtest.h>

namespace swarmlio::teammate {
namespace {

TEST(PointRemoval, RemovesPointsNearAnyCentre) {
  std::vector<ScanPoint> points(6);
  const float xs[] = {0.f, 0.5f, 0.69f, 0.71f, 3.f, 3.6f};
  for (int k = 0; k < 6; ++k) points[static_cast<size_t>(k)].p_in_b = Eigen::Vector3f(xs[k], 0, 0);
  std::vector<int> removed;
  FindPointsNear(points, {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(3.2, 0, 0)}, 0.7, &removed);
  EXPECT_EQ(removed, (std::vector<int>{0, 1, 2, 4, 5}));
  const std::vector<ScanPoint> kept = RemovePoints(points, removed);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_FLOAT_EQ(kept[0].p_in_b.x(), 0.71f);
  FindPointsNear(points, {}, 0.7, &removed);
  EXPECT_TRUE(removed.empty());
}

}  // namespace
}  // namespace swarmlio::teammate
