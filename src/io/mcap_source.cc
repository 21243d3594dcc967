#include "src/io/mcap_source.h"

#include <algorithm>
#include <fstream>
#include <map>
#include <utility>
#include <vector>

#include "src/io/mcap_format.h"
#include "src/io/mcap_scan.h"
#include "src/io/topic_index.h"

namespace swarmlio::io::internal {
namespace {

class McapTopicStream : public TopicMessageStream {
 public:
  McapTopicStream(const McapFile* file, McapChunkCache* cache, std::vector<size_t> messages)
      : file_(file), messages_(std::move(messages)), reader_(file, cache) {}

  Status Next(uint64_t max_bytes, SourceMessage* message, bool* has_message) override {
    *has_message = false;
    if (next_ >= messages_.size()) return Status::Ok();
    const McapMessage& m = file_->messages[messages_[next_++]];
    message->datatype = file_->channels[m.channel].schema_name;
    message->bag_time_ns = m.log_time_ns;
    message->size = static_cast<size_t>(m.size);
    message->data = nullptr;
    message->too_large = m.size > max_bytes;
    *has_message = true;
    if (message->too_large) return Status::Ok();
    return reader_.Read(m, &message->data);
  }

 private:
  const McapFile* file_;
  std::vector<size_t> messages_;  // indices into file_->messages, log-time order
  size_t next_ = 0;
  McapMessageReader reader_;
};

class McapSource : public BagSource {
 private:
  // Message i's time (defined first: the members below deduce from it).
  auto TimeOf() const {
    return [this](size_t i) { return file_.messages[i].log_time_ns; };
  }

 public:
  Status Load(const std::string& path, bool recover) {
    SWARMLIO_RETURN_IF_ERROR(ScanMcapFile(path, recover, &file_));
    for (const McapChannel& c : file_.channels) {
      SourceConnection connection;
      connection.topic = c.topic;
      connection.datatype = c.schema_name;
      connection.encoding = c.message_encoding;
      const auto md5 = c.metadata.find("md5sum");
      if (md5 != c.metadata.end()) connection.md5sum = md5->second;
      connections_.push_back(std::move(connection));
    }
    index_.Build(
        file_.messages.size(),
        [this](size_t i) -> const std::string& {
          return file_.channels[file_.messages[i].channel].topic;
        },
        TimeOf());
    return Status::Ok();
  }

  const std::vector<SourceConnection>& connections() const override { return connections_; }
  int64_t message_count() const override { return static_cast<int64_t>(file_.messages.size()); }
  int64_t start_time_ns() const override { return index_.start_time_ns(); }
  int64_t end_time_ns() const override { return index_.end_time_ns(); }
  const BagRecoveryStats& recovery() const override { return file_.damage; }

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
    *stream = std::make_unique<McapTopicStream>(&file_, &cache_, index_.Messages(topic));
    return Status::Ok();
  }

 private:
  McapFile file_;
  McapChunkCache cache_{&file_};  // shared by the topic streams
  std::vector<SourceConnection> connections_;
  internal::TopicIndex index_;
};

}  // namespace

Status OpenMcapSource(const std::string& path,
                      const BagSourceOptions& options,
                      std::unique_ptr<BagSource>* source) {
  auto mcap = std::make_unique<McapSource>();
  SWARMLIO_RETURN_IF_ERROR(mcap->Load(path, options.recover));
  *source = std::move(mcap);
  return Status::Ok();
}

bool HasMcapMagic(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  uint8_t magic[kMcapMagicBytes] = {};
  if (!file.read(reinterpret_cast<char*>(magic), sizeof(magic))) return false;
  return IsMcapMagic(magic);
}

}  // namespace swarmlio::io::internal
