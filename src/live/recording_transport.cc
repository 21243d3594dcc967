#include "swarmlio/live/recording_transport.h"

namespace swarmlio::live {

Status RecordingTransport::Poll(int64_t now_ns, std::vector<net::Datagram>* received) {
  const size_t first = received->size();
  const Status polled = inner_->Poll(now_ns, received);
  if (log_ == nullptr || received->size() == first) return polled;
  Status logged;
  for (size_t i = first; i < received->size() && logged.ok(); ++i) {
    logged = log_->Append((*received)[i]);
  }
  if (logged.ok()) logged = log_->Flush();
  if (!logged.ok() && log_error_.ok()) log_error_ = logged;
  return polled.ok() ? logged : polled;
}

Status RecordingTransport::CloseLog() {
  if (log_ == nullptr) return log_error_;
  const Status closed = log_->Close();
  return log_error_.ok() ? closed : log_error_;
}

}  // namespace swarmlio::live
