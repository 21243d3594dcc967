#include "src/io/mcap_source.h"

#include <algorithm>
#include <fstream>
#include <map>
#include <utility>
#include <vector>

#include "src/io/mcap_format.h"
#include "src/io/mcap_scan.h"

namespace swarmlio::io::internal {
namespace {

class McapTopicStream : public TopicMessageStream {
 public:
  McapTopicStream(const McapFile* file, std::vector<size_t> messages)
      : file_(file), messages_(std::move(messages)), reader_(file) {}

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
    for (size_t i = 0; i < file_.messages.size(); ++i) {
      const McapMessage& m = file_.messages[i];
      by_topic_[file_.channels[m.channel].topic].push_back(i);
      if (i == 0 || m.log_time_ns < start_time_ns_) start_time_ns_ = m.log_time_ns;
      if (i == 0 || m.log_time_ns > end_time_ns_) end_time_ns_ = m.log_time_ns;
    }
    for (auto& entry : by_topic_) {
      std::stable_sort(entry.second.begin(), entry.second.end(), [this](size_t a, size_t b) {
        return file_.messages[a].log_time_ns < file_.messages[b].log_time_ns;
      });
    }
    return Status::Ok();
  }

  const std::vector<SourceConnection>& connections() const override { return connections_; }
  int64_t message_count() const override { return static_cast<int64_t>(file_.messages.size()); }
  int64_t start_time_ns() const override { return start_time_ns_; }
  int64_t end_time_ns() const override { return end_time_ns_; }
  const BagRecoveryStats& recovery() const override { return file_.damage; }

  Status Summarize(const std::string& topic, TopicSummary* summary) override {
    *summary = TopicSummary();
    const std::vector<size_t>& messages = Messages(topic);
    summary->message_count = static_cast<int64_t>(messages.size());
    if (!messages.empty()) {
      summary->first_time_ns = file_.messages[messages.front()].log_time_ns;
      summary->last_time_ns = file_.messages[messages.back()].log_time_ns;
    }
    return Status::Ok();
  }

  Status TopicTimes(const std::string& topic,
                    size_t max_count,
                    std::vector<int64_t>* times) override {
    times->clear();
    for (size_t i : Messages(topic)) {
      if (times->size() >= max_count) break;
      times->push_back(file_.messages[i].log_time_ns);
    }
    return Status::Ok();
  }

  Status OpenTopic(const std::string& topic, std::unique_ptr<TopicMessageStream>* stream) override {
    *stream = std::make_unique<McapTopicStream>(&file_, Messages(topic));
    return Status::Ok();
  }

 private:
  const std::vector<size_t>& Messages(const std::string& topic) const {
    static const std::vector<size_t>* const kNone = new std::vector<size_t>();
    const auto it = by_topic_.find(topic);
    return it == by_topic_.end() ? *kNone : it->second;
  }

  McapFile file_;
  std::vector<SourceConnection> connections_;
  std::map<std::string, std::vector<size_t>> by_topic_;
  int64_t start_time_ns_ = 0;
  int64_t end_time_ns_ = 0;
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
