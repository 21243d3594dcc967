// Options of the simulated network (YAML section `network`), see
// docs/network.md, "Simulated network".
//
//   network:
//     seed: 1
//     default_link:            # every directed link i -> j
//       latency_mean_s: 0.005
//       jitter_std_s: 0.002
//       loss_probability: 0.01
//     links:                   # overrides; the last matching entry wins
//       - {from_id: 0, to_id: 2, link: {loss_probability: 0.3}}
//
// An override's `link` starts from the built-in LinkOptions defaults, not
// from `default_link`: write every key that should differ from them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/net/swarm_limits.h"

namespace swarmlio::net {

/// Behaviour of one directed link. Per packet, in this order: the bandwidth
/// queue (if capped), loss, latency = latency_mean_s + jitter (approximately
/// normal, truncated at >= 0), an optional extra delay (reordering), and an
/// optional duplicate with its own latency.
struct LinkOptions {
  double latency_mean_s = 0.005;       // one-way delay mean [s]
  double jitter_std_s = 0.001;         // std of the delay around the mean [s]
  double loss_probability = 0.0;       // independent per packet
  double duplicate_probability = 0.0;  // a second copy is delivered
  double reorder_probability = 0.0;    // extra delay, uniform in [0, reorder_delay_max_s]
  double reorder_delay_max_s = 0.02;   // [s]
  double skip_delay_probability = 0.0;  // sent without latency_mean_s (jitter and extra delay
                                        // still apply): netem's "reorder", a fast lane
  double bandwidth_bytes_per_s = 0.0;  // 0: unlimited; else packets queue (FIFO)
  double max_queue_delay_s = 0.5;      // a packet that would wait longer is dropped [s]

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("latency_mean_s", latency_mean_s, FieldSpec::InRange(0.0, 10.0, "s", "mean one-way delay"));
    v("jitter_std_s", jitter_std_s,
      FieldSpec::InRange(0.0, 10.0, "s", "delay standard deviation (truncated at 0 delay)"));
    v("loss_probability", loss_probability,
      FieldSpec::InRange(0.0, 1.0, "", "probability that a packet is lost"));
    v("bandwidth_bytes_per_s", bandwidth_bytes_per_s,
      FieldSpec::AtLeast(0.0, "B/s", "link capacity, 0 for unlimited"));
    config::VisitExperimental(v, [&](auto& x) {
      x("duplicate_probability", duplicate_probability,
        FieldSpec::InRange(0.0, 1.0, "", "probability that a packet is delivered twice"));
      x("reorder_probability", reorder_probability,
        FieldSpec::InRange(0.0, 1.0, "", "probability of an extra delay that reorders packets"));
      x("reorder_delay_max_s", reorder_delay_max_s,
        FieldSpec::InRange(0.0, 10.0, "s", "extra delay is uniform in [0, this]"));
      x("skip_delay_probability", skip_delay_probability,
        FieldSpec::InRange(0.0, 1.0, "",
                           "probability that a packet skips latency_mean_s (netem's reorder)"));
      x("max_queue_delay_s", max_queue_delay_s,
        FieldSpec::Positive("s", "with a bandwidth cap, packets that would queue longer are dropped")
            .WithMax(60.0));
    });
  }

  std::string Validate() const { return config::ValidateFields(*this); }
};

/// Link options for the links from `from_id` to `to_id` (-1: any drone).
struct LinkOverride {
  int from_id = -1;
  int to_id = -1;
  LinkOptions link;

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("from_id", from_id,
      FieldSpec::InRange(-1, kMaxSwarmSize - 1, "", "sending drone, -1 for any"));
    v("to_id", to_id, FieldSpec::InRange(-1, kMaxSwarmSize - 1, "", "receiving drone, -1 for any"));
    v("link", link);
  }

  std::string Validate() const;
};

struct NetworkOptions {
  int64_t seed = 1;  // same seed + same sends -> same deliveries, bit for bit
  LinkOptions default_link;
  std::vector<LinkOverride> links;

  template <class V>
  void VisitFields(V&& v) {
    using config::FieldSpec;
    v("seed", seed, FieldSpec::AtLeast(0, "", "random seed of the simulated network"));
    v("default_link", default_link);
    v("links", links);
  }

  std::string Validate() const { return config::ValidateFields(*this); }

  /// The options of link from -> to: the last matching override, else default_link.
  const LinkOptions& ForLink(int from_id, int to_id) const;
};

}  // namespace swarmlio::net
