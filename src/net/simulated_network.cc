// SimulatedNetwork: per-link queues, loss, delay, reordering and duplication.
#include "swarmlio/net/simulated_network.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <string>

#include "src/net/random.h"

namespace swarmlio::net {
namespace {

constexpr int64_t kNoTime = std::numeric_limits<int64_t>::min();
// Redraws of a negative delay before it is clamped to 0 (truncated normal).
constexpr int kMaxDelayRedraws = 16;

int64_t SecondsToNs(double seconds) { return std::llround(seconds * 1e9); }

/// One copy of a packet on its way to a receiver.
struct InFlight {
  int64_t arrival_ns = 0;
  uint64_t order = 0;  // global creation order: ties and determinism
  int link = 0;
  uint64_t send_index = 0;  // position in the link's send sequence
  int64_t send_ns = 0;
  std::shared_ptr<const std::vector<uint8_t>> bytes;
};

struct ArrivesLater {
  bool operator()(const InFlight& a, const InFlight& b) const {
    return a.arrival_ns != b.arrival_ns ? a.arrival_ns > b.arrival_ns : a.order > b.order;
  }
};

uint64_t LinkSeed(int64_t seed, int from_id, int to_id) {
  uint64_t state = static_cast<uint64_t>(seed);
  uint64_t mixed = internal::SplitMix64(&state);
  state = mixed ^ (static_cast<uint64_t>(from_id) << 8 | static_cast<uint64_t>(to_id));
  return internal::SplitMix64(&state);
}

}  // namespace

LinkStats& LinkStats::operator+=(const LinkStats& o) {
  sent += o.sent;
  delivered += o.delivered;
  dropped_loss += o.dropped_loss;
  dropped_queue += o.dropped_queue;
  duplicated += o.duplicated;
  reordered += o.reordered;
  bytes_sent += o.bytes_sent;
  bytes_delivered += o.bytes_delivered;
  latency_sum_s += o.latency_sum_s;
  latency_max_s = std::max(latency_max_s, o.latency_max_s);
  return *this;
}

class SimulatedNetwork::Impl {
 public:
  struct Link {
    Link(const LinkOptions& o, uint64_t seed) : options(o), rng(seed) {}
    LinkOptions options;
    internal::DeterministicRandom rng;
    int64_t busy_until_ns = kNoTime;  // bandwidth queue
    uint64_t next_send_index = 0;
    int64_t max_delivered_index = -1;  // for the reordering count
    LinkStats stats;
  };

  std::vector<int> ids;  // ascending
  std::vector<int> index_of = std::vector<int>(kMaxSwarmSize, -1);
  std::vector<Link> links;  // from_index * n + to_index
  std::vector<std::priority_queue<InFlight, std::vector<InFlight>, ArrivesLater>> inboxes;
  std::vector<std::unique_ptr<EndpointImpl>> endpoints;
  uint64_t next_order = 0;

  int n() const { return static_cast<int>(ids.size()); }

  Status Send(int from, int64_t now_ns, int destination_id, const uint8_t* data, size_t size);
  Status Poll(int to, int64_t now_ns, std::vector<Datagram>* received);

 private:
  void SendOnLink(int from,
                  int to,
                  int64_t now_ns,
                  const std::shared_ptr<const std::vector<uint8_t>>& bytes);
  double SampleDelay(Link* link);
};

class SimulatedNetwork::EndpointImpl : public Transport {
 public:
  EndpointImpl(Impl* network, int index) : network_(network), index_(index) {}
  int self_id() const override { return network_->ids[index_]; }
  Status Send(int64_t now_ns, int destination_id, const uint8_t* data, size_t size) override {
    return network_->Send(index_, now_ns, destination_id, data, size);
  }
  Status Poll(int64_t now_ns, std::vector<Datagram>* received) override {
    return network_->Poll(index_, now_ns, received);
  }

