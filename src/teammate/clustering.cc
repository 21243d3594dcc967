#include "swarmlio/teammate/clustering.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

#include <algorithm>
#include <limits>
#include <utility>

namespace swarmlio::teammate {

struct ReflectiveClusterer::Impl {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud{new pcl::PointCloud<pcl::PointXYZ>};
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree{new pcl::search::KdTree<pcl::PointXYZ>};
  std::vector<pcl::PointIndices> cluster_indices;
  std::vector<int> selected;
  std::vector<std::pair<float, int>> by_distance;
};

ReflectiveClusterer::ReflectiveClusterer(const ClusteringOptions& options)
    : options_(options), impl_(std::make_unique<Impl>()) {}

ReflectiveClusterer::~ReflectiveClusterer() = default;

void ReflectiveClusterer::FindReflectiveClusters(const std::vector<ScanPoint>& points,
                                                 std::vector<PointCluster>* clusters,
                                                 int* num_reflective_points) {
  const float min_reflectivity = static_cast<float>(options_.min_reflectivity);
  const float min_range2 = static_cast<float>(options_.min_range_m * options_.min_range_m);
  const float max_range2 = static_cast<float>(options_.max_range_m * options_.max_range_m);
  std::vector<int>& selected = impl_->selected;
  selected.clear();
  for (size_t i = 0; i < points.size(); ++i) {
    const ScanPoint& point = points[i];
    if (point.reflectivity < min_reflectivity) continue;
    const float range2 = point.p_in_b.squaredNorm();
    if (range2 < min_range2 || range2 > max_range2) continue;
    selected.push_back(static_cast<int>(i));
  }
  if (num_reflective_points != nullptr) *num_reflective_points = static_cast<int>(selected.size());
  ClusterIndices(points, selected, options_.max_cluster_points, clusters);
}

bool ReflectiveClusterer::ClusterRegion(const std::vector<ScanPoint>& points,
                                        const Eigen::Vector3d& center_in_b, double radius_m,
                                        PointCluster* cluster) {
  const Eigen::Vector3f center = center_in_b.cast<float>();
  const float radius2 = static_cast<float>(radius_m * radius_m);
  const float min_range2 = static_cast<float>(options_.min_range_m * options_.min_range_m);
  std::vector<std::pair<float, int>>& by_distance = impl_->by_distance;
  by_distance.clear();
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i].p_in_b;
    const float dx = p.x() - center.x();
    if (dx * dx > radius2) continue;  // cheap rejection of most points
    const float d2 = (p - center).squaredNorm();
    if (d2 > radius2 || p.squaredNorm() < min_range2) continue;
    by_distance.emplace_back(d2, static_cast<int>(i));
  }
  const size_t keep = static_cast<size_t>(options_.max_region_points);
  if (by_distance.size() > keep) {
    std::nth_element(by_distance.begin(), by_distance.begin() + static_cast<std::ptrdiff_t>(keep),
                     by_distance.end());
    by_distance.resize(keep);
  }
  std::vector<int> indices;
  indices.reserve(by_distance.size());
  for (const auto& [d2, index] : by_distance) indices.push_back(index);
  std::sort(indices.begin(), indices.end());  // deterministic cluster order
  std::vector<PointCluster> clusters;
  ClusterIndices(points, indices, options_.max_region_points, &clusters);
  double best = std::numeric_limits<double>::infinity();
  for (const PointCluster& c : clusters) {
    const double d = (c.centroid_in_b - center_in_b).norm();
    if (d < best) {
      best = d;
      *cluster = c;
    }
  }
  return !clusters.empty();
}

void ReflectiveClusterer::ClusterIndices(const std::vector<ScanPoint>& points,
                                         const std::vector<int>& indices, int max_cluster_points,
                                         std::vector<PointCluster>* clusters) {
  clusters->clear();
  if (static_cast<int>(indices.size()) < options_.min_cluster_points || indices.empty()) return;
  pcl::PointCloud<pcl::PointXYZ>& cloud = *impl_->cloud;
  cloud.resize(indices.size());
  for (size_t k = 0; k < indices.size(); ++k) {
    const Eigen::Vector3f& p = points[static_cast<size_t>(indices[k])].p_in_b;
    cloud[k] = pcl::PointXYZ(p.x(), p.y(), p.z());
  }
  impl_->tree->setInputCloud(impl_->cloud);
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> extraction;
  extraction.setClusterTolerance(options_.cluster_tolerance_m);
  extraction.setMinClusterSize(options_.min_cluster_points);
  extraction.setMaxClusterSize(max_cluster_points);
  extraction.setSearchMethod(impl_->tree);
  extraction.setInputCloud(impl_->cloud);
  impl_->cluster_indices.clear();
  extraction.extract(impl_->cluster_indices);

  const float min_reflectivity = static_cast<float>(options_.min_reflectivity);
  for (const pcl::PointIndices& members : impl_->cluster_indices) {
    PointCluster c;
    c.min_in_b.setConstant(std::numeric_limits<double>::infinity());
    c.max_in_b.setConstant(-std::numeric_limits<double>::infinity());
    Eigen::Vector3d sum = Eigen::Vector3d::Zero(), reflective_sum = Eigen::Vector3d::Zero();
    double time_sum = 0.0, reflective_time_sum = 0.0;
    for (const int member : members.indices) {
      const ScanPoint& point = points[static_cast<size_t>(indices[static_cast<size_t>(member)])];
      const Eigen::Vector3d p = point.p_in_b.cast<double>();
      sum += p;
      c.min_in_b = c.min_in_b.cwiseMin(p);
      c.max_in_b = c.max_in_b.cwiseMax(p);
      time_sum += point.time_offset_s;
      if (point.reflectivity >= min_reflectivity) {
        ++c.num_reflective_points;
        reflective_sum += p;
        reflective_time_sum += point.time_offset_s;
      }
    }
    if (c.num_reflective_points > 0) {
      c.reflective_centroid_in_b = reflective_sum / c.num_reflective_points;
      c.reflective_mean_time_offset_s = reflective_time_sum / c.num_reflective_points;
    }
    c.num_points = static_cast<int>(members.indices.size());
    c.centroid_in_b = sum / c.num_points;
    c.mean_time_offset_s = time_sum / c.num_points;
    clusters->push_back(c);
  }
  // Deterministic order: by distance from the sensor.
  std::sort(clusters->begin(), clusters->end(), [](const PointCluster& a, const PointCluster& b) {
    return a.centroid_in_b.squaredNorm() < b.centroid_in_b.squaredNorm();
  });
}

}  // namespace swarmlio::teammate
