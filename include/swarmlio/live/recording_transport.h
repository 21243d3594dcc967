// RecordingTransport: a net::Transport decorator that appends every datagram
// the wrapped transport returns from Poll to a packet log (net/packet_log.h),
// before the MessageChannel decodes it: raw bytes, transport source id and
// arrival time (the `now_ns` given to Poll, i.e. the sensor time line). Send
// passes through. Used by the live process's network thread only.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/net/packet_log.h"
#include "swarmlio/net/transport.h"

namespace swarmlio::live {

class RecordingTransport : public net::Transport {
 public:
  /// `inner` must outlive this; `log` may be null (nothing recorded).
  RecordingTransport(net::Transport* inner, std::unique_ptr<net::PacketLogWriter> log)
      : inner_(inner), log_(std::move(log)) {}

  int self_id() const override { return inner_->self_id(); }
  Status Send(int64_t now_ns, int destination_id, const uint8_t* data, size_t size) override {
    return inner_->Send(now_ns, destination_id, data, size);
  }
  /// Polls the inner transport and logs what it returned (flushed per poll
  /// that returned something). A log write error is returned after the
  /// datagrams were appended to `*received` (the datagrams are not lost).
  Status Poll(int64_t now_ns, std::vector<net::Datagram>* received) override;

  /// Closes the log (returns its first error, if any, since it was opened).
  Status CloseLog();
  int64_t logged() const { return log_ ? log_->records() : 0; }

 private:
  net::Transport* inner_;
  std::unique_ptr<net::PacketLogWriter> log_;
  Status log_error_;
};

}  // namespace swarmlio::live
