#include "swarmlio/io/bag_reader.h"

#include <geometry_msgs/PoseStamped.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/query.h>
#include <rosbag/view.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>

#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

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

using internal::kLivoxCustomMsgMd5;

constexpr char kImuType[] = "sensor_msgs/Imu";
constexpr char kPointCloud2Type[] = "sensor_msgs/PointCloud2";
constexpr char kPoseStampedType[] = "geometry_msgs/PoseStamped";
// The Livox drivers 1 and 2 use the same CustomMsg layout (and MD5).
constexpr std::array<const char*, 2> kCustomMsgTypes = {"livox_ros_driver/CustomMsg",
                                                        "livox_ros_driver2/CustomMsg"};

enum class StreamKind { kImu, kLidar, kGroundTruth };

const char* OptionKey(StreamKind kind) {
  switch (kind) {
    case StreamKind::kImu:
      return "imu_topic";
    case StreamKind::kLidar:
      return "lidar_topic";
    case StreamKind::kGroundTruth:
      return "ground_truth_topic";
  }
  return "?";
}

bool AllFinite(const Eigen::Vector3d& v) { return v.allFinite(); }

bool PointFinite(const LidarPoint& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) &&
         std::isfinite(p.offset_time_s);
}

// Removes non-finite points; returns how many were removed.
int64_t DropNonFinitePoints(LidarScan* scan) {
  std::vector<LidarPoint>& points = scan->points;
  const size_t before = points.size();
  size_t kept = 0;
  for (size_t i = 0; i < before; ++i) {
    if (PointFinite(points[i])) {
      if (kept != i) points[kept] = points[i];
      ++kept;
    }
  }
  points.resize(kept);
  return static_cast<int64_t>(before - kept);
}

}  // namespace

int64_t BagRecord::stamp_ns() const {
  return std::visit([](const auto& r) { return r.stamp_ns; }, data);
}

class BagReader::Impl {
 public:
  Impl(std::string path, BagReaderOptions options)
      : path_(std::move(path)), options_(std::move(options)) {}

  Status Open();
  Status Next(BagRecord* record, bool* has_record);

  const ReadStats& stats() const { return stats_; }
  const BagReaderOptions& options() const { return options_; }
  const std::string& path() const { return path_; }
  LidarMessageType lidar_message_type() const { return lidar_type_; }
  bool has_ground_truth() const { return streams_.size() == 3; }
  int64_t start_time_ns() const { return start_time_ns_; }
  int64_t end_time_ns() const { return end_time_ns_; }

 private:
  // One topic streamed through its own index view, with one decoded record
  // of lookahead for the stamp-ordered merge.
  struct TopicStream {
    StreamKind kind = StreamKind::kImu;
    std::string topic;
    std::unique_ptr<rosbag::View> view;
    rosbag::View::iterator it;
    rosbag::View::iterator end;
    bool exhausted = false;
    std::optional<BagRecord> pending;
    bool pending_without_point_time = false;
    bool has_last_stamp = false;
    int64_t last_stamp_ns = 0;
    int64_t message_index = 0;  // index within the topic of the message at `it`
  };

  Status CheckTopic(const std::vector<const rosbag::ConnectionInfo*>& connections,
                    StreamKind kind,
                    const std::string& topic,
                    bool required,
                    bool* found);
  Status AddStream(StreamKind kind, const std::string& topic);
  Status Fill(TopicStream* stream);
  // Decodes and checks the message at stream->it; sets stream->pending when
  // the record is delivered, leaves it empty when skipped.
  Status Consume(TopicStream* stream, const rosbag::MessageInstance& message);
  Status Malformed(const TopicStream& stream,
                   const rosbag::MessageInstance& message,
                   const Status& cause);
  void Skip(SkipReason reason, const TopicStream& stream, int64_t count = 1);
  bool AcceptStamp(TopicStream* stream, int64_t stamp_ns, SkipReason reason);

  std::string path_;
  BagReaderOptions options_;
  int64_t start_time_ns_ = 0;
  int64_t end_time_ns_ = 0;
  rosbag::Bag bag_;  // declared before streams_: the views point into it
  std::vector<TopicStream> streams_;
  LidarMessageType lidar_type_ = LidarMessageType::kPointCloud2;
  std::vector<uint8_t> buffer_;
  ReadStats stats_;
  std::array<bool, kNumSkipReasons> warned_{};
  bool warned_no_point_time_ = false;
  bool failed_ = false;
};

