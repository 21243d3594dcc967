#include "src/io/bag_common.h"

#include <console_bridge/console.h>
#include <rosbag/exceptions.h>

#include <filesystem>
#include <mutex>
#include <system_error>

#include "src/io/bag_precheck.h"
#include "swarmlio/common/check.h"

namespace swarmlio::io::internal {
namespace {

class GlogOutputHandler : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text,
           console_bridge::LogLevel level,
           const char* filename,
           int line) override {
    VLOG(1) << "rosbag [" << static_cast<int>(level) << "] " << filename << ":" << line << ": "
            << text;
  }
};

}  // namespace

void RouteRosbagLogsToGlog() {
  static std::once_flag once;
  std::call_once(once, [] {
    console_bridge::OutputHandler* current = console_bridge::getOutputHandler();
    if (current != nullptr && dynamic_cast<console_bridge::OutputHandlerSTD*>(current) == nullptr) {
      return;  // somebody chose a handler already
    }
    static GlogOutputHandler* const kHandler = new GlogOutputHandler();
    console_bridge::useOutputHandler(kHandler);
  });
}

Status StatusFromException(const std::string& path,
                           const std::string& action,
                           const std::exception& e) {
  const std::string message = "bag '" + path + "': " + action + " failed: " + e.what();
  if (dynamic_cast<const rosbag::BagIOException*>(&e) != nullptr) {
    return Status::IoError(message);
  }
  return Status::DataLoss(message);
}

Status UnknownExceptionStatus(const std::string& path, const std::string& action) {
  return Status::Internal("bag '" + path + "': " + action + " failed: unknown exception");
}

Status OpenBagForReading(const std::string& path,
                         bool verify_chunks,
                         rosbag::Bag* bag,
                         BagPrecheckResult* precheck_result) {
  RouteRosbagLogsToGlog();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return Status::NotFound("bag '" + path + "': no such file");
  }
  BagPrecheckOptions precheck;
  precheck.verify_chunk_records = verify_chunks;
  SWARMLIO_RETURN_IF_ERROR(PrecheckBagFile(path, precheck, precheck_result));
  try {
    bag->open(path, rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    return StatusFromException(path, "open", e);
  } catch (...) {
    return UnknownExceptionStatus(path, "open");
  }
  return Status::Ok();
}

}  // namespace swarmlio::io::internal
