#include "src/io/rosbag2_folder.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <exception>
#include <filesystem>
#include <set>
#include <utility>
#include <vector>

namespace swarmlio::io::internal {
namespace {

namespace fs = std::filesystem;

// A metadata.yaml path in the folder; ROS 2 Foxy wrote them prefixed with the
// folder's own name, so an absent path is also tried by its file name alone.
std::string StoragePath(const std::string& folder, const std::string& relative) {
  const fs::path path = fs::path(folder) / relative;
  std::error_code ec;
  if (fs::exists(path, ec)) return path.string();
  const fs::path by_name = fs::path(folder) / fs::path(relative).filename();
  return fs::exists(by_name, ec) ? by_name.string() : path.string();
}

// The storage files of the folder, in recording order.
Status StorageFiles(const std::string& folder, std::vector<std::string>* files) {
  files->clear();
  const fs::path metadata = fs::path(folder) / "metadata.yaml";
  std::error_code ec;
  if (fs::exists(metadata, ec)) {
    try {
      const YAML::Node paths =
          YAML::LoadFile(metadata.string())["rosbag2_bagfile_information"]["relative_file_paths"];
      if (!paths || !paths.IsSequence()) {
        return Status::DataLoss("bag '" + folder +
                                "': metadata.yaml has no "
                                "rosbag2_bagfile_information.relative_file_paths list");
      }
      for (const YAML::Node& p : paths) files->push_back(StoragePath(folder, p.as<std::string>()));
    } catch (const std::exception& e) {
      return Status::DataLoss("bag '" + folder + "': metadata.yaml: " + e.what());
    }
  } else {
    for (const fs::directory_entry& entry : fs::directory_iterator(folder, ec)) {
      const std::string extension = entry.path().extension().string();
      if (extension == ".db3" || extension == ".mcap") files->push_back(entry.path().string());
    }
    std::sort(files->begin(), files->end());
  }
  if (files->empty()) {
    return Status::NotFound("bag '" + folder +
                            "': a folder without metadata.yaml, .db3 or .mcap files");
  }
  return Status::Ok();
}

// One topic's messages, file after file.
class ChainedTopicStream : public TopicMessageStream {
 public:
  explicit ChainedTopicStream(std::vector<std::unique_ptr<TopicMessageStream>> parts)
      : parts_(std::move(parts)) {}

  Status Next(uint64_t max_bytes, SourceMessage* message, bool* has_message) override {
    *has_message = false;
    while (next_ < parts_.size()) {
      SWARMLIO_RETURN_IF_ERROR(parts_[next_]->Next(max_bytes, message, has_message));
      if (*has_message) return Status::Ok();
      ++next_;
    }
    return Status::Ok();
  }

 private:
  std::vector<std::unique_ptr<TopicMessageStream>> parts_;
  size_t next_ = 0;
};

class ChainedSource : public BagSource {
 public:
  explicit ChainedSource(std::vector<std::unique_ptr<BagSource>> parts) : parts_(std::move(parts)) {
    std::set<std::pair<std::string, std::string>> seen;  // topic, datatype
    for (size_t i = 0; i < parts_.size(); ++i) {
      const BagSource& part = *parts_[i];
      for (const SourceConnection& c : part.connections()) {
        if (seen.insert({c.topic, c.datatype}).second) connections_.push_back(c);
      }
      if (part.message_count() == 0) continue;
      if (message_count_ == 0 || part.start_time_ns() < start_time_ns_) {
        start_time_ns_ = part.start_time_ns();
      }
      if (message_count_ == 0 || part.end_time_ns() > end_time_ns_)
        end_time_ns_ = part.end_time_ns();
      message_count_ += part.message_count();
      if (part.recovery().recovered && !recovery_.recovered) recovery_ = part.recovery();
    }
  }

  const std::vector<SourceConnection>& connections() const override { return connections_; }
  int64_t message_count() const override { return message_count_; }
  int64_t start_time_ns() const override { return start_time_ns_; }
  int64_t end_time_ns() const override { return end_time_ns_; }
  const BagRecoveryStats& recovery() const override { return recovery_; }

  Status Summarize(const std::string& topic, TopicSummary* summary) override {
    *summary = TopicSummary();
    for (const std::unique_ptr<BagSource>& part : parts_) {
      TopicSummary s;
      SWARMLIO_RETURN_IF_ERROR(part->Summarize(topic, &s));
      if (s.message_count == 0) continue;
      if (summary->message_count == 0) summary->first_time_ns = s.first_time_ns;
      summary->first_time_ns = std::min(summary->first_time_ns, s.first_time_ns);
      summary->last_time_ns = std::max(summary->last_time_ns, s.last_time_ns);
      summary->message_count += s.message_count;
    }
    return Status::Ok();
  }

  Status TopicTimes(const std::string& topic,
                    size_t max_count,
                    std::vector<int64_t>* times) override {
    times->clear();
    for (const std::unique_ptr<BagSource>& part : parts_) {
      std::vector<int64_t> part_times;
      SWARMLIO_RETURN_IF_ERROR(part->TopicTimes(topic, max_count - times->size(), &part_times));
      times->insert(times->end(), part_times.begin(), part_times.end());
      if (times->size() >= max_count) break;
    }
    return Status::Ok();
  }

  Status OpenTopic(const std::string& topic, std::unique_ptr<TopicMessageStream>* stream) override {
    std::vector<std::unique_ptr<TopicMessageStream>> streams;
    for (const std::unique_ptr<BagSource>& part : parts_) {
      streams.emplace_back();
      SWARMLIO_RETURN_IF_ERROR(part->OpenTopic(topic, &streams.back()));
    }
    *stream = std::make_unique<ChainedTopicStream>(std::move(streams));
    return Status::Ok();
  }

 private:
  std::vector<std::unique_ptr<BagSource>> parts_;
  std::vector<SourceConnection> connections_;
  int64_t message_count_ = 0;
  int64_t start_time_ns_ = 0;
  int64_t end_time_ns_ = 0;
  BagRecoveryStats recovery_;
};

}  // namespace

Status OpenRosbag2Folder(const std::string& path,
                         const BagSourceOptions& options,
                         std::unique_ptr<BagSource>* source) {
  std::vector<std::string> files;
  SWARMLIO_RETURN_IF_ERROR(StorageFiles(path, &files));
  std::vector<std::unique_ptr<BagSource>> parts;
  for (const std::string& file : files) {
    std::error_code ec;
    if (fs::is_directory(file, ec)) {
      return Status::DataLoss("bag '" + path + "': storage file '" + file + "' is a folder");
    }
    parts.emplace_back();
    SWARMLIO_RETURN_IF_ERROR(BagSource::Open(file, options, &parts.back()));
  }
  if (parts.size() == 1) {
    *source = std::move(parts.front());
  } else {
    *source = std::make_unique<ChainedSource>(std::move(parts));
  }
  return Status::Ok();
}

}  // namespace swarmlio::io::internal
