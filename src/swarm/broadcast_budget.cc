// swarm::BroadcastBudget and swarm::SendRotation (broadcast_budget.h).
#include "swarmlio/common/time.h"
#include "swarmlio/swarm/broadcast_budget.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

namespace swarmlio::swarm {

BroadcastBudget::BroadcastBudget(const BroadcastBudgetOptions& options) : options_(options) {}

void BroadcastBudget::Refill(int64_t stamp_ns) {
  if (!limited()) return;
  const double capacity = options_.max_bytes_per_s * options_.burst_s;
  if (!refilled_) {
    credit_ = capacity;
  } else if (stamp_ns > last_stamp_ns_) {
    credit_ += options_.max_bytes_per_s * SecondsBetween(last_stamp_ns_, stamp_ns);
    credit_ = std::min(credit_, capacity);
  }
  if (!refilled_ || stamp_ns > last_stamp_ns_) last_stamp_ns_ = stamp_ns;
  refilled_ = true;
}

size_t BroadcastBudget::WireBytes(size_t packet_bytes) const {
  return packet_bytes + static_cast<size_t>(options_.ip_udp_header_bytes);
}

void BroadcastBudget::Spend(size_t bytes) {
  if (limited()) credit_ -= static_cast<double>(bytes);
}

bool BroadcastBudget::TrySpend(size_t bytes) {
  if (!limited()) return true;
  if (credit_ < static_cast<double>(bytes)) return false;
  credit_ -= static_cast<double>(bytes);
  return true;
}

int BroadcastBudget::Affordable(size_t first_bytes, size_t item_bytes, int max_items) const {
  if (max_items <= 0) return 0;
  if (!limited()) return max_items;
  const double left = credit_ - static_cast<double>(first_bytes);
  if (left < static_cast<double>(item_bytes)) return 0;
  const double n = item_bytes == 0 ? static_cast<double>(max_items)
                                   : std::floor(left / static_cast<double>(item_bytes));
  return static_cast<int>(std::min(n, static_cast<double>(max_items)));
}

std::vector<int> SendRotation::Order(std::vector<int> ids) const {
  const auto key = [this](int id) {
    const auto it = last_sent_.find(id);
    return std::make_tuple(it == last_sent_.end() ? uint64_t{0} : it->second, id);
  };
  std::stable_sort(ids.begin(), ids.end(), [&](int a, int b) { return key(a) < key(b); });
  return ids;
}

}  // namespace swarmlio::swarm
