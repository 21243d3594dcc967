#include "swarmlio/io/bag_writer.h"

#include <geometry_msgs/PoseStamped.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>

#include <exception>
#include <string>
#include <utility>

#include "src/io/bag_common.h"
#include "src/io/custom_msg.h"
#include "src/io/custom_msg_codec.h"
#include "src/io/imu_codec.h"
#include "src/io/pointcloud2_codec.h"
#include "src/io/pose_codec.h"
#include "src/io/ros_time.h"
#include "swarmlio/common/check.h"

namespace swarmlio::io {
namespace {

rosbag::CompressionType ToRosbag(BagCompression compression) {
  switch (compression) {
    case BagCompression::kNone:
      return rosbag::compression::Uncompressed;
    case BagCompression::kLz4:
      return rosbag::compression::LZ4;
    case BagCompression::kBz2:
      return rosbag::compression::BZ2;
  }
  return rosbag::compression::Uncompressed;
}

}  // namespace

class BagWriter::Impl {
 public:
  Impl(std::string path, BagWriterOptions options)
      : path_(std::move(path)), options_(std::move(options)) {}

  ~Impl() {
    if (open_) static_cast<void>(Close());
  }

  Status Open() {
    const std::string error = options_.Validate();
    if (!error.empty()) return Status::InvalidArgument("BagWriterOptions: " + error);
    internal::RouteRosbagLogsToGlog();
    try {
      bag_.open(path_, rosbag::bagmode::Write);
      bag_.setCompression(ToRosbag(options_.compression));
    } catch (const std::exception& e) {
      return internal::StatusFromException(path_, "open for writing", e);
    } catch (...) {
      return internal::UnknownExceptionStatus(path_, "open for writing");
    }
    open_ = true;
    return Status::Ok();
  }

  Status WriteImu(const ImuSample& imu, int64_t record_time_ns) {
    sensor_msgs::Imu msg;
    SWARMLIO_RETURN_IF_ERROR(
        internal::EncodeImu(imu, imu_seq_, &msg).WithContext("bag '" + path_ + "': IMU"));
    SWARMLIO_RETURN_IF_ERROR(Write(options_.imu_topic, record_time_ns, msg));
    ++imu_seq_;
    return Status::Ok();
  }

  Status WriteScan(const LidarScan& scan, int64_t record_time_ns) {
    const std::string context = "bag '" + path_ + "': scan";
    if (options_.lidar_format == LidarMessageFormat::kLivoxCustomMsg) {
      internal::LivoxCustomMsg msg;
      SWARMLIO_RETURN_IF_ERROR(
          internal::EncodeLivoxCustomMsg(scan, scan_seq_, &msg).WithContext(context));
      SWARMLIO_RETURN_IF_ERROR(Write(options_.lidar_topic, record_time_ns, msg));
    } else {
      sensor_msgs::PointCloud2 msg;
      SWARMLIO_RETURN_IF_ERROR(internal::EncodePointCloud2(scan, scan_seq_,
                                                           options_.point_time_unit,
                                                           options_.write_point_time
                                                               ? options_.point_time_field
                                                               : std::string(),
                                                           &msg)
                                   .WithContext(context));
      SWARMLIO_RETURN_IF_ERROR(Write(options_.lidar_topic, record_time_ns, msg));
    }
    ++scan_seq_;
    return Status::Ok();
  }

  Status WriteGroundTruth(const PoseStamped& pose, int64_t record_time_ns) {
    const std::string context = "bag '" + path_ + "': ground truth";
    if (options_.ground_truth_format == GroundTruthFormat::kOdometry) {
      internal::NavOdometry msg;
      SWARMLIO_RETURN_IF_ERROR(
          internal::EncodeOdometry(pose, pose_seq_, &msg).WithContext(context));
      SWARMLIO_RETURN_IF_ERROR(Write(options_.ground_truth_topic, record_time_ns, msg));
    } else {
      geometry_msgs::PoseStamped msg;
      SWARMLIO_RETURN_IF_ERROR(
          internal::EncodePoseStamped(pose, pose_seq_, &msg).WithContext(context));
      SWARMLIO_RETURN_IF_ERROR(Write(options_.ground_truth_topic, record_time_ns, msg));
    }
    ++pose_seq_;
    return Status::Ok();
  }

  Status Close() {
    if (!open_) return Status::Ok();
    open_ = false;
    try {
      bag_.close();
    } catch (const std::exception& e) {
      return internal::StatusFromException(path_, "close", e);
    } catch (...) {
      return internal::UnknownExceptionStatus(path_, "close");
    }
    return Status::Ok();
  }

  const std::string& path() const { return path_; }

 private:
  template <class Msg>
  Status Write(const std::string& topic, int64_t record_time_ns, const Msg& msg) {
    if (!open_) return Status::FailedPrecondition("bag '" + path_ + "': writer is closed");
    ros::Time time;
    SWARMLIO_RETURN_IF_ERROR(internal::BagTimeFromStampNs(record_time_ns, &time)
                                 .WithContext("bag '" + path_ + "': record time"));
    try {
      bag_.write(topic, time, msg);
    } catch (const std::exception& e) {
      return internal::StatusFromException(path_, "writing to topic '" + topic + "'", e);
    } catch (...) {
      return internal::UnknownExceptionStatus(path_, "writing to topic '" + topic + "'");
    }
    return Status::Ok();
  }

  std::string path_;
  BagWriterOptions options_;
  rosbag::Bag bag_;
  bool open_ = false;
  uint32_t imu_seq_ = 0;
  uint32_t scan_seq_ = 0;
  uint32_t pose_seq_ = 0;
};

BagWriter::BagWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BagWriter::~BagWriter() = default;

Status BagWriter::Open(const std::string& path,
                       const BagWriterOptions& options,
                       std::unique_ptr<BagWriter>* writer) {
  CHECK(writer != nullptr);
  writer->reset();
  auto impl = std::make_unique<Impl>(path, options);
  SWARMLIO_RETURN_IF_ERROR(impl->Open());
  writer->reset(new BagWriter(std::move(impl)));
  return Status::Ok();
}

Status BagWriter::WriteImu(const ImuSample& imu) { return WriteImu(imu, imu.stamp_ns); }
Status BagWriter::WriteImu(const ImuSample& imu, int64_t record_time_ns) {
  return impl_->WriteImu(imu, record_time_ns);
}
Status BagWriter::WriteScan(const LidarScan& scan) { return WriteScan(scan, scan.stamp_ns); }
Status BagWriter::WriteScan(const LidarScan& scan, int64_t record_time_ns) {
  return impl_->WriteScan(scan, record_time_ns);
}
Status BagWriter::WriteGroundTruth(const PoseStamped& pose) {
  return WriteGroundTruth(pose, pose.stamp_ns);
}
Status BagWriter::WriteGroundTruth(const PoseStamped& pose, int64_t record_time_ns) {
  return impl_->WriteGroundTruth(pose, record_time_ns);
}
Status BagWriter::Close() { return impl_->Close(); }
const std::string& BagWriter::path() const { return impl_->path(); }

}  // namespace swarmlio::io
