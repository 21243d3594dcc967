#include "swarmlio/io/bag_reader.h"

#include <geometry_msgs/PoseStamped.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>

#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "src/io/bag_source.h"
#include "src/io/custom_msg.h"
#include "src/io/custom_msg_codec.h"
#include "src/io/imu_codec.h"
#include "src/io/message_types.h"
#include "src/io/odometry_msg.h"
#include "src/io/point_time_check.h"
#include "src/io/pointcloud2_codec.h"
#include "src/io/pose_codec.h"
#include "src/io/record_checks.h"
#include "swarmlio/common/check.h"

namespace swarmlio::io {
namespace {

using internal::AllFinite;
using internal::DropNonFinitePoints;
using internal::MessageKind;
using internal::WireEncoding;

// LiDAR messages whose bag times give the scan period.
constexpr size_t kScanPeriodSamples = 1001;

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

// The message types a stream accepts, for messages: ROS1 names, or for a
// log of ROS 2 (CDR) messages the ROS 2 names.
const char* AcceptedTypes(StreamKind kind, bool ros2) {
  switch (kind) {
    case StreamKind::kImu:
      return ros2 ? "sensor_msgs/msg/Imu" : "sensor_msgs/Imu";
    case StreamKind::kLidar:
      return ros2 ? "sensor_msgs/msg/PointCloud2 or livox_ros_driver2/msg/CustomMsg"
                  : "sensor_msgs/PointCloud2 or livox_ros_driver(2)/CustomMsg";
    case StreamKind::kGroundTruth:
      return ros2 ? "geometry_msgs/msg/PoseStamped or nav_msgs/msg/Odometry"
                  : "geometry_msgs/PoseStamped or nav_msgs/Odometry";
  }
  return "?";
}

StreamKind StreamOf(MessageKind kind) {
  switch (kind) {
    case MessageKind::kImu:
      return StreamKind::kImu;
    case MessageKind::kPointCloud2:
    case MessageKind::kLivoxCustomMsg:
      return StreamKind::kLidar;
    default:
      return StreamKind::kGroundTruth;
  }
}

bool TypeMatches(StreamKind kind, const internal::SourceConnection& c) {
  WireEncoding wire = WireEncoding::kRos1;
  const MessageKind message = internal::MessageKindOf(c.datatype, c.encoding, &wire);
  return message != MessageKind::kUnsupported && StreamOf(message) == kind;
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
  GroundTruthMessageType ground_truth_message_type() const { return ground_truth_type_; }
  bool has_ground_truth() const { return !ground_truth_topic_.empty(); }
  const std::string& imu_topic() const { return imu_topic_; }
  const std::string& lidar_topic() const { return lidar_topic_; }
  const std::string& ground_truth_topic() const { return ground_truth_topic_; }
  double scan_period_s() const { return scan_period_s_; }
  int64_t start_time_ns() const { return source_->start_time_ns(); }
  int64_t end_time_ns() const { return source_->end_time_ns(); }

 private:
  // One topic streamed in bag-time order, with one decoded record of
  // lookahead for the stamp-ordered merge.
  struct TopicStream {
    StreamKind kind = StreamKind::kImu;
    std::string topic;
    std::unique_ptr<internal::TopicMessageStream> messages;
    bool exhausted = false;
    std::optional<BagRecord> pending;
    bool pending_without_point_time = false;
    bool pending_time_from_azimuth = false;
    bool has_last_stamp = false;
    int64_t last_stamp_ns = 0;
    int64_t message_index = -1;  // index within the topic of the last message read
  };

  // Finds the topic of `kind`: the configured one when the bag has it, else
  // the only topic of a matching type (see BagReaderOptions). "" = none
  // (ground truth only).
  Status ResolveTopic(StreamKind kind, const std::string& configured, std::string* resolved);
  // Checks every connection of `topic` for a supported type and MD5, and
  // sets lidar_type_ / ground_truth_type_.
  Status CheckTopic(StreamKind kind, const std::string& topic);
  Status AddStream(StreamKind kind, const std::string& topic);
  Status Fill(TopicStream* stream);
  // Decodes and checks one message; sets stream->pending when the record is
  // delivered, leaves it empty when skipped.
  Status Consume(TopicStream* stream, const internal::SourceMessage& message);
  // True when the log holds ROS 2 (CDR) messages (for the type names in errors).
  bool Ros2Log() const {
    for (const internal::SourceConnection& c : source_->connections()) {
      if (c.encoding == internal::kCdrEncoding) return true;
    }
    return false;
  }
  // True when scans without a per-point time field get it from azimuth.
  bool ReconstructFromAzimuth() const {
    return options_.reconstruct_point_time == PointTimeReconstruction::kAzimuth ||
           (options_.reconstruct_point_time == PointTimeReconstruction::kAuto &&
            options_.spinning_lidar);
  }
  Status Malformed(const TopicStream& stream,
                   const internal::SourceMessage& message,
                   const Status& cause);
  std::string Where(const TopicStream& stream, const internal::SourceMessage& message) const;
  void Skip(SkipReason reason, const TopicStream& stream, int64_t count = 1);
  bool AcceptStamp(TopicStream* stream, int64_t stamp_ns, SkipReason reason);

  std::string path_;
  BagReaderOptions options_;
  std::unique_ptr<internal::BagSource> source_;  // declared before streams_: they read it
  std::vector<TopicStream> streams_;
  std::string imu_topic_;
  std::string lidar_topic_;
  std::string ground_truth_topic_;
  LidarMessageType lidar_type_ = LidarMessageType::kPointCloud2;
  GroundTruthMessageType ground_truth_type_ = GroundTruthMessageType::kPoseStamped;
  std::array<WireEncoding, 3> encodings_{};  // by StreamKind
  double scan_period_s_ = internal::kDefaultScanPeriodS;
  bool scan_period_measured_ = false;
  ReadStats stats_;
  std::array<bool, kNumSkipReasons> warned_{};
  bool warned_no_point_time_ = false;
  bool failed_ = false;
};

Status BagReader::Impl::ResolveTopic(StreamKind kind,
                                     const std::string& configured,
                                     std::string* resolved) {
  resolved->clear();
  const std::string key = OptionKey(kind);
  const bool ground_truth = kind == StreamKind::kGroundTruth;
  if (ground_truth && configured.empty()) return Status::Ok();  // none wanted
  const bool is_auto = ground_truth ? configured == kAutoTopic : IsAutoTopic(configured);
  const std::vector<internal::SourceConnection>& connections = source_->connections();
  if (!is_auto) {
    for (const internal::SourceConnection& c : connections) {
      if (c.topic == configured) {
        *resolved = configured;
        return Status::Ok();
      }
    }
    // A configured ground-truth topic that is absent means no ground truth:
    // another odometry topic may be an estimate, not ground truth.
    if (ground_truth) return Status::Ok();
  }
  std::map<std::string, std::string> candidates;  // topic -> datatype
  for (const internal::SourceConnection& c : connections) {
    if (TypeMatches(kind, c)) candidates.emplace(c.topic, c.datatype);
  }
  const std::string what = is_auto ? key + " is '" + configured + "' (find by type)"
                                   : key + " '" + configured + "' not found";
  if (candidates.size() == 1) {
    *resolved = candidates.begin()->first;
    if (!is_auto) {
      LOG(WARNING) << "bag '" << path_ << "': " << what << "; using '" << *resolved
                   << "', the only " << candidates.begin()->second << " topic (set " << key
                   << " to silence this)";
    }
    return Status::Ok();
  }
  if (candidates.empty()) {
    if (ground_truth) return Status::Ok();
    return Status::NotFound("bag '" + path_ + "': " + what + ", and no topic has type " +
                            AcceptedTypes(kind, Ros2Log()) +
                            "; the bag has topics: " + internal::DescribeTopics(connections));
  }
  std::string list;
  for (const auto& [topic, datatype] : candidates) {
    list += (list.empty() ? "" : ", ") + topic + " [" + datatype + "]";
  }
  return Status::NotFound("bag '" + path_ + "': " + what + ", and " +
                          std::to_string(candidates.size()) + " topics have type " +
                          AcceptedTypes(kind, Ros2Log()) + ": " + list + "; set " + key +
                          " to one of them");
}

Status BagReader::Impl::CheckTopic(StreamKind kind, const std::string& topic) {
  const std::string where = "bag '" + path_ + "': " + OptionKey(kind) + " '" + topic + "'";
  bool found = false;
  MessageKind first = MessageKind::kUnsupported;
  WireEncoding first_wire = WireEncoding::kRos1;
  for (const internal::SourceConnection& c : source_->connections()) {
    if (c.topic != topic) continue;
    WireEncoding wire = WireEncoding::kRos1;
    const MessageKind message = internal::MessageKindOf(c.datatype, c.encoding, &wire);
    if (message == MessageKind::kUnsupported || StreamOf(message) != kind) {
      const std::string encoding =
          c.encoding == internal::kRos1Encoding ? "" : " (encoding " + c.encoding + ")";
      return Status::InvalidArgument(where + " has type " + c.datatype + encoding + ", expected " +
                                     AcceptedTypes(kind, Ros2Log()));
    }
    if (wire == WireEncoding::kRos1 && c.md5sum != internal::ExpectedRos1Md5(message)) {
      return Status::InvalidArgument(where + " type " + c.datatype + " has MD5 " + c.md5sum +
                                     ", which does not match the supported definition");
    }
    if (found && (message != first || wire != first_wire)) {
      return Status::InvalidArgument(where + " carries several message types");
    }
    found = true;
    first = message;
    first_wire = wire;
  }
  encodings_[static_cast<size_t>(kind)] = first_wire;
  if (first == MessageKind::kLivoxCustomMsg) lidar_type_ = LidarMessageType::kLivoxCustomMsg;
  if (first == MessageKind::kPointCloud2) lidar_type_ = LidarMessageType::kPointCloud2;
  if (first == MessageKind::kOdometry) ground_truth_type_ = GroundTruthMessageType::kOdometry;
  if (first == MessageKind::kPoseStamped) {
    ground_truth_type_ = GroundTruthMessageType::kPoseStamped;
  }
  return Status::Ok();
}

Status BagReader::Impl::AddStream(StreamKind kind, const std::string& topic) {
  TopicStream stream;
  stream.kind = kind;
  stream.topic = topic;
  SWARMLIO_RETURN_IF_ERROR(source_->OpenTopic(topic, &stream.messages));
  streams_.push_back(std::move(stream));
  return Status::Ok();
}

Status BagReader::Impl::Open() {
  const std::string error = options_.Validate();
  if (!error.empty()) return Status::InvalidArgument("BagReaderOptions: " + error);
  internal::BagSourceOptions source_options;
  source_options.verify_chunks = options_.verify_chunks;
  source_options.recover = options_.recover_damaged_bags;
  SWARMLIO_RETURN_IF_ERROR(internal::BagSource::Open(path_, source_options, &source_));
  stats_.recovery = source_->recovery();
  stats_.skipped[static_cast<size_t>(SkipReason::kDamagedRecord)] = stats_.recovery.damaged_records;

  SWARMLIO_RETURN_IF_ERROR(ResolveTopic(StreamKind::kImu, options_.imu_topic, &imu_topic_));
  SWARMLIO_RETURN_IF_ERROR(ResolveTopic(StreamKind::kLidar, options_.lidar_topic, &lidar_topic_));
  SWARMLIO_RETURN_IF_ERROR(
      ResolveTopic(StreamKind::kGroundTruth, options_.ground_truth_topic, &ground_truth_topic_));
  SWARMLIO_RETURN_IF_ERROR(CheckTopic(StreamKind::kImu, imu_topic_));
  SWARMLIO_RETURN_IF_ERROR(CheckTopic(StreamKind::kLidar, lidar_topic_));
  if (!ground_truth_topic_.empty()) {
    SWARMLIO_RETURN_IF_ERROR(CheckTopic(StreamKind::kGroundTruth, ground_truth_topic_));
  }
  if ((options_.check_point_time_span || ReconstructFromAzimuth()) &&
      lidar_type_ == LidarMessageType::kPointCloud2) {
    std::vector<int64_t> times;
    SWARMLIO_RETURN_IF_ERROR(source_->TopicTimes(lidar_topic_, kScanPeriodSamples, &times));
    scan_period_s_ = internal::EstimateScanPeriodS(times);
    scan_period_measured_ = times.size() >= 2;
  }
  if (stats_.recovery.recovered) {
    LOG(WARNING) << "bag '" << path_ << "' is damaged: " << stats_.recovery.Summary();
  }
  // Stream order = tie-break order of equal stamps.
  streams_.reserve(3);
  SWARMLIO_RETURN_IF_ERROR(AddStream(StreamKind::kImu, imu_topic_));
  SWARMLIO_RETURN_IF_ERROR(AddStream(StreamKind::kLidar, lidar_topic_));
  if (!ground_truth_topic_.empty()) {
    SWARMLIO_RETURN_IF_ERROR(AddStream(StreamKind::kGroundTruth, ground_truth_topic_));
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

std::string BagReader::Impl::Where(const TopicStream& stream,
                                   const internal::SourceMessage& message) const {
  return "bag '" + path_ + "': topic '" + stream.topic + "' message #" +
         std::to_string(stream.message_index) + " (" + message.datatype + ", bag time " +
         std::to_string(message.bag_time_ns) + " ns)";
}

Status BagReader::Impl::Malformed(const TopicStream& stream,
                                  const internal::SourceMessage& message,
                                  const Status& cause) {
  if (options_.skip_malformed_messages) {
    Skip(SkipReason::kMalformedMessage, stream);
    return Status::Ok();
  }
  return Status::DataLoss(Where(stream, message) + ": " + cause.message());
}

Status BagReader::Impl::Consume(TopicStream* stream, const internal::SourceMessage& message) {
  if (message.too_large) {
    return Malformed(*stream, message,
                     Status::DataLoss("message size " + std::to_string(message.size) +
                                      " bytes exceeds max_message_mib"));
  }
  const uint8_t* data = message.data;
  const size_t size = message.size;
  const WireEncoding wire = encodings_[static_cast<size_t>(stream->kind)];

  switch (stream->kind) {
    case StreamKind::kImu: {
      ImuSample imu;
      const Status status = internal::DecodeImu(data, size, &imu, wire);
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
      std::string time_field;
      Status status;
      if (lidar_type_ == LidarMessageType::kLivoxCustomMsg) {
        status = internal::DecodeLivoxCustomMsg(data, size, &scan, wire);
      } else {
        internal::PointCloud2DecodeOptions decode_options;
        decode_options.time_unit = options_.point_time_unit;
        decode_options.time_field = options_.point_time_field;
        internal::PointCloud2DecodeInfo info;
        status = internal::DecodePointCloud2(data, size, decode_options, &scan, &info, wire);
        without_point_time = status.ok() && !info.has_time_field;
        time_field = info.time_field;
      }
      if (!status.ok()) return Malformed(*stream, message, status);
      const int64_t dropped = DropNonFinitePoints(&scan);
      if (dropped > 0) Skip(SkipReason::kPointNonFinite, *stream, dropped);
      if (scan.points.empty()) {
        Skip(SkipReason::kScanEmpty, *stream);
        return Status::Ok();
      }
      if (options_.check_point_time_span && lidar_type_ == LidarMessageType::kPointCloud2 &&
          !without_point_time) {
        const std::string problem = internal::CheckPointTimeSpan(
            scan, options_.point_time_unit, time_field, scan_period_s_, scan_period_measured_);
        if (!problem.empty()) {
          return Status::InvalidArgument(Where(*stream, message) + ": " + problem);
        }
      }
      if (!AcceptStamp(stream, scan.stamp_ns, SkipReason::kScanNonMonotonic)) return Status::Ok();
      bool from_azimuth = false;
      if (without_point_time && ReconstructFromAzimuth()) {
        from_azimuth = internal::ReconstructPointTimeFromAzimuth(scan_period_s_, &scan).reconstructed;
      }
      if (without_point_time && !warned_no_point_time_) {
        warned_no_point_time_ = true;
        LOG(WARNING) << "bag '" << path_ << "' topic '" << stream->topic
                     << "': PointCloud2 has no per-point time field (tried "
                     << (options_.point_time_field.empty() ? "time, t, timestamp, offset_time"
                                                           : options_.point_time_field)
                     << "); "
                     << (ReconstructFromAzimuth()
                             ? "reconstructing it from azimuth over the scan period " +
                                   std::to_string(scan_period_s_) + " s"
                             : std::string("reading each scan as one instant (all offsets 0; "
                                           "a spinning LiDAR: set spinning_lidar or "
                                           "reconstruct_point_time: azimuth)"));
      }
      stream->pending_without_point_time = without_point_time;
      stream->pending_time_from_azimuth = from_azimuth;
      stream->pending.emplace(BagRecord{std::move(scan)});
      return Status::Ok();
    }
    case StreamKind::kGroundTruth: {
      PoseStamped pose;
      const Status status = ground_truth_type_ == GroundTruthMessageType::kOdometry
                                ? internal::DecodeOdometryPose(data, size, &pose, wire)
                                : internal::DecodePoseStamped(data, size, &pose, wire);
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
  const uint64_t max_bytes = static_cast<uint64_t>(options_.max_message_mib) << 20;
  while (!stream->pending.has_value() && !stream->exhausted) {
    internal::SourceMessage message;
    bool has_message = false;
    SWARMLIO_RETURN_IF_ERROR(stream->messages->Next(max_bytes, &message, &has_message));
    if (!has_message) {
      stream->exhausted = true;
      break;
    }
    ++stream->message_index;
    SWARMLIO_RETURN_IF_ERROR(Consume(stream, message));
  }
  return Status::Ok();
}

Status BagReader::Impl::Next(BagRecord* record, bool* has_record) {
  *has_record = false;
  if (failed_) {
    return Status::FailedPrecondition("bag '" + path_ + "': reader stopped after an error");
  }
  Status status;
  for (TopicStream& stream : streams_) {
    status = Fill(&stream);
    if (!status.ok()) break;
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
      if (best->pending_time_from_azimuth) ++stats_.scans_point_time_from_azimuth;
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
GroundTruthMessageType BagReader::ground_truth_message_type() const {
  return impl_->ground_truth_message_type();
}
bool BagReader::has_ground_truth() const { return impl_->has_ground_truth(); }
const std::string& BagReader::imu_topic() const { return impl_->imu_topic(); }
const std::string& BagReader::lidar_topic() const { return impl_->lidar_topic(); }
const std::string& BagReader::ground_truth_topic() const { return impl_->ground_truth_topic(); }
double BagReader::scan_period_s() const { return impl_->scan_period_s(); }
int64_t BagReader::start_time_ns() const { return impl_->start_time_ns(); }
int64_t BagReader::end_time_ns() const { return impl_->end_time_ns(); }

}  // namespace swarmlio::io
