// Packet log: every datagram one drone received (raw bytes, transport source
// id, arrival time on the drone's sensor time line), written by the live
// process (`<name>_received.bin`, docs/online.md) and read back by the
// offline replay to re-run that drone with exactly that network history.
//
// File layout (little-endian):
//   header (24 B): magic "SWLIOPKT" | u32 version (1) | i32 self_id |
//                  i64 sensor_start_ns (the playback start on the sensor time line)
//   records:       u32 size | i32 source_id | i64 arrival_ns |
//                  u32 crc32 (of source_id, arrival_ns and the bytes) | bytes[size]
// A record's size is in [1, kMaxPacketBytes]; arrival times never decrease.
//
// Reading checks everything: a bad magic or version is an error; a
// truncated or corrupt record (bad size, checksum, or decreasing arrival)
// stops the read with DataLoss naming the file, the record index and its
// byte offset, and the complete records before it are kept.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/net/transport.h"

namespace swarmlio::net {

struct PacketLogHeader {
  static constexpr char kMagic[9] = "SWLIOPKT";
  static constexpr uint32_t kVersion = 1;
  static constexpr size_t kHeaderBytes = 24;
  static constexpr size_t kRecordHeaderBytes = 20;

  int self_id = -1;             // the receiving drone's id
  int64_t sensor_start_ns = 0;  // playback start on the sensor time line [ns]
};

class PacketLogWriter {
 public:
  /// Creates (truncates) `path` and writes the header. IoError naming the file.
  static Status Open(const std::string& path, const PacketLogHeader& header,
                     std::unique_ptr<PacketLogWriter>* writer);
  ~PacketLogWriter();
  PacketLogWriter(const PacketLogWriter&) = delete;
  PacketLogWriter& operator=(const PacketLogWriter&) = delete;

  /// Appends one record. InvalidArgument for an empty or oversized datagram
  /// or an arrival before the previous one; IoError when the write fails.
  Status Append(const Datagram& datagram);
  /// Hands the buffered records to the operating system.
  Status Flush();
  /// Flushes and closes (also done by the destructor, errors then ignored).
  Status Close();

  int64_t records() const { return records_; }
  int64_t bytes_written() const { return bytes_written_; }
  const std::string& path() const { return path_; }

 private:
  PacketLogWriter(std::string path, std::FILE* file) : path_(std::move(path)), file_(file) {}

  std::string path_;
  std::FILE* file_;
  int64_t records_ = 0;
  int64_t bytes_written_ = 0;
  int64_t last_arrival_ns_ = std::numeric_limits<int64_t>::min();
};

/// Reads a whole packet log. `*datagrams` is replaced by the complete
/// records (also when an error is returned: everything before the damage).
/// IoError (cannot open), InvalidArgument (bad magic, unsupported version),
/// DataLoss (truncated or corrupt record), each naming `path`.
Status ReadPacketLog(const std::string& path, PacketLogHeader* header,
                     std::vector<Datagram>* datagrams);

/// CRC-32 (IEEE 802.3, reflected, as zlib's crc32) of `size` bytes, continued from `crc`.
uint32_t Crc32(const uint8_t* data, size_t size, uint32_t crc = 0);

}  // namespace swarmlio::net
