#include "src/io/bag_source.h"


#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/query.h>
#include <rosbag/view.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <utility>

#include "src/io/bag_common.h"
#include "src/io/bag_precheck.h"
#include "src/io/bag_recovery.h"
#include "src/io/db3_source.h"
#include "src/io/topic_index.h"
#include "src/io/mcap_source.h"
#include "src/io/ros_time.h"
#include "src/io/rosbag2_folder.h"
#include "swarmlio/common/check.h"

namespace swarmlio::io::internal {
namespace {

// ---------------------------------------------------------------------------
// A healthy bag, read through rosbag's index.

class RosbagTopicStream : public TopicMessageStream {
 public:
  RosbagTopicStream(const std::string& path, rosbag::Bag* bag, const std::string& topic)
      : path_(path),
        view_(*bag, rosbag::TopicQuery(topic)),
        it_(view_.begin()),
        end_(view_.end()) {}

  Status Next(uint64_t max_bytes, SourceMessage* message, bool* has_message) override {
    *has_message = false;
    try {
      if (started_ && it_ != end_) ++it_;
      started_ = true;
      if (it_ == end_) return Status::Ok();
      const rosbag::MessageInstance& instance = *it_;
      message->datatype = instance.getDataType();
      message->bag_time_ns = StampNsFromRosTime(instance.getTime());
      message->size = instance.size();
      message->data = nullptr;
      message->too_large = message->size > max_bytes;
      *has_message = true;
      if (message->too_large) return Status::Ok();
      buffer_.resize(message->size);
      ros::serialization::OStream out(buffer_.data(), static_cast<uint32_t>(message->size));
      instance.write(out);
      message->data = buffer_.data();
    } catch (const std::exception& e) {
      return StatusFromException(path_, "reading a message", e);
    } catch (...) {
      return UnknownExceptionStatus(path_, "reading a message");
    }
    return Status::Ok();
  }

 private:
  std::string path_;
  rosbag::View view_;
  rosbag::View::iterator it_;
  rosbag::View::iterator end_;
  bool started_ = false;
  std::vector<uint8_t> buffer_;
};

class RosbagSource : public BagSource {
 public:
  explicit RosbagSource(std::string path) : path_(std::move(path)) {}

  rosbag::Bag* bag() { return &bag_; }

  Status Load() {
    try {
      rosbag::View all(bag_);
      message_count_ = static_cast<int64_t>(all.size());
      if (message_count_ > 0) {
        start_time_ns_ = StampNsFromRosTime(all.getBeginTime());
        end_time_ns_ = StampNsFromRosTime(all.getEndTime());
      }
      for (const rosbag::ConnectionInfo* c : all.getConnections()) {
        connections_.push_back({c->topic, c->datatype, c->md5sum});
      }
    } catch (const std::exception& e) {
      return StatusFromException(path_, "reading the index", e);
    } catch (...) {
      return UnknownExceptionStatus(path_, "reading the index");
    }
    return Status::Ok();
  }

  const std::vector<SourceConnection>& connections() const override { return connections_; }
  int64_t message_count() const override { return message_count_; }
  int64_t start_time_ns() const override { return start_time_ns_; }
  int64_t end_time_ns() const override { return end_time_ns_; }
  const BagRecoveryStats& recovery() const override { return recovery_; }

  Status Summarize(const std::string& topic, TopicSummary* summary) override {
    *summary = TopicSummary();
    try {
      rosbag::View view(bag_, rosbag::TopicQuery(topic));
      summary->message_count = static_cast<int64_t>(view.size());
      if (summary->message_count > 0) {
        summary->first_time_ns = StampNsFromRosTime(view.getBeginTime());
        summary->last_time_ns = StampNsFromRosTime(view.getEndTime());
      }
    } catch (const std::exception& e) {
      return StatusFromException(path_, "reading the index", e);
    } catch (...) {
      return UnknownExceptionStatus(path_, "reading the index");
    }
    return Status::Ok();
  }

  Status TopicTimes(const std::string& topic,
                    size_t max_count,
                    std::vector<int64_t>* times) override {
    times->clear();
    try {
      rosbag::View view(bag_, rosbag::TopicQuery(topic));
      for (const rosbag::MessageInstance& m : view) {  // index only, no data read
        if (times->size() >= max_count) break;
        times->push_back(StampNsFromRosTime(m.getTime()));
      }
    } catch (const std::exception& e) {
      return StatusFromException(path_, "reading the index", e);
    } catch (...) {
      return UnknownExceptionStatus(path_, "reading the index");
    }
    return Status::Ok();
  }

  Status OpenTopic(const std::string& topic, std::unique_ptr<TopicMessageStream>* stream) override {
    try {
      *stream = std::make_unique<RosbagTopicStream>(path_, &bag_, topic);
    } catch (const std::exception& e) {
      return StatusFromException(path_, "reading the index", e);
    } catch (...) {
      return UnknownExceptionStatus(path_, "reading the index");
    }
    return Status::Ok();
  }

