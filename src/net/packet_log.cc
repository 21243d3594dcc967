// Packet log writer and reader (format in packet_log.h).
#include "swarmlio/net/packet_log.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <system_error>

#include "swarmlio/net/swarm_limits.h"

namespace swarmlio::net {
namespace {

void PutU32(uint32_t v, std::vector<uint8_t>* out) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<uint8_t>(v >> (8 * i)));
}
void PutI64(int64_t value, std::vector<uint8_t>* out) {
  const uint64_t v = static_cast<uint64_t>(value);
  for (int i = 0; i < 8; ++i) out->push_back(static_cast<uint8_t>(v >> (8 * i)));
}
uint32_t GetU32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 |
         static_cast<uint32_t>(p[2]) << 16 | static_cast<uint32_t>(p[3]) << 24;
}
int64_t GetI64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return static_cast<int64_t>(v);
}

// The checksum covers source id, arrival and payload (the size is implied).
uint32_t RecordCrc(int source_id, int64_t arrival_ns, const uint8_t* bytes, size_t size) {
  std::vector<uint8_t> head;
  PutU32(static_cast<uint32_t>(source_id), &head);
  PutI64(arrival_ns, &head);
  return Crc32(bytes, size, Crc32(head.data(), head.size()));
}

std::string ErrnoText() { return std::generic_category().message(errno); }

}  // namespace

uint32_t Crc32(const uint8_t* data, size_t size, uint32_t crc) {
  crc = ~crc;
  for (size_t i = 0; i < size; ++i) {
    crc ^= data[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

Status PacketLogWriter::Open(const std::string& path, const PacketLogHeader& header,
                             std::unique_ptr<PacketLogWriter>* writer) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) return Status::IoError(path + ": cannot create: " + ErrnoText());
  std::unique_ptr<PacketLogWriter> w(new PacketLogWriter(path, file));
  std::vector<uint8_t> head(PacketLogHeader::kMagic, PacketLogHeader::kMagic + 8);
  PutU32(PacketLogHeader::kVersion, &head);
  PutU32(static_cast<uint32_t>(header.self_id), &head);
  PutI64(header.sensor_start_ns, &head);
  if (std::fwrite(head.data(), 1, head.size(), file) != head.size()) {
    return Status::IoError(path + ": cannot write the header: " + ErrnoText());
  }
  w->bytes_written_ = static_cast<int64_t>(head.size());
  SWARMLIO_RETURN_IF_ERROR(w->Flush());
  *writer = std::move(w);
  return Status::Ok();
}

PacketLogWriter::~PacketLogWriter() { (void)Close(); }

Status PacketLogWriter::Append(const Datagram& d) {
  if (file_ == nullptr) return Status::FailedPrecondition(path_ + ": closed");
  if (d.bytes.empty() || d.bytes.size() > kMaxPacketBytes) {
    return Status::InvalidArgument(path_ + ": datagram of " + std::to_string(d.bytes.size()) +
                                   " B not logged (1.." + std::to_string(kMaxPacketBytes) + ")");
  }
  if (d.arrival_ns < last_arrival_ns_) {
    return Status::InvalidArgument(path_ + ": arrival " + std::to_string(d.arrival_ns) +
                                   " ns before the previous record's");
  }
  std::vector<uint8_t> head;
  head.reserve(PacketLogHeader::kRecordHeaderBytes);
  PutU32(static_cast<uint32_t>(d.bytes.size()), &head);
  PutU32(static_cast<uint32_t>(d.source_id), &head);
  PutI64(d.arrival_ns, &head);
  PutU32(RecordCrc(d.source_id, d.arrival_ns, d.bytes.data(), d.bytes.size()), &head);
  if (std::fwrite(head.data(), 1, head.size(), file_) != head.size() ||
      std::fwrite(d.bytes.data(), 1, d.bytes.size(), file_) != d.bytes.size()) {
    return Status::IoError(path_ + ": write failed: " + ErrnoText());
  }
  last_arrival_ns_ = d.arrival_ns;
  ++records_;
  bytes_written_ += static_cast<int64_t>(head.size() + d.bytes.size());
  return Status::Ok();
}

Status PacketLogWriter::Flush() {
  if (file_ == nullptr) return Status::Ok();
  if (std::fflush(file_) != 0) return Status::IoError(path_ + ": flush failed: " + ErrnoText());
  return Status::Ok();
}

Status PacketLogWriter::Close() {
  if (file_ == nullptr) return Status::Ok();
  const bool flushed = std::fflush(file_) == 0;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!flushed || !closed) return Status::IoError(path_ + ": close failed: " + ErrnoText());
  return Status::Ok();
}

