// The live drivers' shared options (live_flags.h).
#include "live_flags.h"

#include <exception>
#include <string>
#include <vector>

#include "swarmlio/common/split_list.h"
#include "swarmlio/net/swarm_key_file.h"

DEFINE_string(manifest, "", "swarm manifest YAML (docs/replay.md); with --drone");
DEFINE_string(drone, "", "the drone of --manifest this process runs (its name)");
DEFINE_string(bag, "", "instead of --manifest: the drone's bag");
DEFINE_string(sensor_preset, "", "with --bag (swarmlio_ros: alone): sensor preset (configs/*.yaml)");
DEFINE_int32(drone_id, 0, "with --bag / --sensor_preset: the drone's swarm id (its index in the swarm)");
DEFINE_string(name, "", "with --bag / --sensor_preset: the drone's name (default uav<drone_id + 1>)");
DEFINE_string(initialization, "",
              "static | in_flight: overrides the drone's odometry.initialization (a drone "
              "starting while flying: in_flight); empty: the manifest's or preset's");
DEFINE_string(key_file, "", "required: the swarm's pre-shared key, 64 hex digits "
                            "(head -c 32 /dev/urandom | xxd -p -c 64)");
DEFINE_string(udp_mode, "multicast", "multicast | broadcast | unicast");
DEFINE_int32(port, 8821, "UDP port: the swarm's (multicast, broadcast) or this drone's (unicast)");
DEFINE_string(peers, "",
              "id=host:port,... every teammate (unicast; other modes: source ids only); id is "
              "the swarm id or a drone name of --manifest");
DEFINE_string(multicast_group, "239.255.88.21", "multicast group");
DEFINE_string(interface_address, "0.0.0.0",
              "multicast: interface to join and send on; unicast: address to bind");
DEFINE_string(broadcast_address, "255.255.255.255", "broadcast mode destination");
DEFINE_double(max_scan_backlog_s, 0.3, "a scan taken later than this behind playback (live: behind its arrival) is dropped");
DEFINE_int32(max_queued_scans, 4, "scans waiting for the estimator at most; more are dropped");
DEFINE_double(network_poll_period_ms, 2.0, "UDP poll period [ms]");

namespace swarmlio::tools {
namespace {

Status ParsePeers(const std::string& text, const driver::SwarmManifest& manifest,
                  std::vector<net::UdpPeer>* peers) {
  for (const std::string& item : SplitList(text)) {
    const size_t eq = item.find('=');
    const size_t colon = item.rfind(':');
    if (eq == std::string::npos || colon == std::string::npos || colon < eq) {
      return Status::InvalidArgument("--peers: '" + item + "' is not id=host:port");
    }
    const std::string id_text = item.substr(0, eq);
    net::UdpPeer peer;
    peer.id = -1;
    for (size_t i = 0; i < manifest.drones.size(); ++i) {
      if (manifest.drones[i].name == id_text) peer.id = static_cast<int>(i);
    }
    try {
      if (peer.id < 0) peer.id = std::stoi(id_text);
      peer.port = std::stoi(item.substr(colon + 1));
    } catch (const std::exception&) {
      return Status::InvalidArgument("--peers: '" + item +
                                     "': id (number or drone name) or port unreadable");
    }
    peer.address = item.substr(eq + 1, colon - eq - 1);
    peers->push_back(peer);
  }
  return Status::Ok();
}

}  // namespace

namespace {

/// --initialization overrides the drone's odometry.initialization.
Status ApplyInitializationFlag(driver::DroneInput* drone) {
  if (!FLAGS_initialization.empty() &&
      !config::EnumFromString(FLAGS_initialization, &drone->odometry.initialization)) {
    return Status::InvalidArgument("--initialization: '" + FLAGS_initialization +
                                   "' is not static or in_flight");
  }
  return Status::Ok();
}

}  // namespace

Status LoadDroneFromFlags(LiveInput input, driver::DroneInput* drone, int* drone_id,
                          driver::SwarmManifest* manifest) {
  if (!FLAGS_manifest.empty()) {
    if (FLAGS_drone.empty()) return Status::InvalidArgument("--manifest needs --drone=<name>");
    SWARMLIO_RETURN_IF_ERROR(driver::LoadManifest(FLAGS_manifest, manifest));
    for (size_t i = 0; i < manifest->drones.size(); ++i) {
      if (manifest->drones[i].name == FLAGS_drone) {
        *drone = manifest->drones[i];
        *drone_id = static_cast<int>(i);
        return ApplyInitializationFlag(drone);
      }
    }
    return Status::NotFound("--drone=" + FLAGS_drone + ": not in " + FLAGS_manifest);
  }
  if (input == LiveInput::kBag && FLAGS_bag.empty()) {
    return Status::InvalidArgument("give --manifest and --drone, or --bag");
  }
  if (input == LiveInput::kTopics && FLAGS_bag.empty() && FLAGS_sensor_preset.empty()) {
    return Status::InvalidArgument("give --manifest and --drone, or --sensor_preset");
  }
  const std::string name =
      FLAGS_name.empty() ? "uav" + std::to_string(FLAGS_drone_id + 1) : FLAGS_name;
  SWARMLIO_RETURN_IF_ERROR(
      driver::ManifestFromBags({FLAGS_bag}, FLAGS_sensor_preset, {name}, manifest));
  *drone = manifest->drones[0];
  *drone_id = FLAGS_drone_id;
  return ApplyInitializationFlag(drone);
}

Status UdpOptionsFromFlags(const driver::SwarmManifest& manifest, net::UdpOptions* udp) {
  if (!config::EnumFromString(FLAGS_udp_mode, &udp->mode)) {
    return Status::InvalidArgument("--udp_mode=" + FLAGS_udp_mode + ": expected one of " +
                                   config::EnumChoices<net::UdpMode>());
  }
  udp->port = FLAGS_port;
  udp->multicast_group = FLAGS_multicast_group;
  udp->interface_address = FLAGS_interface_address;
  udp->broadcast_address = FLAGS_broadcast_address;
  SWARMLIO_RETURN_IF_ERROR(ParsePeers(FLAGS_peers, manifest, &udp->peers));
  if (const std::string invalid = udp->Validate(); !invalid.empty()) {
    return Status::InvalidArgument("udp options (--udp_mode, --port, --peers, ...): " + invalid);
  }
  return Status::Ok();
}

Status SwarmKeyFromFlags(net::SwarmKey* key) {
  if (FLAGS_key_file.empty()) return Status::InvalidArgument("--key_file is required");
  return net::LoadSwarmKeyFile(FLAGS_key_file, key).WithContext("--key_file");
}

void ApplyLiveFlags(live::LiveOptions* options) {
  options->max_scan_backlog_s = FLAGS_max_scan_backlog_s;
  options->max_queued_scans = FLAGS_max_queued_scans;
  options->network_poll_period_ms = FLAGS_network_poll_period_ms;
}

}  // namespace swarmlio::tools
