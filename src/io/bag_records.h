// Record-level access to a ROS1 bag file (format 2.0) without rosbag: the
// record layout (u32 header length, header fields "name=value", u32 data
// length, data), bounds-checked reads, and chunk decompression. Shared by
// the structural pre-check (bag_precheck.h) and the recovery scan of
// damaged bags (bag_recovery.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "src/io/ros_message_reader.h"
#include "swarmlio/common/status.h"

namespace swarmlio::io::internal {

inline constexpr char kBagMagic[] = "#ROSBAG V2.0\n";
inline constexpr size_t kBagMagicBytes = sizeof(kBagMagic) - 1;
inline constexpr char kBagVersionPrefix[] = "#ROSBAG V";
// Record header sizes we are willing to read (real ones are < 1 KiB).
inline constexpr uint32_t kMaxRecordHeaderBytes = 1u << 20;
// Record opcodes of the 2.0 format.
inline constexpr uint8_t kOpMessageData = 0x02;
inline constexpr uint8_t kOpFileHeader = 0x03;
inline constexpr uint8_t kOpIndexData = 0x04;
inline constexpr uint8_t kOpChunk = 0x05;
inline constexpr uint8_t kOpChunkInfo = 0x06;
inline constexpr uint8_t kOpConnection = 0x07;
// Bytes of one index-data entry: u32 sec, u32 nsec, u32 offset.
inline constexpr uint32_t kIndexEntryBytes = 12;
// Smallest record: u32 header length + u32 data length.
inline constexpr uint64_t kMinRecordBytes = 8;

using HeaderFields = std::map<std::string, std::string>;

/// Parses a record header (a sequence of u32-length-prefixed "name=value").
Status ParseHeaderFields(const uint8_t* data, size_t size, HeaderFields* fields);

/// Reads a little-endian integer header field of exactly sizeof(UInt) bytes.
template <class UInt>
Status GetField(const HeaderFields& fields,
                const std::string& name,
                const std::string& where,
                UInt* value) {
  const auto it = fields.find(name);
  if (it == fields.end() || it->second.size() != sizeof(UInt)) {
    return Status::DataLoss(where + ": missing or malformed header field '" + name + "'");
  }
  *value = LoadLittleEndian<UInt>(reinterpret_cast<const uint8_t*>(it->second.data()));
  return Status::Ok();
}

/// DataLoss unless the "op" field is `expected`.
Status CheckOp(const HeaderFields& fields, uint8_t expected, const std::string& where);

/// One record as stored: header fields and where its data lies.
struct Record {
  HeaderFields fields;
  uint64_t data_offset = 0;
  uint32_t data_bytes = 0;
  uint64_t end() const { return data_offset + data_bytes; }
};

/// Bounds-checked positional reads of a bag file.
class BagFile {
 public:
  BagFile(const std::string& path, uint64_t size);

  bool is_open() const { return file_.is_open(); }
  uint64_t size() const { return size_; }

  /// Reads `count` bytes at `offset`; false if the file ends first.
  bool Read(uint64_t offset, size_t count, std::vector<uint8_t>* bytes);
  /// The same into `bytes`, which has room for `count` (straight from the
  /// kernel into it for large reads).
  bool Read(uint64_t offset, size_t count, uint8_t* bytes);

  /// Reads the record at `offset`, which must end by `limit`.
  Status ReadRecord(uint64_t offset, uint64_t limit, const std::string& what, Record* record);

 private:
  std::ifstream file_;
  uint64_t size_;
  std::vector<uint8_t> bytes_;
};

/// Decompresses a chunk's stored bytes ("none", "lz4" or "bz2") into
/// `uncompressed_bytes` bytes; DataLoss if it does not decompress to exactly
/// that size.
Status DecompressChunk(const std::string& compression,
                       std::vector<uint8_t>* stored,
                       uint32_t uncompressed_bytes,
                       std::vector<uint8_t>* out);

/// DataLoss for a compression ratio no real chunk has (a corrupt size field,
/// which would otherwise be allocated), or an unknown compression.
Status CheckChunkSizes(const std::string& compression, uint64_t stored, uint64_t uncompressed);

}  // namespace swarmlio::io::internal
