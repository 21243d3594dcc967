// The command-line options every live driver shares (swarmlio_live and the
// ROS node swarmlio_ros, docs/online.md): which drone (a manifest entry, or
// a bag / sensor preset with a swarm id), the swarm key, the UDP network and
// the estimator thread's drop policy. The gflags are defined in
// live_flags.cc; each tool adds its own.
#pragma once

#include <gflags/gflags.h>

#include <string>

#include "swarmlio/common/status.h"
#include "swarmlio/live/live_options.h"
#include "swarmlio/net/swarm_key.h"
#include "swarmlio/net/udp_transport.h"
#include "swarmlio/driver/manifest.h"

DECLARE_string(manifest);
DECLARE_string(drone);
DECLARE_string(bag);
DECLARE_string(sensor_preset);
DECLARE_int32(drone_id);
DECLARE_string(name);
DECLARE_string(initialization);
DECLARE_string(key_file);
DECLARE_string(udp_mode);
DECLARE_int32(port);
DECLARE_string(peers);
DECLARE_string(multicast_group);
DECLARE_string(interface_address);
DECLARE_string(broadcast_address);
DECLARE_double(max_scan_backlog_s);
DECLARE_int32(max_queued_scans);
DECLARE_double(network_poll_period_ms);

namespace swarmlio::tools {

/// Whether the drone's input is its bag (swarmlio_live) or live topics
/// (swarmlio_ros: --sensor_preset alone is enough, no --bag).
enum class LiveInput { kBag, kTopics };

/// The drone from --manifest/--drone, or --bag (kBag) / --sensor_preset with
/// --drone_id and --name. `manifest` holds every drone (names for --peers).
Status LoadDroneFromFlags(LiveInput input, driver::DroneInput* drone, int* drone_id,
                          driver::SwarmManifest* manifest);

/// --udp_mode, --port, --peers (ids or names of `manifest`), ... validated.
Status UdpOptionsFromFlags(const driver::SwarmManifest& manifest, net::UdpOptions* udp);

/// --key_file (required).
Status SwarmKeyFromFlags(net::SwarmKey* key);

/// --max_scan_backlog_s, --max_queued_scans, --network_poll_period_ms.
void ApplyLiveFlags(live::LiveOptions* options);

}  // namespace swarmlio::tools
