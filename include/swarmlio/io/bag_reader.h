// Streaming reader of IMU, LiDAR and ground-truth records from a ROS1 bag.
//
// Each configured topic is streamed through its own bag index view (nothing
// is loaded up front besides the bag's index), decoded with bounds-checked
// decoders, sanity-checked, and the topics are merged by header stamp. So the
// records come out ordered by stamp_ns (ties: IMU, then scan, then pose).
// Records that fail a check are skipped and counted in stats() (see
// read_stats.h); a malformed message or a broken bag is an error Status.
// Before rosbag sees the file its structure is checked (every length and
// offset against the file size, and with options.verify_chunks every chunk's
// records), so corrupt bags give an error, not a crash. A truncated or
// unindexed bag is read by scanning its records instead of rosbag's index
// (options.recover_damaged_bags): every complete message before the damage,
// the rest counted in stats().recovery.
//
// Topics left empty/"auto", or configured but absent from the bag, are found
// by message type when the bag has exactly one candidate (see
// BagReaderOptions); the resolved names are imu_topic(), lidar_topic() and
// ground_truth_topic().
//
// ROS headers stay in src/io; this header needs none.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <variant>

#include "swarmlio/common/status.h"
#include "swarmlio/io/bag_options.h"
#include "swarmlio/io/read_stats.h"
#include "swarmlio/sensors/measurements.h"

namespace swarmlio::io {

/// One record read from a bag: an IMU sample, a LiDAR scan or a ground-truth
/// pose of the body frame b in the global frame G.
struct BagRecord {
  std::variant<ImuSample, LidarScan, PoseStamped> data;

  const ImuSample* imu() const { return std::get_if<ImuSample>(&data); }
  const LidarScan* scan() const { return std::get_if<LidarScan>(&data); }
  const PoseStamped* ground_truth() const { return std::get_if<PoseStamped>(&data); }
  int64_t stamp_ns() const;
};

/// Type of the LiDAR topic found in the bag.
enum class LidarMessageType { kPointCloud2, kLivoxCustomMsg };

/// Type of the ground-truth topic found in the bag.
enum class GroundTruthMessageType { kPoseStamped, kOdometry };

class BagReader {
 public:
  /// Opens `path` and resolves the topics: the IMU and LiDAR topics must
  /// exist (or be found by type) with a supported type, the ground-truth
  /// topic may be absent.
  static Status Open(const std::string& path,
                     const BagReaderOptions& options,
                     std::unique_ptr<BagReader>* reader);

  ~BagReader();
  BagReader(const BagReader&) = delete;
  BagReader& operator=(const BagReader&) = delete;

  /// Reads the next record in stamp order. At the end of the bag returns Ok
  /// with *has_record = false. After an error the reader is unusable.
  Status Next(BagRecord* record, bool* has_record);

  const ReadStats& stats() const;
  const BagReaderOptions& options() const;
  const std::string& path() const;
  LidarMessageType lidar_message_type() const;
  GroundTruthMessageType ground_truth_message_type() const;
  bool has_ground_truth() const;
  /// The topics read (after discovery); ground_truth_topic() is "" without
  /// ground truth.
  const std::string& imu_topic() const;
  const std::string& lidar_topic() const;
  const std::string& ground_truth_topic() const;
  /// Scan period used by the per-point time check [s]: the median spacing of
  /// the LiDAR topic's bag times (0.1 s when it has fewer than 2 messages),
  /// clamped to [1 ms, 1 s].
  double scan_period_s() const;
  /// Bag (receive) time of the first and last message of the whole bag, as
  /// ReadBagInfo reports them (0 for an empty bag).
  int64_t start_time_ns() const;
  int64_t end_time_ns() const;

 private:
  class Impl;
  explicit BagReader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace swarmlio::io
