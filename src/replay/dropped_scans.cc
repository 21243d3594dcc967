#include "swarmlio/replay/dropped_scans.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

namespace swarmlio::replay {

Status ReadDroppedScans(const std::string& path, std::vector<int64_t>* stamps_ns) {
  std::ifstream in(path);
  if (!in) return Status::IoError(path + ": " + std::strerror(errno));
  std::vector<int64_t> stamps;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    long long stamp = 0;
    std::string reason, rest;
    if (!(fields >> stamp >> reason) || (reason != "queue" && reason != "backlog") ||
        (fields >> rest)) {
      return Status::DataLoss(path + ":" + std::to_string(number) + ": expected '<stamp_ns> " +
                              "queue|backlog', found '" + line + "'");
    }
    stamps.push_back(static_cast<int64_t>(stamp));
  }
  if (in.bad()) return Status::IoError(path + ": read failed");
  *stamps_ns = std::move(stamps);
  return Status::Ok();
}

}  // namespace swarmlio::replay
