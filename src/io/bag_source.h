// Where the bag reader and ReadBagInfo get messages from: rosbag's index for
// a healthy ROS1 bag, a scan of the records (bag_recovery.h) for a truncated
// or unindexed one, a scan of an MCAP file (mcap_source.h), a rosbag2 SQLite3
// file (db3_source.h) -- each told by its magic bytes, not its extension --
// or a rosbag2 folder of such files (rosbag2_folder.h). Both give the connections, the time range,
// and per topic the messages in bag-time order, as raw bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/io/read_stats.h"

namespace swarmlio::io::internal {

struct SourceConnection {
  std::string topic;
  std::string datatype;           // ROS1 ("sensor_msgs/Imu") or ROS 2 ("sensor_msgs/msg/Imu") name
  std::string md5sum;             // ROS1 only
  std::string encoding = "ros1";  // message encoding: "ros1", or an MCAP channel's ("cdr")
};

/// One stored message. `data` stays valid until the stream's next call.
struct SourceMessage {
  const uint8_t* data = nullptr;
  size_t size = 0;
  bool too_large = false;  // size > max_bytes: data not read
  std::string datatype;
  int64_t bag_time_ns = 0;
};

/// The messages of one topic in bag-time order (ties: file order).
class TopicMessageStream {
 public:
  virtual ~TopicMessageStream() = default;
  /// Reads the next message; *has_message = false at the end. Messages
  /// larger than `max_bytes` are returned with too_large set, unread.
  virtual Status Next(uint64_t max_bytes, SourceMessage* message, bool* has_message) = 0;
};

/// Count and bag-time range of one topic's messages.
struct TopicSummary {
  int64_t message_count = 0;
  int64_t first_time_ns = 0;
  int64_t last_time_ns = 0;
};

struct BagSourceOptions {
  bool verify_chunks = true;  // pre-check every chunk's records (healthy bags)
  bool recover = true;        // scan a truncated / unindexed bag instead of failing
};

class BagSource {
 public:
  /// Opens `path`: NotFound if there is no such file, DataLoss or IoError
  /// with the path and the reason if it cannot be read.
  static Status Open(const std::string& path,
                     const BagSourceOptions& options,
                     std::unique_ptr<BagSource>* source);

  virtual ~BagSource() = default;

  /// One entry per connection (a topic may have several).
  virtual const std::vector<SourceConnection>& connections() const = 0;
  virtual int64_t message_count() const = 0;
  /// Bag time of the first and last message (0 for an empty bag).
  virtual int64_t start_time_ns() const = 0;
  virtual int64_t end_time_ns() const = 0;
  virtual Status Summarize(const std::string& topic, TopicSummary* summary) = 0;
  /// Bag times of the first `max_count` messages of `topic`, in order.
  virtual Status TopicTimes(const std::string& topic,
                            size_t max_count,
                            std::vector<int64_t>* times) = 0;
  /// A stream over `topic`; it must not outlive this source.
  virtual Status OpenTopic(const std::string& topic,
                           std::unique_ptr<TopicMessageStream>* stream) = 0;
  /// What recovery found (recovered = false for a healthy bag).
  virtual const BagRecoveryStats& recovery() const = 0;
};

/// "topic [datatype], ..." of the given connections, sorted, each topic once.
std::string DescribeTopics(const std::vector<SourceConnection>& connections);

}  // namespace swarmlio::io::internal