Status ReadPacketLog(const std::string& path, PacketLogHeader* header,
                     std::vector<Datagram>* datagrams) {
  datagrams->clear();
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::IoError(path + ": cannot open: " + ErrnoText());
  const std::vector<uint8_t> data((std::istreambuf_iterator<char>(in)),
                                  std::istreambuf_iterator<char>());
  if (in.bad()) return Status::IoError(path + ": read failed");
  if (data.size() < 8 || std::memcmp(data.data(), PacketLogHeader::kMagic, 8) != 0) {
    return Status::InvalidArgument(path + ": not a swarmlio packet log (bad magic; expected " +
                                   PacketLogHeader::kMagic + ")");
  }
  if (data.size() < PacketLogHeader::kHeaderBytes) {
    return Status::DataLoss(path + ": truncated header (" + std::to_string(data.size()) + " of " +
                            std::to_string(PacketLogHeader::kHeaderBytes) + " B)");
  }
  const uint32_t version = GetU32(data.data() + 8);
  if (version != PacketLogHeader::kVersion) {
    return Status::InvalidArgument(path + ": packet log version " + std::to_string(version) +
                                   " not supported (expected " +
                                   std::to_string(PacketLogHeader::kVersion) + ")");
  }
  header->self_id = static_cast<int32_t>(GetU32(data.data() + 12));
  header->sensor_start_ns = GetI64(data.data() + 16);
  size_t offset = PacketLogHeader::kHeaderBytes;
  int64_t last_arrival_ns = std::numeric_limits<int64_t>::min();
  while (offset < data.size()) {
    const std::string where = path + ": record " + std::to_string(datagrams->size()) +
                              " at byte " + std::to_string(offset);
    const std::string kept = "; the " + std::to_string(datagrams->size()) +
                             " complete records before it are kept";
    const size_t left = data.size() - offset;
    if (left < PacketLogHeader::kRecordHeaderBytes) {
      return Status::DataLoss(where + ": truncated record header (" + std::to_string(left) +
                              " of " + std::to_string(PacketLogHeader::kRecordHeaderBytes) +
                              " B)" + kept);
    }
    const uint8_t* p = data.data() + offset;
    const uint32_t size = GetU32(p);
    Datagram d;
    d.source_id = static_cast<int32_t>(GetU32(p + 4));
    d.arrival_ns = GetI64(p + 8);
    const uint32_t crc = GetU32(p + 16);
    if (size == 0 || size > kMaxPacketBytes) {
      return Status::DataLoss(where + ": size " + std::to_string(size) + " B outside 1.." +
                              std::to_string(kMaxPacketBytes) + kept);
    }
    if (left - PacketLogHeader::kRecordHeaderBytes < size) {
      return Status::DataLoss(where + ": truncated payload (" +
                              std::to_string(left - PacketLogHeader::kRecordHeaderBytes) +
                              " of " + std::to_string(size) + " B)" + kept);
    }
    const uint8_t* bytes = p + PacketLogHeader::kRecordHeaderBytes;
    if (RecordCrc(d.source_id, d.arrival_ns, bytes, size) != crc) {
      return Status::DataLoss(where + ": checksum mismatch" + kept);
    }
    if (d.arrival_ns < last_arrival_ns) {
      return Status::DataLoss(where + ": arrival time before the previous record's" + kept);
    }
    last_arrival_ns = d.arrival_ns;
    d.bytes.assign(bytes, bytes + size);
    datagrams->push_back(std::move(d));
    offset += PacketLogHeader::kRecordHeaderBytes + size;
  }
  return Status::Ok();
}

}  // namespace swarmlio::net
