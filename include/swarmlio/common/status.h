// Status: the error value returned across module boundaries.
//
// Library code never throws across a module boundary, never prints and never
// ends the process. A function that can fail on bad input (a file, a packet, a
// config value) returns a Status; programmer errors are CHECKs (see check.h).
#pragma once

#include <string>
#include <utility>

namespace swarmlio {

class [[nodiscard]] Status {
 public:
  enum class Code { kOk = 0, kInvalidArgument, kNotFound, kIoError, kDataLoss, kOutOfRange,
                    kFailedPrecondition, kInternal };

  Status() = default;
  static Status Ok() { return Status(); }
  static Status InvalidArgument(std::string msg) { return {Code::kInvalidArgument, std::move(msg)}; }
  static Status NotFound(std::string msg) { return {Code::kNotFound, std::move(msg)}; }
  static Status IoError(std::string msg) { return {Code::kIoError, std::move(msg)}; }
  static Status DataLoss(std::string msg) { return {Code::kDataLoss, std::move(msg)}; }
  static Status OutOfRange(std::string msg) { return {Code::kOutOfRange, std::move(msg)}; }
  static Status FailedPrecondition(std::string msg) {
    return {Code::kFailedPrecondition, std::move(msg)};
  }
  static Status Internal(std::string msg) { return {Code::kInternal, std::move(msg)}; }

  bool ok() const { return code_ == Code::kOk; }
  Code code() const { return code_; }
  const std::string& message() const { return message_; }

  /// Returns a copy whose message is "context: message" (no-op when ok).
  Status WithContext(const std::string& context) const {
    if (ok()) return *this;
    return Status(code_, context + ": " + message_);
  }

 private:
  Status(Code code, std::string msg) : code_(code), message_(std::move(msg)) {}
  Code code_ = Code::kOk;
  std::string message_;
};

}  // namespace swarmlio

/// Propagates a non-ok Status to the caller.
#define SWARMLIO_RETURN_IF_ERROR(expr)            \
  do {                                            \
    ::swarmlio::Status _swarmlio_status = (expr); \
    if (!_swarmlio_status.ok()) return _swarmlio_status; \
  } while (false)
