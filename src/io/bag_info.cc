#include "swarmlio/io/bag_info.h"

#include <rosbag/bag.h>
#include <rosbag/query.h>
#include <rosbag/view.h>

#include <filesystem>
#include <map>
#include <system_error>

#include "src/io/bag_common.h"
#include "src/io/ros_time.h"
#include "swarmlio/common/check.h"

namespace swarmlio::io {

Status ReadBagInfo(const std::string& path, BagInfo* info) {
  CHECK(info != nullptr);
  *info = BagInfo();
  info->path = path;
  rosbag::Bag bag;
  SWARMLIO_RETURN_IF_ERROR(internal::OpenBagForReading(path, /*verify_chunks=*/false, &bag));
  std::error_code ec;
  info->file_size_bytes = std::filesystem::file_size(path, ec);
  if (ec) info->file_size_bytes = 0;
  try {
    rosbag::View all(bag);
    info->message_count = all.size();
    if (info->message_count > 0) {
      info->start_time_ns = internal::StampNsFromRosTime(all.getBeginTime());
      info->end_time_ns = internal::StampNsFromRosTime(all.getEndTime());
    }
    std::map<std::string, BagTopicInfo> topics;
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      if (topics.count(c->topic) > 0) continue;
      BagTopicInfo& topic = topics[c->topic];
      topic.topic = c->topic;
      topic.datatype = c->datatype;
      topic.md5sum = c->md5sum;
      rosbag::View view(bag, rosbag::TopicQuery(c->topic));
      topic.message_count = view.size();
      if (topic.message_count > 0) {
        topic.first_time_ns = internal::StampNsFromRosTime(view.getBeginTime());
        topic.last_time_ns = internal::StampNsFromRosTime(view.getEndTime());
      }
    }
    for (auto& entry : topics) info->topics.push_back(std::move(entry.second));
  } catch (const std::exception& e) {
    return internal::StatusFromException(path, "reading the index", e);
  } catch (...) {
    return internal::UnknownExceptionStatus(path, "reading the index");
  }
  return Status::Ok();
}

}  // namespace swarmlio::io
