// A rosbag2 folder (what `ros2 bag record` writes): metadata.yaml names the
// storage files (rosbag2_bagfile_information.relative_file_paths: .db3 or
// .mcap; without metadata.yaml the folder's .db3 and .mcap files in name
// order). Each file is opened by its magic bytes; a split recording (several
// files, in recording order) is read as one log: connections merged by topic
// and type, each topic's messages file after file.
#pragma once

#include <memory>
#include <string>

#include "src/io/bag_source.h"
#include "swarmlio/common/status.h"

namespace swarmlio::io::internal {

Status OpenRosbag2Folder(const std::string& path,
                         const BagSourceOptions& options,
                         std::unique_ptr<BagSource>* source);

}  // namespace swarmlio::io::internal