Status BagReader::Impl::CheckTopic(const std::vector<const rosbag::ConnectionInfo*>& connections,
                                   StreamKind kind,
                                   const std::string& topic,
                                   bool required,
                                   bool* found) {
  const std::string key = OptionKey(kind);
  *found = false;
  std::string type_found;
  for (const rosbag::ConnectionInfo* c : connections) {
    if (c->topic != topic) continue;
    *found = true;
    std::string expected;
    bool type_ok = false;
    bool md5_ok = false;
    if (kind == StreamKind::kImu) {
      expected = kImuType;
      type_ok = c->datatype == kImuType;
      md5_ok = c->md5sum == ros::message_traits::MD5Sum<sensor_msgs::Imu>::value();
    } else if (kind == StreamKind::kGroundTruth) {
      expected = kPoseStampedType;
      type_ok = c->datatype == kPoseStampedType;
      md5_ok = c->md5sum == ros::message_traits::MD5Sum<geometry_msgs::PoseStamped>::value();
    } else {
      expected = std::string(kPointCloud2Type) + " or " + kCustomMsgTypes[0];
      LidarMessageType type = LidarMessageType::kPointCloud2;
      if (c->datatype == kPointCloud2Type) {
        type_ok = true;
        md5_ok = c->md5sum == ros::message_traits::MD5Sum<sensor_msgs::PointCloud2>::value();
      } else {
        for (const char* custom : kCustomMsgTypes) {
          if (c->datatype == custom) {
            type_ok = true;
            type = LidarMessageType::kLivoxCustomMsg;
            md5_ok = c->md5sum == kLivoxCustomMsgMd5;
          }
        }
      }
      if (type_ok) {
        if (!type_found.empty() && type != lidar_type_) {
          return Status::InvalidArgument("bag '" + path_ + "': " + key + " '" + topic +
                                         "' carries several message types");
        }
        lidar_type_ = type;
      }
    }
    if (!type_ok) {
      return Status::InvalidArgument("bag '" + path_ + "': " + key + " '" + topic + "' has type " +
                                     c->datatype + ", expected " + expected);
    }
    if (!md5_ok) {
      return Status::InvalidArgument("bag '" + path_ + "': " + key + " '" + topic + "' type " +
                                     c->datatype + " has MD5 " + c->md5sum +
                                     ", which does not match the supported definition");
    }
    type_found = c->datatype;
  }
  if (required && !*found) {
    return Status::NotFound(
        "bag '" + path_ + "': " + key + " '" + topic +
        "' not found; the bag has topics: " + internal::DescribeTopics(connections));
  }
  return Status::Ok();
}

Status BagReader::Impl::AddStream(StreamKind kind, const std::string& topic) {
  TopicStream stream;
  stream.kind = kind;
  stream.topic = topic;
  stream.view = std::make_unique<rosbag::View>(bag_, rosbag::TopicQuery(topic));
  streams_.push_back(std::move(stream));
  TopicStream& added = streams_.back();
  added.it = added.view->begin();
  added.end = added.view->end();
  return Status::Ok();
}

Status BagReader::Impl::Open() {
  const std::string error = options_.Validate();
  if (!error.empty()) return Status::InvalidArgument("BagReaderOptions: " + error);
  SWARMLIO_RETURN_IF_ERROR(internal::OpenBagForReading(path_, options_.verify_chunks, &bag_));
  try {
    rosbag::View all(bag_);
    if (all.size() > 0) {
      start_time_ns_ = internal::StampNsFromRosTime(all.getBeginTime());
      end_time_ns_ = internal::StampNsFromRosTime(all.getEndTime());
    }
    const std::vector<const rosbag::ConnectionInfo*> connections = all.getConnections();
    bool found_imu = false;
    bool found_lidar = false;
    bool found_gt = false;
    SWARMLIO_RETURN_IF_ERROR(
        CheckTopic(connections, StreamKind::kImu, options_.imu_topic, true, &found_imu));
    SWARMLIO_RETURN_IF_ERROR(
        CheckTopic(connections, StreamKind::kLidar, options_.lidar_topic, true, &found_lidar));
    if (!options_.ground_truth_topic.empty()) {
      SWARMLIO_RETURN_IF_ERROR(CheckTopic(connections, StreamKind::kGroundTruth,
                                          options_.ground_truth_topic, false, &found_gt));
    }
    // Stream order = tie-break order of equal stamps.
    streams_.reserve(3);
    SWARMLIO_RETURN_IF_ERROR(AddStream(StreamKind::kImu, options_.imu_topic));
    SWARMLIO_RETURN_IF_ERROR(AddStream(StreamKind::kLidar, options_.lidar_topic));
    if (found_gt) {
      SWARMLIO_RETURN_IF_ERROR(AddStream(StreamKind::kGroundTruth, options_.ground_truth_topic));
    }
  } catch (const std::exception& e) {
    return internal::StatusFromException(path_, "reading the index", e);
  } catch (...) {
    return internal::UnknownExceptionStatus(path_, "reading the index");
  }
  return Status::Ok();
}

