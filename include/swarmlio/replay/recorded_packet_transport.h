// RecordedPacketTransport: a net::Transport that plays back a packet log
// (net/packet_log.h) written by the live process, so the offline replay can
// re-run one drone with exactly the datagrams it received live, at their
// recorded arrival times on its sensor time line (docs/online.md, "Offline
// re-run"). Poll(now) returns the logged datagrams with arrival <= now, in
// log order; Send discards (the recording already holds what the teammates
// heard) and counts.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/net/packet_log.h"
#include "swarmlio/net/transport.h"

namespace swarmlio::replay {

class RecordedPacketTransport : public net::Transport {
 public:
  /// Reads the whole log. Errors (naming the file): cannot open, not a
  /// packet log, unsupported version, recorded by another drone id than
  /// `self_id`. A truncated or corrupt log (e.g. the live process was
  /// killed) opens with the complete records before the damage, and
  /// damage() says what was lost.
  static Status Open(const std::string& path, int self_id,
                     std::unique_ptr<RecordedPacketTransport>* transport);

  int self_id() const override { return self_id_; }
  /// Discards the packet (counted in sent_discarded()); Ok.
  Status Send(int64_t now_ns, int destination_id, const uint8_t* data, size_t size) override;
  Status Poll(int64_t now_ns, std::vector<net::Datagram>* received) override;

  int64_t num_datagrams() const { return static_cast<int64_t>(datagrams_.size()); }
  int64_t delivered() const { return static_cast<int64_t>(next_); }
  int64_t sent_discarded() const { return sent_discarded_; }
  const net::PacketLogHeader& header() const { return header_; }
  /// Ok, or the DataLoss the log was read with (its records up to the damage are kept).
  const Status& damage() const { return damage_; }

 private:
  RecordedPacketTransport() = default;

  int self_id_ = -1;
  net::PacketLogHeader header_;
  std::vector<net::Datagram> datagrams_;
  size_t next_ = 0;
  int64_t sent_discarded_ = 0;
  Status damage_;
};

}  // namespace swarmlio::replay