 private:
  std::string path_;
  rosbag::Bag bag_;
  std::vector<SourceConnection> connections_;
  int64_t message_count_ = 0;
  int64_t start_time_ns_ = 0;
  int64_t end_time_ns_ = 0;
  BagRecoveryStats recovery_;
};

// ---------------------------------------------------------------------------
// A damaged bag, read from a scan of its records.

class RecoveredTopicStream : public TopicMessageStream {
 public:
  RecoveredTopicStream(const RecoveredBag* bag, std::vector<size_t> messages)
      : bag_(bag), messages_(std::move(messages)), reader_(bag) {}

  Status Next(uint64_t max_bytes, SourceMessage* message, bool* has_message) override {
    *has_message = false;
    if (next_ >= messages_.size()) return Status::Ok();
    const RecoveredMessage& m = bag_->messages[messages_[next_++]];
    message->datatype = bag_->connections[m.connection].datatype;
    message->bag_time_ns = m.time_ns;
    message->size = m.size;
    message->data = nullptr;
    message->too_large = m.size > max_bytes;
    *has_message = true;
    if (message->too_large) return Status::Ok();
    SWARMLIO_RETURN_IF_ERROR(reader_.Read(m, &buffer_));
    message->data = buffer_.data();
    return Status::Ok();
  }

 private:
  const RecoveredBag* bag_;
  std::vector<size_t> messages_;  // indices into bag_->messages, bag-time order
  size_t next_ = 0;
  RecoveredMessageReader reader_;
  std::vector<uint8_t> buffer_;
};

class RecoveredSource : public BagSource {
 private:
  // Message i's time (defined first: the members below deduce from it).
  auto TimeOf() const {
    return [this](size_t i) { return bag_.messages[i].time_ns; };
  }

 public:
  Status Load(const std::string& path, const std::string& reason) {
    SWARMLIO_RETURN_IF_ERROR(ScanBagRecords(path, reason, &bag_));
    for (const RecoveredConnection& c : bag_.connections) {
      connections_.push_back({c.topic, c.datatype, c.md5sum});
    }
    // rosbag's order: bag time, equal times in file order.
    index_.Build(
        bag_.messages.size(),
        [this](size_t i) -> const std::string& {
          return bag_.connections[bag_.messages[i].connection].topic;
        },
        TimeOf());
    return Status::Ok();
  }

  const std::vector<SourceConnection>& connections() const override { return connections_; }
  int64_t message_count() const override { return static_cast<int64_t>(bag_.messages.size()); }
  int64_t start_time_ns() const override { return index_.start_time_ns(); }
  int64_t end_time_ns() const override { return index_.end_time_ns(); }
  const BagRecoveryStats& recovery() const override { return bag_.stats; }

  Status Summarize(const std::string& topic, TopicSummary* summary) override {
    index_.Summarize(topic, TimeOf(), summary);
    return Status::Ok();
  }

  Status TopicTimes(const std::string& topic,
                    size_t max_count,
                    std::vector<int64_t>* times) override {
    index_.TopicTimes(topic, max_count, TimeOf(), times);
    return Status::Ok();
  }

  Status OpenTopic(const std::string& topic, std::unique_ptr<TopicMessageStream>* stream) override {
    *stream = std::make_unique<RecoveredTopicStream>(&bag_, index_.Messages(topic));
    return Status::Ok();
  }

 private:
  RecoveredBag bag_;
  std::vector<SourceConnection> connections_;
  internal::TopicIndex index_;
};

}  // namespace

Status BagSource::Open(const std::string& path,
                       const BagSourceOptions& options,
                       std::unique_ptr<BagSource>* source) {
  CHECK(source != nullptr);
  source->reset();
  // The format is told by the magic bytes, whatever the extension; a folder
  // is a rosbag2 recording.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return OpenRosbag2Folder(path, options, source);
  if (HasMcapMagic(path)) return OpenMcapSource(path, options, source);
  if (HasSqliteMagic(path)) return OpenDb3Source(path, source);
  auto healthy = std::make_unique<RosbagSource>(path);
  BagPrecheckResult precheck;
  const Status opened = OpenBagForReading(path, options.verify_chunks, healthy->bag(), &precheck);
  if (opened.ok()) {
    SWARMLIO_RETURN_IF_ERROR(healthy->Load());
    *source = std::move(healthy);
    return Status::Ok();
  }
  if (!precheck.index_damaged) return opened;
  if (!options.recover) {
    return Status::DataLoss(opened.message() +
                            " (recover_damaged_bags is false; with true the complete messages "
                            "before the damage are read)");
  }
  // The prefix "bag 'path': " of the pre-check's message is dropped: the
  // recovery stats belong to that bag anyway.
  std::string reason = opened.message();
  const std::string prefix = "bag '" + path + "': ";
  if (reason.rfind(prefix, 0) == 0) reason = reason.substr(prefix.size());
  auto recovered = std::make_unique<RecoveredSource>();
  SWARMLIO_RETURN_IF_ERROR(recovered->Load(path, reason));
  *source = std::move(recovered);
  return Status::Ok();
}

std::string DescribeTopics(const std::vector<SourceConnection>& connections) {
  std::map<std::string, std::string> types;  // topic -> datatype
  for (const SourceConnection& c : connections) types.emplace(c.topic, c.datatype);
  if (types.empty()) return "(none)";
  std::string out;
  for (const auto& [topic, datatype] : types) {
    if (!out.empty()) out += ", ";
    out += topic + " [" + datatype + "]";
  }
  return out;
}

}  // namespace swarmlio::io::internal
