// swarm::BroadcastBudget: the bytes one drone may put on the wire, as a token
// bucket on the sensor clock, and the "least recently sent first" order in
// which optional content shares it (docs/swarm.md "Broadcast budget",
// docs/network.md section 2.2).
//
// Why: every drone broadcasts one state per scan (mandatory), but what rides
// along grows with the swarm: an observation per teammate in view, an echo per
// teammate for the clock sync, an extrinsic entry per identified teammate.
// Capping each item count separately still lets their sum grow past the link's
// budget; a byte budget bounds the sum for any N, and the priorities decide
// what a crowded drone leaves out.
//
// The bucket: credit grows by max_bytes_per_s x (stamp - previous stamp) and
// is capped at max_bytes_per_s x burst_s (it starts full). Mandatory packets
// are spent whatever the credit (it may go negative: optional content then
// waits until it recovered); optional items only when the credit covers them.
// So over any window of W seconds the bytes sent are at most
// max_bytes_per_s x (W + burst_s), plus mandatory packets in excess of the
// rate (only when the states alone exceed it, e.g. scans faster than
// max_bytes_per_s / state bytes per second). Sizes are wire bytes: the
// swarmlio packet plus ip_udp_header_bytes per datagram, as the socket
// counters of net::UdpTransport count them.
//
// Deterministic (stamps, no clock): a replay reproduces a live drone's choices.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "swarmlio/common/option_fields.h"

namespace swarmlio::swarm {

/// YAML section `swarm.broadcast_budget`.
struct BroadcastBudgetOptions {
  /// Bytes on the wire per second, IP/UDP headers included (0 = unlimited:
  /// everything is sent, as before the budget) [B/s].
  double max_bytes_per_s = 1450.0;
  /// Credit saved at most this many seconds of the rate [s].
  double burst_s = 0.5;
  /// IPv4 (20) + UDP (8) header bytes per datagram [B].
  int ip_udp_header_bytes = 28;
  /// Entries per GlobalExtrinsic broadcast (least recently sent first; 0 =
  /// as many as the budget affords).
  int max_extrinsic_entries_per_broadcast = 0;
  /// Echoes per state for teammates whose clock offset is not converged
  /// (ClockSyncOptions::min_samples) that rank above the observations;
  /// further echoes come after them.
  int urgent_echoes_per_state = 1;
  // A T_Gi_Gj entry not sent for this long goes out like a new one, ahead of
  // the observations and echoes (0 = never): on a saturated budget the
  // periodic re-broadcast would otherwise starve, and a teammate that lost
  // the one new-entry broadcast would never hear it again. Longer when the
  // entries would then take more than 10 % of max_bytes_per_s (39 entries at
  // 1450 B/s: 11 s) [s].
  double extrinsic_overdue_s = 3.0;

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("max_bytes_per_s", max_bytes_per_s,
      FieldSpec::InRange(0.0, 1e9, "B/s", "bytes on the wire per second, headers included (0 = unlimited)"));
    config::VisitExperimental(v, [&](auto& x) {
      x("burst_s", burst_s, FieldSpec::InRange(0.0, 60.0, "s", "credit saved at most this many seconds"));
      x("ip_udp_header_bytes", ip_udp_header_bytes,
        FieldSpec::InRange(0, 128, "B", "IP/UDP header bytes per datagram"));
      x("max_extrinsic_entries_per_broadcast", max_extrinsic_entries_per_broadcast,
        FieldSpec::InRange(0, 255, "", "T_Gi_Gj entries per broadcast (0 = as many as the budget affords)"));
      x("urgent_echoes_per_state", urgent_echoes_per_state,
        FieldSpec::InRange(0, 8, "", "echoes for unconverged clock offsets ranked above the observations"));
      x("extrinsic_overdue_s", extrinsic_overdue_s,
        FieldSpec::InRange(0.0, 3600.0, "s",
                           "an entry not sent for this long goes out like a new one (0 = never)"));
    });
  }
  std::string Validate() const { return config::ValidateFields(*this); }
};

class BroadcastBudget {
 public:
  explicit BroadcastBudget(const BroadcastBudgetOptions& options = {});

  bool limited() const { return options_.max_bytes_per_s > 0.0; }
  /// Adds the credit earned since the previous call (the first call: a full
  /// bucket). Stamps going backwards earn nothing.
  void Refill(int64_t stamp_ns);
  /// A datagram carrying a packet of `packet_bytes` (swarmlio header, payload
  /// and tag) on the wire.
  size_t WireBytes(size_t packet_bytes) const;
  /// Mandatory bytes: spent whatever the credit.
  void Spend(size_t bytes);
  /// Optional bytes: spent (true) only if the credit covers them.
  bool TrySpend(size_t bytes);
  /// Items of item_bytes each the credit covers after first_bytes (paid once
  /// with the first item), at most max_items; all of them when unlimited.
  int Affordable(size_t first_bytes, size_t item_bytes, int max_items) const;
  double credit_bytes() const { return credit_; }

 private:
  BroadcastBudgetOptions options_;
  double credit_ = 0.0;
  bool refilled_ = false;
  int64_t last_stamp_ns_ = 0;
};

/// The order in which ids share a budget: never sent first, then the least
/// recently sent; ties by id. Ids are teammates (observed, echoed, or
/// extrinsic entries), each kind with its own rotation.
class SendRotation {
 public:
  /// `ids` sorted in sending order.
  std::vector<int> Order(std::vector<int> ids) const;
  /// `stamp_ns`: when (sensor clock), for LastSentNs.
  void MarkSent(int id, int64_t stamp_ns = std::numeric_limits<int64_t>::min()) {
    last_sent_[id] = ++sends_;
    last_sent_ns_[id] = stamp_ns;
  }
  bool EverSent(int id) const { return last_sent_.count(id) > 0; }
  /// The stamp given at id's last send (INT64_MIN if never sent or none given).
  int64_t LastSentNs(int id) const {
    const auto it = last_sent_ns_.find(id);
    return it == last_sent_ns_.end() ? std::numeric_limits<int64_t>::min() : it->second;
  }
  void Forget(int id) {
    last_sent_.erase(id);
    last_sent_ns_.erase(id);
  }

 private:
  std::map<int, uint64_t> last_sent_;  // id -> send count at its last send
  std::map<int, int64_t> last_sent_ns_;  // id -> stamp of its last send
  uint64_t sends_ = 0;
};

}  // namespace swarmlio::swarm
