#include "swarmlio/replay/recorded_packet_transport.h"

#include <utility>

namespace swarmlio::replay {

Status RecordedPacketTransport::Open(const std::string& path, int self_id,
                                     std::unique_ptr<RecordedPacketTransport>* transport) {
  std::unique_ptr<RecordedPacketTransport> t(new RecordedPacketTransport());
  t->self_id_ = self_id;
  const Status read = net::ReadPacketLog(path, &t->header_, &t->datagrams_);
  if (read.code() == Status::Code::kDataLoss && !t->datagrams_.empty()) {
    t->damage_ = read;  // keep the records before the damage
  } else if (!read.ok()) {
    return read;
  }
  if (t->header_.self_id != self_id) {
    return Status::InvalidArgument(path + ": recorded by drone id " +
                                   std::to_string(t->header_.self_id) + ", replayed as drone id " +
                                   std::to_string(self_id) +
                                   " (the drone's index in the manifest must match the live run)");
  }
  *transport = std::move(t);
  return Status::Ok();
}

Status RecordedPacketTransport::Send(int64_t /*now_ns*/, int /*destination_id*/,
                                     const uint8_t* /*data*/, size_t /*size*/) {
  ++sent_discarded_;
  return Status::Ok();
}

Status RecordedPacketTransport::Poll(int64_t now_ns, std::vector<net::Datagram>* received) {
  while (next_ < datagrams_.size() && datagrams_[next_].arrival_ns <= now_ns) {
    received->push_back(datagrams_[next_]);
    ++next_;
  }
  return Status::Ok();
}

}  // namespace swarmlio::replay