 private:
  Impl* network_;
  int index_;
};

Status SimulatedNetwork::Create(const NetworkOptions& options,
                                const std::vector<int>& drone_ids,
                                std::unique_ptr<SimulatedNetwork>* network) {
  const std::string error = options.Validate();
  if (!error.empty()) return Status::InvalidArgument("network." + error);
  auto impl = std::make_unique<Impl>();
  impl->ids = drone_ids;
  std::sort(impl->ids.begin(), impl->ids.end());
  for (size_t i = 0; i < impl->ids.size(); ++i) {
    const int id = impl->ids[i];
    if (!IsValidDroneId(id)) {
      return Status::InvalidArgument("simulated network: drone id " + std::to_string(id) +
                                     " out of range 0.." + std::to_string(kMaxSwarmSize - 1));
    }
    if (impl->index_of[id] >= 0) {
      return Status::InvalidArgument("simulated network: drone id " + std::to_string(id) +
                                     " given twice");
    }
    impl->index_of[id] = static_cast<int>(i);
  }
  for (size_t k = 0; k < options.links.size(); ++k) {
    for (int id : {options.links[k].from_id, options.links[k].to_id}) {
      if (id >= 0 && impl->index_of[id] < 0) {
        return Status::InvalidArgument("network.links[" + std::to_string(k) + "]: drone " +
                                       std::to_string(id) + " is not in the swarm");
      }
    }
  }
  const int n = impl->n();
  impl->links.reserve(static_cast<size_t>(n) * n);
  for (int from = 0; from < n; ++from) {
    for (int to = 0; to < n; ++to) {
      const int from_id = impl->ids[from];
      const int to_id = impl->ids[to];
      impl->links.emplace_back(options.ForLink(from_id, to_id),
                               LinkSeed(options.seed, from_id, to_id));
    }
  }
  impl->inboxes.resize(n);
  for (int i = 0; i < n; ++i) {
    impl->endpoints.push_back(std::make_unique<EndpointImpl>(impl.get(), i));
  }
  network->reset(new SimulatedNetwork(std::move(impl)));
  return Status::Ok();
}

SimulatedNetwork::SimulatedNetwork(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SimulatedNetwork::~SimulatedNetwork() = default;

Transport* SimulatedNetwork::Endpoint(int drone_id) {
  if (!IsValidDroneId(drone_id) || impl_->index_of[drone_id] < 0) return nullptr;
  return impl_->endpoints[impl_->index_of[drone_id]].get();
}

const std::vector<int>& SimulatedNetwork::drone_ids() const { return impl_->ids; }

LinkStats SimulatedNetwork::Stats(int from_id, int to_id) const {
  if (!IsValidDroneId(from_id) || !IsValidDroneId(to_id)) return {};
  const int from = impl_->index_of[from_id];
  const int to = impl_->index_of[to_id];
  if (from < 0 || to < 0) return {};
  return impl_->links[from * impl_->n() + to].stats;
}

LinkStats SimulatedNetwork::TotalStats() const {
  LinkStats total;
  for (const Impl::Link& link : impl_->links) total += link.stats;
  return total;
}

int64_t SimulatedNetwork::NextArrivalNs() const {
  int64_t next = std::numeric_limits<int64_t>::max();
  for (const auto& inbox : impl_->inboxes) {
    if (!inbox.empty()) next = std::min(next, inbox.top().arrival_ns);
  }
  return next;
}

Status SimulatedNetwork::Impl::Send(
    int from, int64_t now_ns, int destination_id, const uint8_t* data, size_t size) {
  const int from_id = ids[from];
  if (size == 0 || size > kMaxPacketBytes) {
    return Status::InvalidArgument("drone " + std::to_string(from_id) + ": packet of " +
                                   std::to_string(size) + " bytes (must be 1.." +
                                   std::to_string(kMaxPacketBytes) + ")");
  }
  if (destination_id == from_id) {
    return Status::InvalidArgument("drone " + std::to_string(from_id) + " sends to itself");
  }
  auto bytes = std::make_shared<const std::vector<uint8_t>>(data, data + size);
  if (destination_id == kBroadcastId) {
    for (int to = 0; to < n(); ++to) {
      if (to != from) SendOnLink(from, to, now_ns, bytes);
    }
    return Status::Ok();
  }
  if (!IsValidDroneId(destination_id) || index_of[destination_id] < 0) {
    return Status::NotFound("drone " + std::to_string(from_id) + ": no drone " +
                            std::to_string(destination_id) + " on the network");
  }
  SendOnLink(from, index_of[destination_id], now_ns, bytes);
  return Status::Ok();
}

double SimulatedNetwork::Impl::SampleDelay(Link* link) {
  const LinkOptions& o = link->options;
  const bool skip = o.skip_delay_probability > 0.0 && link->rng.Bernoulli(o.skip_delay_probability);
  const double mean = skip ? 0.0 : o.latency_mean_s;
  double delay = mean;
  if (o.jitter_std_s > 0.0) {
    delay = 0.0;
    for (int attempt = 0; attempt < kMaxDelayRedraws; ++attempt) {
      const double candidate = mean + o.jitter_std_s * link->rng.StandardNormal();
      if (candidate >= 0.0) {
        delay = candidate;
        break;
      }
    }
  }
  if (o.reorder_probability > 0.0 && link->rng.Bernoulli(o.reorder_probability)) {
    delay += o.reorder_delay_max_s * link->rng.Uniform01();
  }
  return delay;
}

void SimulatedNetwork::Impl::SendOnLink(int from,
                                        int to,
                                        int64_t now_ns,
                                        const std::shared_ptr<const std::vector<uint8_t>>& bytes) {
  const int index = from * n() + to;
  Link& link = links[index];
  const LinkOptions& o = link.options;
  const uint64_t send_index = link.next_send_index++;
  link.stats.sent += 1;
  link.stats.bytes_sent += bytes->size();

  int64_t depart_ns = now_ns;
  if (o.bandwidth_bytes_per_s > 0.0) {
    const int64_t start_ns = std::max(now_ns, link.busy_until_ns);
    if (start_ns - now_ns > SecondsToNs(o.max_queue_delay_s)) {
      link.stats.dropped_queue += 1;
      return;
    }
    link.busy_until_ns =
        start_ns + SecondsToNs(static_cast<double>(bytes->size()) / o.bandwidth_bytes_per_s);
    depart_ns = link.busy_until_ns;
  }
  if (o.loss_probability > 0.0 && link.rng.Bernoulli(o.loss_probability)) {
    link.stats.dropped_loss += 1;
    return;
  }
  const bool duplicate =
      o.duplicate_probability > 0.0 && link.rng.Bernoulli(o.duplicate_probability);
  const int copies = duplicate ? 2 : 1;
  if (duplicate) link.stats.duplicated += 1;
  for (int copy = 0; copy < copies; ++copy) {
    InFlight f;
    f.arrival_ns = depart_ns + SecondsToNs(SampleDelay(&link));
    f.order = next_order++;
    f.link = index;
    f.send_index = send_index;
    f.send_ns = now_ns;
    f.bytes = bytes;
    inboxes[to].push(std::move(f));
  }
}

Status SimulatedNetwork::Impl::Poll(int to, int64_t now_ns, std::vector<Datagram>* received) {
  auto& inbox = inboxes[to];
  while (!inbox.empty() && inbox.top().arrival_ns <= now_ns) {
    const InFlight& f = inbox.top();
    Link& link = links[f.link];
    const int64_t send_index = static_cast<int64_t>(f.send_index);
    if (send_index < link.max_delivered_index) {
      link.stats.reordered += 1;
    } else {
      link.max_delivered_index = send_index;
    }
    const double latency_s = static_cast<double>(f.arrival_ns - f.send_ns) * 1e-9;
    link.stats.delivered += 1;
    link.stats.bytes_delivered += f.bytes->size();
    link.stats.latency_sum_s += latency_s;
    link.stats.latency_max_s = std::max(link.stats.latency_max_s, latency_s);
    Datagram d;
    d.source_id = ids[f.link / n()];
    d.arrival_ns = f.arrival_ns;
    d.bytes = *f.bytes;
    received->push_back(std::move(d));
    inbox.pop();
  }
  return Status::Ok();
}

}  // namespace swarmlio::net
