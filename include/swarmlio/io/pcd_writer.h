// Writes point clouds as PCD files (binary, x y z float32) through PCL's
// writer; PCL stays inside src/io/pcd_writer.cc.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"

namespace swarmlio::io {

/// Writes `points` (any frame; coordinates rounded to float) to `path`.
/// IoError when the file cannot be written, InvalidArgument for non-finite
/// points (nothing is written).
Status WritePcd(const std::string& path, const std::vector<Eigen::Vector3d>& points);

/// Reads the x y z of a PCD file written by WritePcd (or any PCD with x, y, z).
Status ReadPcd(const std::string& path, std::vector<Eigen::Vector3d>* points);

}  // namespace swarmlio::io
