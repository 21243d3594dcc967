// A small rosbag2 SQLite writer (the `sqlite3` storage of ROS 2 Humble): a
// `.db3` file with the tables `schema`, `topics` (name, type such as
// "sensor_msgs/msg/Imu", serialization format "cdr", QoS as an empty string)
// and `messages` (topic id, receive time [ns], CDR bytes), inside one
// transaction committed at Close. Read back by db3_source.h; the format:
// docs/bag_format.md "ROS 2 logs".
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"

struct sqlite3;
struct sqlite3_stmt;

namespace swarmlio::io::internal {

class Db3Writer {
 public:
  Db3Writer();
  ~Db3Writer();
  Db3Writer(const Db3Writer&) = delete;
  Db3Writer& operator=(const Db3Writer&) = delete;

  /// Creates `path` (an existing file is replaced) with the tables.
  Status Open(const std::string& path);
  /// Adds a topic of ROS 2 `type`; *id is its row id.
  Status AddTopic(const std::string& name, const std::string& type, int64_t* id);
  Status WriteMessage(int64_t topic_id, int64_t timestamp_ns, const std::vector<uint8_t>& data);
  /// Commits and closes; the file is complete only after this.
  Status Close();

 private:
  Status Execute(const std::string& sql);
  Status Error(const std::string& what) const;

  std::string path_;
  sqlite3* db_ = nullptr;
  sqlite3_stmt* insert_message_ = nullptr;
};

}  // namespace swarmlio::io::internal
