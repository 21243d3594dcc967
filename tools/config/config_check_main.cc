// swarmlio_config_check: validates a swarmlio YAML config and prints every
// resolved value with its unit, range and doc (keys the file omits show their
// defaults), or one error naming file, line, key and reason.
//
//   swarmlio_config_check --config=configs/livox_avia.yaml
//   swarmlio_config_check configs/livox_avia.yaml
//   swarmlio_config_check --dump_defaults   # every known section, defaults
//
// Exit code: 0 when the file is valid, 1 otherwise.
#include <gflags/gflags.h>

#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "swarmlio/config/config_file.h"
#include "swarmlio/config/dump_options.h"
#include "swarmlio/lio/odometry_options.h"
#include "swarmlio/net/network_options.h"
#include "swarmlio/sensors/imu_options.h"
#include "swarmlio/sensors/lidar_options.h"
#include "swarmlio/swarm/swarm_options.h"
#include "swarmlio/teammate/teammate_detector_options.h"

DEFINE_string(config, "", "YAML config file to check (or pass it as the only argument)");
DEFINE_bool(dump_defaults, false, "print every known section with its default values and exit");
DEFINE_bool(quiet, false, "print nothing on success, only errors");

namespace {

using swarmlio::Status;
using swarmlio::config::ConfigFile;

// One top-level section this tool knows. Add a line to Sections() when a
// module adds an options struct that configs/*.yaml may contain.
struct Section {
  std::string name;
  // Reads the section from `file` and renders the resolved values.
  std::function<Status(const ConfigFile& file, std::string* yaml)> read_and_dump;
  std::function<std::string()> dump_defaults;
};

template <class Options>
Section MakeSection(const std::string& name) {
  Section section;
  section.name = name;
  section.read_and_dump = [name](const ConfigFile& file, std::string* yaml) {
    Options options;
    const Status status = file.Read(name, &options);
    if (status.ok()) *yaml = swarmlio::config::DumpOptions(options, name);
    return status;
  };
  section.dump_defaults = [name] { return swarmlio::config::DumpOptions(Options(), name); };
  return section;
}

std::vector<Section> Sections() {
  return {
      MakeSection<swarmlio::LidarOptions>("lidar"),
      MakeSection<swarmlio::ImuOptions>("imu"),
      MakeSection<swarmlio::teammate::TeammateDetectorOptions>("teammate"),
      MakeSection<swarmlio::lio::OdometryOptions>("odometry"),
      MakeSection<swarmlio::swarm::SwarmOptions>("swarm"),
      MakeSection<swarmlio::net::NetworkOptions>("network"),
  };
}

int Fail(const std::string& message) {
  std::fprintf(stderr, "swarmlio_config_check: error: %s\n", message.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  gflags::SetUsageMessage(
      "validates a swarmlio YAML config and prints the resolved values\n"
      "usage: swarmlio_config_check [--config=]FILE [--quiet] | --dump_defaults");
  gflags::ParseCommandLineFlags(&argc, &argv, /*remove_flags=*/true);

  if (FLAGS_dump_defaults) {
    std::string out = "# swarmlio configuration: every known section with its defaults.\n";
    for (const Section& section : Sections()) out += "\n" + section.dump_defaults();
    std::fputs(out.c_str(), stdout);
    return 0;
  }

  std::string path = FLAGS_config;
  if (argc == 2 && path.empty()) path = argv[1];
  if (path.empty() || argc > 2 || (argc == 2 && path != argv[1])) {
    return Fail("give exactly one config file (--config=FILE or FILE); see --help");
  }

  ConfigFile file;
  Status status = ConfigFile::Load(path, &file);
  if (!status.ok()) return Fail(status.message());

  std::string out = "# " + path + ": OK\n# Resolved values; keys the file omits show defaults.\n";
  for (const Section& section : Sections()) {
    std::string yaml;
    status = section.read_and_dump(file, &yaml);
    if (!status.ok()) return Fail(status.message());
    out += "\n";
    if (!file.HasSection(section.name)) out += "# (not in the file: defaults)\n";
    out += yaml;
  }
  status = file.CheckNoUnusedSections();
  if (!status.ok()) return Fail(status.message());
  if (!FLAGS_quiet) std::fputs(out.c_str(), stdout);
  return 0;
}
