#include "swarmlio/io/pcd_writer.h"

#include <pcl/io/pcd_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <filesystem>

namespace swarmlio::io {

Status WritePcd(const std::string& path, const std::vector<Eigen::Vector3d>& points) {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  cloud.reserve(points.size());
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) return Status::InvalidArgument(path + ": non-finite point, not written");
    cloud.push_back(pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                  static_cast<float>(p.z())));
  }
  cloud.width = static_cast<uint32_t>(cloud.size());
  cloud.height = 1;
  cloud.is_dense = true;
  if (cloud.empty()) {
    // PCL refuses to write an empty cloud; an empty map is still a valid result.
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (f == nullptr) return Status::IoError(path + ": cannot open for writing");
    const char header[] =
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n"
        "TYPE F F F\nCOUNT 1 1 1\nWIDTH 0\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 0\n"
        "DATA binary\n";
    const bool ok = std::fwrite(header, 1, sizeof(header) - 1, f) == sizeof(header) - 1;
    return std::fclose(f) == 0 && ok ? Status::Ok()
                                     : Status::IoError(path + ": write failed");
  }
  pcl::PCDWriter writer;
  if (writer.writeBinary(path, cloud) != 0) return Status::IoError(path + ": cannot write PCD");
  return Status::Ok();
}

Status ReadPcd(const std::string& path, std::vector<Eigen::Vector3d>* points) {
  if (!std::filesystem::exists(path)) return Status::NotFound(path + ": no such file");
  pcl::PointCloud<pcl::PointXYZ> cloud;
  pcl::PCDReader reader;
  if (reader.read(path, cloud) != 0) return Status::DataLoss(path + ": not a readable PCD file");
  points->clear();
  points->reserve(cloud.size());
  for (const pcl::PointXYZ& p : cloud) points->emplace_back(p.x, p.y, p.z);
  return Status::Ok();
}

}  // namespace swarmlio::io
