#include "swarmlio/teammate/clustering.h"

#include <gtest/gtest.h>

#include <random>

#include "synthetic_scan.h"

namespace swarmlio::teammate {
namespace {

using testing::AddBackground;
using testing::AddBlob;

TEST(ReflectiveClusterer, FindsTapeBlobsAndIgnoresDiffusePoints) {
  std::mt19937_64 rng(1);
  std::vector<ScanPoint> points;
  AddBackground(5000, &rng, &points);
  const Eigen::Vector3d a(3.0, 1.0, 0.2), b(-2.0, 4.0, -0.3);
  AddBlob(a, Eigen::Vector3d(0.1, 0.07, 0.025), 30, 230.f, &rng, &points);
  AddBlob(b, Eigen::Vector3d(0.1, 0.07, 0.025), 12, 210.f, &rng, &points);
  AddBlob(Eigen::Vector3d(25, 0, 0), Eigen::Vector3d::Constant(0.05), 30, 250.f, &rng, &points);  // beyond 20 m

  ReflectiveClusterer clusterer{ClusteringOptions()};
  std::vector<PointCluster> clusters;
  int num_reflective = 0;
  clusterer.FindReflectiveClusters(points, &clusters, &num_reflective);
  EXPECT_EQ(num_reflective, 42);
  ASSERT_EQ(clusters.size(), 2u);
  // Sorted by range: a (3.2 m) before b (4.5 m).
  EXPECT_LT((clusters[0].centroid_in_b - a).norm(), 0.05);
  EXPECT_LT((clusters[1].centroid_in_b - b).norm(), 0.05);
  EXPECT_EQ(clusters[0].num_points, 30);
  EXPECT_EQ(clusters[0].num_reflective_points, 30);
  EXPECT_TRUE(clusterer.IsDroneSized(clusters[0]));
  EXPECT_LT((clusters[0].reflective_centroid_in_b - clusters[0].centroid_in_b).norm(), 1e-12);
}

TEST(ReflectiveClusterer, ToleranceSplitsAndMergesClusters) {
  std::mt19937_64 rng(2);
  std::vector<ScanPoint> points;
  // Two blobs 0.2 m apart merge at 0.3 m tolerance; 0.6 m apart they do not.
  AddBlob(Eigen::Vector3d(2, 0, 0), Eigen::Vector3d::Constant(0.02), 10, 240.f, &rng, &points);
  AddBlob(Eigen::Vector3d(2, 0.2, 0), Eigen::Vector3d::Constant(0.02), 10, 240.f, &rng, &points);
  AddBlob(Eigen::Vector3d(2, 0.8, 0), Eigen::Vector3d::Constant(0.02), 10, 240.f, &rng, &points);
  ReflectiveClusterer clusterer{ClusteringOptions()};
  std::vector<PointCluster> clusters;
  clusterer.FindReflectiveClusters(points, &clusters);
  ASSERT_EQ(clusters.size(), 2u);
  int sizes = clusters[0].num_points * 100 + clusters[1].num_points;
  EXPECT_TRUE(sizes == 2010 || sizes == 1020) << sizes;
}

TEST(ReflectiveClusterer, MinimumClusterSizeAndObjectSize) {
  std::mt19937_64 rng(3);
  std::vector<ScanPoint> points;
  AddBlob(Eigen::Vector3d(4, 0, 0), Eigen::Vector3d::Constant(0.02), 2, 240.f, &rng, &points);  // too few
  // A 1.2 m long reflective sign: a cluster, but not drone-sized.
  AddBlob(Eigen::Vector3d(0, 5, 0), Eigen::Vector3d(0.6, 0.01, 0.2), 400, 240.f, &rng, &points);
  ReflectiveClusterer clusterer{ClusteringOptions()};
  std::vector<PointCluster> clusters;
  clusterer.FindReflectiveClusters(points, &clusters);
  ASSERT_EQ(clusters.size(), 1u);
  EXPECT_GT(clusters[0].SizeM(), 1.0);
  EXPECT_FALSE(clusterer.IsDroneSized(clusters[0]));
}

TEST(ReflectiveClusterer, RegionClusteringUsesRawPointsAndPicksTheNearestCluster) {
  std::mt19937_64 rng(4);
  std::vector<ScanPoint> points;
  AddBackground(3000, &rng, &points);
  // A drone whose tape is too dim to pass the threshold, and a second object nearby.
  const Eigen::Vector3d drone(5.0, -2.0, 0.5);
  AddBlob(drone, Eigen::Vector3d(0.12, 0.12, 0.06), 25, 120.f, &rng, &points, -0.04f);
  AddBlob(drone + Eigen::Vector3d(0, 0.45, 0), Eigen::Vector3d::Constant(0.03), 8, 60.f, &rng, &points);
  ReflectiveClusterer clusterer{ClusteringOptions()};
  std::vector<PointCluster> reflective;
  clusterer.FindReflectiveClusters(points, &reflective);
  EXPECT_TRUE(reflective.empty());

  PointCluster cluster;
  ASSERT_TRUE(clusterer.ClusterRegion(points, drone + Eigen::Vector3d(0.1, -0.05, 0), 0.5, &cluster));
  EXPECT_EQ(cluster.num_points, 25);
  EXPECT_EQ(cluster.num_reflective_points, 0);
  EXPECT_LT((cluster.centroid_in_b - drone).norm(), 0.05);
  EXPECT_NEAR(cluster.mean_time_offset_s, -0.04, 1e-6);
  // Nothing there.
  EXPECT_FALSE(clusterer.ClusterRegion(points, Eigen::Vector3d(0, 0, 0.5), 0.5, &cluster));
}

TEST(ReflectiveClusterer, RegionKeepsOnlyTheNearestPoints) {
  std::mt19937_64 rng(5);
  std::vector<ScanPoint> points;
  AddBlob(Eigen::Vector3d(3, 0, 0), Eigen::Vector3d::Constant(0.1), 400, 100.f, &rng, &points);
  ClusteringOptions options;
  options.max_region_points = 50;
  ReflectiveClusterer clusterer(options);
  PointCluster cluster;
  ASSERT_TRUE(clusterer.ClusterRegion(points, Eigen::Vector3d(3, 0, 0), 0.5, &cluster));
  EXPECT_EQ(cluster.num_points, 50);
}

}  // namespace
}  // namespace swarmlio::teammate
