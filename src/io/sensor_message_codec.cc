// Single serialized sensor messages <-> records (sensor_message_codec.h),
// with the bag reader's decoders and checks.
#include "swarmlio/io/sensor_message_codec.h"

#include <ros/serialization.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>

#include <utility>

#include "src/io/custom_msg.h"
#include "src/io/custom_msg_codec.h"
#include "src/io/imu_codec.h"
#include "src/io/point_time_check.h"
#include "src/io/pointcloud2_codec.h"
#include "src/io/record_checks.h"

namespace swarmlio::io {
namespace {

template <class Msg>
void Serialize(const Msg& msg, std::vector<uint8_t>* bytes, RosMessageType* type) {
  const uint32_t length = ros::serialization::serializationLength(msg);
  bytes->resize(length);
  ros::serialization::OStream stream(bytes->data(), length);
  ros::serialization::serialize(stream, msg);
  type->datatype = ros::message_traits::DataType<Msg>::value();
  type->md5sum = ros::message_traits::MD5Sum<Msg>::value();
  type->definition = ros::message_traits::Definition<Msg>::value();
}

void Count(ReadStats* stats, SkipReason reason, int64_t count = 1) {
  stats->skipped[static_cast<size_t>(reason)] += count;
}

}  // namespace

bool LidarMessageTypeFromDatatype(const std::string& datatype, LidarMessageType* type) {
  if (datatype == ros::message_traits::DataType<sensor_msgs::PointCloud2>::value()) {
    *type = LidarMessageType::kPointCloud2;
    return true;
  }
  if (internal::IsCustomMsgType(datatype)) {
    *type = LidarMessageType::kLivoxCustomMsg;
    return true;
  }
  return false;
}

std::string ExpectedMd5(const std::string& datatype) {
  if (datatype == ros::message_traits::DataType<sensor_msgs::Imu>::value()) {
    return ros::message_traits::MD5Sum<sensor_msgs::Imu>::value();
  }
  if (datatype == ros::message_traits::DataType<sensor_msgs::PointCloud2>::value()) {
    return ros::message_traits::MD5Sum<sensor_msgs::PointCloud2>::value();
  }
  if (internal::IsCustomMsgType(datatype)) return internal::kLivoxCustomMsgMd5;
  return "";
}

SensorMessageDecoder::SensorMessageDecoder(const BagReaderOptions& options, double scan_period_s)
    : options_(options), scan_period_s_(scan_period_s) {}

Status SensorMessageDecoder::DecodeImu(const uint8_t* data, size_t size, ImuSample* imu,
                                       bool* accepted) {
  *accepted = false;
  SWARMLIO_RETURN_IF_ERROR(internal::DecodeImu(data, size, imu).WithContext("sensor_msgs/Imu"));
  if (!internal::AllFinite(imu->angular_velocity_rad_s) ||
      !internal::AllFinite(imu->linear_acceleration)) {
    Count(&stats_, SkipReason::kImuNonFinite);
    return Status::Ok();
  }
  if (has_imu_stamp_ && imu->stamp_ns < last_imu_stamp_ns_) {
    Count(&stats_, SkipReason::kImuNonMonotonic);
    return Status::Ok();
  }
  has_imu_stamp_ = true;
  last_imu_stamp_ns_ = imu->stamp_ns;
  ++stats_.imu_samples;
  *accepted = true;
  return Status::Ok();
}

Status SensorMessageDecoder::DecodeScan(LidarMessageType type, const uint8_t* data, size_t size,
                                        LidarScan* scan, bool* accepted) {
  *accepted = false;
  bool without_point_time = false;
  std::string time_field;
  if (type == LidarMessageType::kLivoxCustomMsg) {
    SWARMLIO_RETURN_IF_ERROR(
        internal::DecodeLivoxCustomMsg(data, size, scan).WithContext("Livox CustomMsg"));
  } else {
    internal::PointCloud2DecodeOptions decode_options;
    decode_options.time_unit = options_.point_time_unit;
    decode_options.time_field = options_.point_time_field;
    internal::PointCloud2DecodeInfo info;
    SWARMLIO_RETURN_IF_ERROR(internal::DecodePointCloud2(data, size, decode_options, scan, &info)
                                 .WithContext("sensor_msgs/PointCloud2"));
    without_point_time = !info.has_time_field;
    time_field = info.time_field;
  }
  const int64_t dropped = internal::DropNonFinitePoints(scan);
  if (dropped > 0) Count(&stats_, SkipReason::kPointNonFinite, dropped);
  if (scan->points.empty()) {
    Count(&stats_, SkipReason::kScanEmpty);
    return Status::Ok();
  }
  if (options_.check_point_time_span && type == LidarMessageType::kPointCloud2 &&
      !without_point_time) {
    const std::string problem = internal::CheckPointTimeSpan(
        *scan, options_.point_time_unit, time_field, scan_period_s_, /*period_measured=*/false);
    if (!problem.empty()) return Status::InvalidArgument("sensor_msgs/PointCloud2: " + problem);
  }
  if (has_scan_stamp_ && scan->stamp_ns < last_scan_stamp_ns_) {
    Count(&stats_, SkipReason::kScanNonMonotonic);
    return Status::Ok();
  }
  has_scan_stamp_ = true;
  last_scan_stamp_ns_ = scan->stamp_ns;
  if (without_point_time) {
    ++stats_.scans_without_point_time;
    const bool azimuth =
        options_.reconstruct_point_time == PointTimeReconstruction::kAzimuth ||
        (options_.reconstruct_point_time == PointTimeReconstruction::kAuto &&
         options_.spinning_lidar);
    if (azimuth && internal::ReconstructPointTimeFromAzimuth(scan_period_s_, scan).reconstructed) {
      ++stats_.scans_point_time_from_azimuth;
    }
  }
  ++stats_.scans;
  stats_.points += static_cast<int64_t>(scan->points.size());
  *accepted = true;
  return Status::Ok();
}

Status SerializeImu(const ImuSample& imu, uint32_t seq, std::vector<uint8_t>* bytes,
                    RosMessageType* type) {
  sensor_msgs::Imu msg;
  SWARMLIO_RETURN_IF_ERROR(internal::EncodeImu(imu, seq, &msg));
  Serialize(msg, bytes, type);
  return Status::Ok();
}

Status SerializeScan(const LidarScan& scan, const BagWriterOptions& options, uint32_t seq,
                     std::vector<uint8_t>* bytes, RosMessageType* type) {
  if (options.lidar_format == LidarMessageFormat::kLivoxCustomMsg) {
    internal::LivoxCustomMsg msg;
    SWARMLIO_RETURN_IF_ERROR(internal::EncodeLivoxCustomMsg(scan, seq, &msg));
    Serialize(msg, bytes, type);
    return Status::Ok();
  }
  sensor_msgs::PointCloud2 msg;
  SWARMLIO_RETURN_IF_ERROR(internal::EncodePointCloud2(
      scan, seq, options.point_time_unit,
      options.write_point_time ? options.point_time_field : std::string(), &msg));
  Serialize(msg, bytes, type);
  return Status::Ok();
}

}  // namespace swarmlio::io