void BagReader::Impl::Skip(SkipReason reason, const TopicStream& stream, int64_t count) {
  const size_t index = static_cast<size_t>(reason);
  stats_.skipped[index] += count;
  if (!warned_[index]) {
    warned_[index] = true;
    LOG(WARNING) << "bag '" << path_ << "' topic '" << stream.topic << "': skipping ("
                 << SkipReasonName(reason) << "); further cases are only counted in ReadStats";
  }
}

bool BagReader::Impl::AcceptStamp(TopicStream* stream, int64_t stamp_ns, SkipReason reason) {
  if (stream->has_last_stamp && stamp_ns < stream->last_stamp_ns) {
    Skip(reason, *stream);
    return false;
  }
  stream->has_last_stamp = true;
  stream->last_stamp_ns = stamp_ns;
  return true;
}

Status BagReader::Impl::Malformed(const TopicStream& stream,
                                  const rosbag::MessageInstance& message,
                                  const Status& cause) {
  if (options_.skip_malformed_messages) {
    Skip(SkipReason::kMalformedMessage, stream);
    return Status::Ok();
  }
  return Status::DataLoss(
      "bag '" + path_ + "': topic '" + stream.topic + "' message #" +
      std::to_string(stream.message_index) + " (" + message.getDataType() + ", bag time " +
      std::to_string(internal::StampNsFromRosTime(message.getTime())) + " ns): " + cause.message());
}

Status BagReader::Impl::Consume(TopicStream* stream, const rosbag::MessageInstance& message) {
  const uint64_t size = message.size();
  const uint64_t max_bytes = static_cast<uint64_t>(options_.max_message_mib) << 20;
  if (size > max_bytes) {
    return Malformed(*stream, message,
                     Status::DataLoss("message size " + std::to_string(size) +
                                      " bytes exceeds max_message_mib"));
  }
  buffer_.resize(size);
  ros::serialization::OStream out(buffer_.data(), static_cast<uint32_t>(size));
  message.write(out);
  const uint8_t* data = buffer_.data();

  switch (stream->kind) {
    case StreamKind::kImu: {
      ImuSample imu;
      const Status status = internal::DecodeImu(data, size, &imu);
      if (!status.ok()) return Malformed(*stream, message, status);
      if (!AllFinite(imu.angular_velocity_rad_s) || !AllFinite(imu.linear_acceleration)) {
        Skip(SkipReason::kImuNonFinite, *stream);
        return Status::Ok();
      }
      if (!AcceptStamp(stream, imu.stamp_ns, SkipReason::kImuNonMonotonic)) return Status::Ok();
      stream->pending.emplace(BagRecord{std::move(imu)});
      return Status::Ok();
    }
    case StreamKind::kLidar: {
      LidarScan scan;
      bool without_point_time = false;
      Status status;
      if (lidar_type_ == LidarMessageType::kLivoxCustomMsg) {
        status = internal::DecodeLivoxCustomMsg(data, size, &scan);
      } else {
        internal::PointCloud2DecodeOptions decode_options;
        decode_options.time_unit = options_.point_time_unit;
        decode_options.time_field = options_.point_time_field;
        internal::PointCloud2DecodeInfo info;
        status = internal::DecodePointCloud2(data, size, decode_options, &scan, &info);
        without_point_time = status.ok() && !info.has_time_field;
      }
      if (!status.ok()) return Malformed(*stream, message, status);
      const int64_t dropped = DropNonFinitePoints(&scan);
      if (dropped > 0) Skip(SkipReason::kPointNonFinite, *stream, dropped);
      if (scan.points.empty()) {
        Skip(SkipReason::kScanEmpty, *stream);
        return Status::Ok();
      }
      if (!AcceptStamp(stream, scan.stamp_ns, SkipReason::kScanNonMonotonic)) return Status::Ok();
      if (without_point_time && !warned_no_point_time_) {
        warned_no_point_time_ = true;
        LOG(WARNING) << "bag '" << path_ << "' topic '" << stream->topic
                     << "': PointCloud2 has no per-point time field (tried "
                     << (options_.point_time_field.empty() ? "time, t, timestamp, offset_time"
                                                           : options_.point_time_field)
                     << "); reading each scan as one instant (all offsets 0)";
      }
      stream->pending_without_point_time = without_point_time;
      stream->pending.emplace(BagRecord{std::move(scan)});
      return Status::Ok();
    }
    case StreamKind::kGroundTruth: {
      PoseStamped pose;
      const Status status = internal::DecodePoseStamped(data, size, &pose);
      if (!status.ok()) return Malformed(*stream, message, status);
      if (!pose.p_b_in_G.allFinite() || !pose.q_G_b.coeffs().allFinite()) {
        Skip(SkipReason::kPoseNonFinite, *stream);
        return Status::Ok();
      }
      if (!AcceptStamp(stream, pose.stamp_ns, SkipReason::kPoseNonMonotonic)) return Status::Ok();
      stream->pending.emplace(BagRecord{std::move(pose)});
      return Status::Ok();
    }
  }
  return Status::Internal("unknown stream kind");
}

