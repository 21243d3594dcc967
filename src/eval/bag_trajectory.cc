#include "swarmlio/eval/bag_trajectory.h"

#include <memory>
#include <vector>

#include "swarmlio/io/bag_reader.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::eval {

Status ReadBagGroundTruth(const std::string& path,
                          const io::BagReaderOptions& options,
                          Trajectory* trajectory) {
  // Only the poses are used: a LiDAR time unit that does not fit is no reason
  // to refuse the ground truth.
  io::BagReaderOptions reader_options = options;
  reader_options.check_point_time_span = false;
  std::unique_ptr<io::BagReader> reader;
  SWARMLIO_RETURN_IF_ERROR(io::BagReader::Open(path, reader_options, &reader));
  if (!reader->has_ground_truth()) {
    return Status::NotFound(path + ": no ground-truth topic '" + options.ground_truth_topic +
                            "' (geometry_msgs/PoseStamped or nav_msgs/Odometry; 'auto' takes "
                            "the bag's only such topic)");
  }
  std::vector<PoseStamped> poses;
  while (true) {
    io::BagRecord record;
    bool has_record = false;
    SWARMLIO_RETURN_IF_ERROR(reader->Next(&record, &has_record));
    if (!has_record) break;
    if (const PoseStamped* pose = record.ground_truth()) poses.push_back(*pose);
  }
  const std::string& topic = reader->ground_truth_topic();
  if (poses.empty()) return Status::NotFound(path + ": no usable pose on '" + topic + "'");
  Trajectory out = TrajectoryFromPoses(poses);
  SWARMLIO_RETURN_IF_ERROR(ValidateTrajectory(out, path + " " + topic));
  *trajectory = std::move(out);
  return Status::Ok();
}

}  // namespace swarmlio::eval
