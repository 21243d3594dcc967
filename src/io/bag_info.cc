#include "swarmlio/io/bag_info.h"

#include <filesystem>
#include <map>
#include <memory>
#include <system_error>

#include "src/io/bag_source.h"
#include "src/io/mcap_source.h"
#include "swarmlio/common/check.h"

namespace swarmlio::io {

Status ReadBagInfo(const std::string& path, BagInfo* info, bool recover_damaged_bags) {
  CHECK(info != nullptr);
  *info = BagInfo();
  info->path = path;
  info->format = internal::HasMcapMagic(path) ? "mcap" : "ros1";
  internal::BagSourceOptions options;
  options.verify_chunks = false;
  options.recover = recover_damaged_bags;
  std::unique_ptr<internal::BagSource> source;
  SWARMLIO_RETURN_IF_ERROR(internal::BagSource::Open(path, options, &source));
  std::error_code ec;
  info->file_size_bytes = std::filesystem::file_size(path, ec);
  if (ec) info->file_size_bytes = 0;
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
