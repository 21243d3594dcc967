#include "swarmlio/io/bag_info.h"

#include <filesystem>
#include <map>
#include <memory>
#include <system_error>

#include "src/io/bag_source.h"
#include "src/io/db3_source.h"
#include "src/io/mcap_source.h"
#include "swarmlio/common/check.h"

namespace swarmlio::io {
namespace {

std::string Format(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return "rosbag2";
  if (internal::HasMcapMagic(path)) return "mcap";
  if (internal::HasSqliteMagic(path)) return "db3";
  return "ros1";
}

// The file's size, or the sum of a folder's files.
uint64_t SizeBytes(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_directory(path, ec)) {
    const uint64_t size = std::filesystem::file_size(path, ec);
    return ec ? 0 : size;
  }
  uint64_t total = 0;
  for (const auto& entry : std::filesystem::directory_iterator(path, ec)) {
    std::error_code file_ec;
    const uint64_t size = entry.is_regular_file(file_ec) ? entry.file_size(file_ec) : 0;
    if (!file_ec) total += size;
  }
  return total;
}

}  // namespace

Status ReadBagInfo(const std::string& path, BagInfo* info, bool recover_damaged_bags) {
  CHECK(info != nullptr);
  *info = BagInfo();
  info->path = path;
  info->format = Format(path);
  internal::BagSourceOptions options;
  options.verify_chunks = false;
  options.recover = recover_damaged_bags;
  std::unique_ptr<internal::BagSource> source;
  SWARMLIO_RETURN_IF_ERROR(internal::BagSource::Open(path, options, &source));
  info->file_size_bytes = SizeBytes(path);
  info->message_count = source->message_count();
  info->start_time_ns = source->start_time_ns();
  info->end_time_ns = source->end_time_ns();
  info->recovery = source->recovery();
  std::map<std::string, BagTopicInfo> topics;
  for (const internal::SourceConnection& c : source->connections()) {
    if (topics.count(c.topic) > 0) continue;
    BagTopicInfo& topic = topics[c.topic];
    topic.topic = c.topic;
    topic.datatype = c.datatype;
    topic.md5sum = c.md5sum;
    topic.encoding = c.encoding;
    internal::TopicSummary summary;
    SWARMLIO_RETURN_IF_ERROR(source->Summarize(c.topic, &summary));
    topic.message_count = summary.message_count;
    topic.first_time_ns = summary.first_time_ns;
    topic.last_time_ns = summary.last_time_ns;
  }
  for (auto& entry : topics) info->topics.push_back(std::move(entry.second));
  return Status::Ok();
}

}  // namespace swarmlio::io
