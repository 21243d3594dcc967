#include "swarmlio/net/messages.h"

#include <algorithm>
#include <type_traits>

namespace swarmlio::net {

const char* MessageTypeName(MessageType type) {
  switch (type) {
    case MessageType::kEgoState:
      return "EgoState";
    case MessageType::kGlobalExtrinsic:
      return "GlobalExtrinsic";
    case MessageType::kTimeSync:
      return "TimeSync";
    case MessageType::kAirframe:
      return "Airframe";
  }
  return "unknown";
}

MessageType TypeOf(const SwarmMessage& message) {
  return std::visit(
      [](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, EgoStateMessage>) {
          return MessageType::kEgoState;
        } else if constexpr (std::is_same_v<T, GlobalExtrinsicMessage>) {
          return MessageType::kGlobalExtrinsic;
        } else if constexpr (std::is_same_v<T, TimeSyncMessage>) {
          return MessageType::kTimeSync;
        } else {
          static_assert(std::is_same_v<T, AirframeMessage>, "a message type without a MessageType");
          return MessageType::kAirframe;
        }
      },
      message);
}

int SenderOf(const SwarmMessage& message) {
  return std::visit([](const auto& m) { return m.sender_id; }, message);
}

std::vector<GlobalExtrinsicMessage> SplitGlobalExtrinsics(
    int sender_id,
    int64_t stamp_ns,
    const std::vector<GlobalExtrinsicEntry>& entries,
    const Eigen::Vector3d& g_in_Gi,
    const Eigen::Matrix3d& cov_g_in_Gi) {
  std::vector<GlobalExtrinsicMessage> messages;
  size_t begin = 0;
  do {
    const size_t end =
        std::min(entries.size(), begin + static_cast<size_t>(GlobalExtrinsicMessage::kMaxEntries));
    GlobalExtrinsicMessage m;
    m.sender_id = sender_id;
    m.stamp_ns = stamp_ns;
    m.g_in_Gi = g_in_Gi;
    m.cov_g_in_Gi = cov_g_in_Gi;
    m.entries.assign(entries.begin() + static_cast<std::ptrdiff_t>(begin),
                     entries.begin() + static_cast<std::ptrdiff_t>(end));
    messages.push_back(std::move(m));
    begin = end;
  } while (begin < entries.size());
  return messages;
}

}  // namespace swarmlio::net
