// Results of a replay run: per-drone metrics (APE/RPE against ground truth,
// per-scan time, real-time factor, NEES), the metrics table (Markdown, CSV,
// JSON), plots (PNG) and the network statistics. Tool-side: writes files.
#pragma once

#include <string>

#include "swarmlio/common/status.h"
#include "swarmlio/replay/swarm_replay.h"

namespace swarmlio::tools {

struct ReportOptions {
  std::string output_dir;
  bool single_agent = false;
  bool save_maps = true;
};

/// Writes every output of `run` into options.output_dir and returns the
/// Markdown metrics table in `*markdown`. Every output is attempted; the
/// first error (e.g. ground truth that does not overlap the estimate) is
/// returned, with all the others listed in `*problems` (one per line).
Status WriteReport(const replay::SwarmReplay& run, const ReportOptions& options,
                   std::string* markdown, std::string* problems);

}  // namespace swarmlio::tools