Status BagReader::Impl::Fill(TopicStream* stream) {
  while (!stream->pending.has_value() && !stream->exhausted) {
    if (stream->it == stream->end) {
      stream->exhausted = true;
      break;
    }
    SWARMLIO_RETURN_IF_ERROR(Consume(stream, *stream->it));
    ++stream->it;
    ++stream->message_index;
  }
  return Status::Ok();
}

Status BagReader::Impl::Next(BagRecord* record, bool* has_record) {
  *has_record = false;
  if (failed_) {
    return Status::FailedPrecondition("bag '" + path_ + "': reader stopped after an error");
  }
  Status status;
  try {
    for (TopicStream& stream : streams_) {
      status = Fill(&stream);
      if (!status.ok()) break;
    }
  } catch (const std::exception& e) {
    status = internal::StatusFromException(path_, "reading a message", e);
  } catch (...) {
    status = internal::UnknownExceptionStatus(path_, "reading a message");
  }
  if (!status.ok()) {
    failed_ = true;
    return status;
  }

  TopicStream* best = nullptr;
  for (TopicStream& stream : streams_) {
    if (!stream.pending.has_value()) continue;
    if (best == nullptr || stream.pending->stamp_ns() < best->pending->stamp_ns()) best = &stream;
  }
  if (best == nullptr) return Status::Ok();

  *record = std::move(*best->pending);
  best->pending.reset();
  *has_record = true;
  switch (best->kind) {
    case StreamKind::kImu:
      ++stats_.imu_samples;
      break;
    case StreamKind::kLidar:
      ++stats_.scans;
      stats_.points += static_cast<int64_t>(record->scan()->points.size());
      if (best->pending_without_point_time) ++stats_.scans_without_point_time;
      break;
    case StreamKind::kGroundTruth:
      ++stats_.ground_truth_poses;
      break;
  }
  return Status::Ok();
}

// ---------------------------------------------------------------------------

BagReader::BagReader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BagReader::~BagReader() = default;

Status BagReader::Open(const std::string& path,
                       const BagReaderOptions& options,
                       std::unique_ptr<BagReader>* reader) {
  CHECK(reader != nullptr);
  reader->reset();
  auto impl = std::make_unique<Impl>(path, options);
  SWARMLIO_RETURN_IF_ERROR(impl->Open());
  reader->reset(new BagReader(std::move(impl)));
  return Status::Ok();
}

Status BagReader::Next(BagRecord* record, bool* has_record) {
  CHECK(record != nullptr);
  CHECK(has_record != nullptr);
  return impl_->Next(record, has_record);
}

const ReadStats& BagReader::stats() const { return impl_->stats(); }
const BagReaderOptions& BagReader::options() const { return impl_->options(); }
const std::string& BagReader::path() const { return impl_->path(); }
LidarMessageType BagReader::lidar_message_type() const { return impl_->lidar_message_type(); }
bool BagReader::has_ground_truth() const { return impl_->has_ground_truth(); }
int64_t BagReader::start_time_ns() const { return impl_->start_time_ns(); }
int64_t BagReader::end_time_ns() const { return impl_->end_time_ns(); }

}  // namespace swarmlio::io
