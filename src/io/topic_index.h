// The messages of an in-memory log (a salvaged ROS1 bag, an MCAP file) by
// topic, each topic's in time order (equal times in file order, as rosbag
// orders them), with the log's first and last time. Internal to src/io.
#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "src/io/bag_source.h"

namespace swarmlio::io::internal {

class TopicIndex {
 public:
  /// Message i is on topic `topic_of(i)` at `time_ns(i)`, for i < count.
  template <class TopicOf, class TimeOf>
  void Build(size_t count, TopicOf topic_of, TimeOf time_ns) {
    by_topic_.clear();
    for (size_t i = 0; i < count; ++i) {
      by_topic_[topic_of(i)].push_back(i);
      const int64_t t = time_ns(i);
      if (i == 0 || t < start_time_ns_) start_time_ns_ = t;
      if (i == 0 || t > end_time_ns_) end_time_ns_ = t;
    }
    for (auto& entry : by_topic_) {
      std::stable_sort(entry.second.begin(), entry.second.end(),
                       [&](size_t a, size_t b) { return time_ns(a) < time_ns(b); });
    }
  }

  /// The indices of `topic`'s messages in time order (empty when unknown).
  const std::vector<size_t>& Messages(const std::string& topic) const {
    static const std::vector<size_t>* const kNone = new std::vector<size_t>();
    const auto it = by_topic_.find(topic);
    return it == by_topic_.end() ? *kNone : it->second;
  }

  /// `time_ns(i)` as in Build.
  template <class TimeOf>
  void Summarize(const std::string& topic, TimeOf time_ns, TopicSummary* summary) const {
    *summary = TopicSummary();
    const std::vector<size_t>& messages = Messages(topic);
    summary->message_count = static_cast<int64_t>(messages.size());
    if (!messages.empty()) {
      summary->first_time_ns = time_ns(messages.front());
      summary->last_time_ns = time_ns(messages.back());
    }
  }

  template <class TimeOf>
  void TopicTimes(const std::string& topic,
                  size_t max_count,
                  TimeOf time_ns,
                  std::vector<int64_t>* times) const {
    times->clear();
    for (size_t i : Messages(topic)) {
      if (times->size() >= max_count) break;
      times->push_back(time_ns(i));
    }
  }

  int64_t start_time_ns() const { return start_time_ns_; }
  int64_t end_time_ns() const { return end_time_ns_; }

 private:
  std::map<std::string, std::vector<size_t>> by_topic_;
  int64_t start_time_ns_ = 0;
  int64_t end_time_ns_ = 0;
};

}  // namespace swarmlio::io::internal
