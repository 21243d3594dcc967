#include "swarmlio/teammate/association.h"

#include <gtest/gtest.h>

namespace swarmlio::teammate {
namespace {

TEST(AssociateNearest, NearestPairsFirstWithinTheGate) {
  const std::vector<Eigen::Vector3d> predictions = {{0, 0, 0}, {1, 0, 0}, {5, 5, 5}};
  const std::vector<Eigen::Vector3d> clusters = {{0.9, 0, 0}, {0.2, 0, 0}, {0.45, 0, 0}, {9, 9, 9}};
  std::vector<bool> available(clusters.size(), true);
  const std::vector<int> a = AssociateNearest(predictions, clusters, 0.5, &available);
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a[0], 1);   // 0.2 away
  EXPECT_EQ(a[1], 0);   // 0.1 away (the cluster at 0.45 is 0.55 away: outside the gate)
  EXPECT_EQ(a[2], -1);  // nothing within 0.5 m
  EXPECT_FALSE(available[0]);
  EXPECT_FALSE(available[1]);
  EXPECT_TRUE(available[2]);
  EXPECT_TRUE(available[3]);
}

TEST(AssociateNearest, AClusterGoesToOneTrackerOnlyAndUnavailableOnesAreSkipped) {
  const std::vector<Eigen::Vector3d> predictions = {{0, 0, 0}, {0.1, 0, 0}};
  const std::vector<Eigen::Vector3d> clusters = {{0.12, 0, 0}, {0.0, 0.01, 0}};
  std::vector<bool> available = {true, false};
  const std::vector<int> a = AssociateNearest(predictions, clusters, 0.5, &available);
  EXPECT_EQ(a[0], -1);
  EXPECT_EQ(a[1], 0);
}

}  // namespace
}  // namespace swarmlio::teammate
