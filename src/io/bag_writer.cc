#include "swarmlio/io/bag_writer.h"

#include <geometry_msgs/PoseStamped.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>

#include <exception>
#include <limits>
#include <map>
#include <string>
#include <utility>

#include "src/io/bag_common.h"
#include "src/io/cdr_serialize.h"
#include "src/io/custom_msg.h"
#include "src/io/custom_msg_codec.h"
#include "src/io/db3_writer.h"
#include "src/io/imu_codec.h"
#include "src/io/mcap_writer.h"
#include "src/io/message_types.h"
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
    case BagCompression::kZstd:
      break;  // refused by CheckCompressionFor
  }
  return rosbag::compression::Uncompressed;
}

std::string McapCompression(BagCompression compression) {
  switch (compression) {
    case BagCompression::kLz4:
      return "lz4";
    case BagCompression::kZstd:
      return "zstd";
    default:
      return "";
  }
}

// The ROS 2 stamp's int32 seconds must hold the stamp (ROS1 allows 2^32 s).
Status CheckRos2Stamp(const ros::Time& stamp) {
  if (stamp.sec > static_cast<uint32_t>(std::numeric_limits<int32_t>::max())) {
    return Status::InvalidArgument("stamp " + std::to_string(stamp.sec) +
                                   " s does not fit a ROS 2 int32 stamp");
  }
  return Status::Ok();
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
    std::string error = options_.Validate();
    const BagFormat format = ResolveBagFormat(options_.format, path_);
    if (error.empty()) error = CheckCompressionFor(format, options_.compression);
    if (!error.empty()) return Status::InvalidArgument("BagWriterOptions: " + error);
    if (format == BagFormat::kDb3) {
      db3_ = std::make_unique<internal::Db3Writer>();
      SWARMLIO_RETURN_IF_ERROR(db3_->Open(path_));
      open_ = true;
      return Status::Ok();
    }
    if (format == BagFormat::kMcap) {
      internal::McapWriterOptions mcap_options;
      mcap_options.compression = McapCompression(options_.compression);
      mcap_ = std::make_unique<internal::McapWriter>();
      SWARMLIO_RETURN_IF_ERROR(mcap_->Open(path_, mcap_options));
      open_ = true;
      return Status::Ok();
    }
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
    SWARMLIO_RETURN_IF_ERROR(
        Write(options_.imu_topic, internal::MessageKind::kImu, record_time_ns, msg));
    ++imu_seq_;
    return Status::Ok();
  }

  Status WriteScan(const LidarScan& scan, int64_t record_time_ns) {
    const std::string context = "bag '" + path_ + "': scan";
    if (options_.lidar_format == LidarMessageFormat::kLivoxCustomMsg) {
      internal::LivoxCustomMsg msg;
      SWARMLIO_RETURN_IF_ERROR(
          internal::EncodeLivoxCustomMsg(scan, scan_seq_, &msg).WithContext(context));
      SWARMLIO_RETURN_IF_ERROR(
          Write(options_.lidar_topic, internal::MessageKind::kLivoxCustomMsg, record_time_ns, msg));
    } else {
      sensor_msgs::PointCloud2 msg;
      SWARMLIO_RETURN_IF_ERROR(internal::EncodePointCloud2(scan, scan_seq_,
                                                           options_.point_time_unit,
                                                           options_.write_point_time
                                                               ? options_.point_time_field
                                                               : std::string(),
                                                           &msg)
                                   .WithContext(context));
      SWARMLIO_RETURN_IF_ERROR(
          Write(options_.lidar_topic, internal::MessageKind::kPointCloud2, record_time_ns, msg));
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
      SWARMLIO_RETURN_IF_ERROR(Write(options_.ground_truth_topic, internal::MessageKind::kOdometry,
                                     record_time_ns, msg));
    } else {
      geometry_msgs::PoseStamped msg;
      SWARMLIO_RETURN_IF_ERROR(
          internal::EncodePoseStamped(pose, pose_seq_, &msg).WithContext(context));
      SWARMLIO_RETURN_IF_ERROR(Write(options_.ground_truth_topic,
                                     internal::MessageKind::kPoseStamped, record_time_ns, msg));
    }
    ++pose_seq_;
    return Status::Ok();
  }

  Status Close() {
    if (!open_) return Status::Ok();
    open_ = false;
    if (mcap_ != nullptr) return mcap_->Close();
    if (db3_ != nullptr) return db3_->Close();
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
  // rosbag2 .db3: the topic's row on first use.
  Status Db3Topic(const std::string& topic, internal::MessageKind kind, int64_t* id) {
    const auto found = db3_topics_.find(topic);
    if (found != db3_topics_.end()) {
      *id = found->second;
      return Status::Ok();
    }
    SWARMLIO_RETURN_IF_ERROR(db3_->AddTopic(topic, internal::Ros2TypeName(kind), id));
    db3_topics_[topic] = *id;
    return Status::Ok();
  }

  // MCAP: the topic's channel (and its type's schema) on first use.
  Status McapChannel(const std::string& topic, internal::MessageKind kind, uint16_t* channel) {
    const auto found = mcap_channels_.find(topic);
    if (found != mcap_channels_.end()) {
      *channel = found->second;
      return Status::Ok();
    }
    auto schema = mcap_schemas_.find(kind);
    if (schema == mcap_schemas_.end()) {
      uint16_t id = 0;
      SWARMLIO_RETURN_IF_ERROR(mcap_->AddSchema(internal::Ros2TypeName(kind), "ros2msg",
                                                internal::Ros2SchemaText(kind), &id));
      schema = mcap_schemas_.emplace(kind, id).first;
    }
    SWARMLIO_RETURN_IF_ERROR(
        mcap_->AddChannel(schema->second, topic, internal::kCdrEncoding, channel));
    mcap_channels_[topic] = *channel;
    return Status::Ok();
  }

  // A ROS 2 log (MCAP or .db3): the message as CDR.
  template <class Msg>
  Status WriteRos2(const std::string& topic,
                   internal::MessageKind kind,
                   int64_t record_time_ns,
                   const Msg& msg) {
    if (record_time_ns < 0) {
      return Status::InvalidArgument("bag '" + path_ + "': record time " +
                                     std::to_string(record_time_ns) + " ns is negative");
    }
    SWARMLIO_RETURN_IF_ERROR(CheckRos2Stamp(msg.header.stamp).WithContext("bag '" + path_ + "'"));
    internal::SerializeCdr(msg, &buffer_);
    if (db3_ != nullptr) {
      int64_t topic_id = 0;
      SWARMLIO_RETURN_IF_ERROR(Db3Topic(topic, kind, &topic_id));
      return db3_->WriteMessage(topic_id, record_time_ns, buffer_);
    }
    uint16_t channel = 0;
    SWARMLIO_RETURN_IF_ERROR(McapChannel(topic, kind, &channel));
    return mcap_->WriteMessage(channel, static_cast<uint64_t>(record_time_ns), buffer_);
  }

  template <class Msg>
  Status Write(const std::string& topic,
               internal::MessageKind kind,
               int64_t record_time_ns,
               const Msg& msg) {
    if (!open_) return Status::FailedPrecondition("bag '" + path_ + "': writer is closed");
    if (mcap_ != nullptr || db3_ != nullptr) return WriteRos2(topic, kind, record_time_ns, msg);
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
  std::unique_ptr<internal::McapWriter> mcap_;  // set when writing MCAP instead of ROS1
  std::unique_ptr<internal::Db3Writer> db3_;    // set when writing a rosbag2 .db3 file
  std::map<std::string, int64_t> db3_topics_;
  std::map<std::string, uint16_t> mcap_channels_;
  std::map<internal::MessageKind, uint16_t> mcap_schemas_;
  std::vector<uint8_t> buffer_;
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
