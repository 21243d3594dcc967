#include "src/io/bag_precheck.h"

#include <bzlib.h>
#include <roslz4/lz4s.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <system_error>
#include <vector>

#include "src/io/wire_reader.h"

namespace swarmlio::io::internal {
namespace {

constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr size_t kMagicBytes = sizeof(kMagic) - 1;
constexpr char kVersionPrefix[] = "#ROSBAG V";
// Record header sizes we are willing to read (real ones are < 1 KiB).
constexpr uint32_t kMaxRecordHeaderBytes = 1u << 20;
// Record opcodes of the 2.0 format.
constexpr uint8_t kOpMessageData = 0x02;
constexpr uint8_t kOpFileHeader = 0x03;
constexpr uint8_t kOpIndexData = 0x04;
constexpr uint8_t kOpChunk = 0x05;
constexpr uint8_t kOpChunkInfo = 0x06;
constexpr uint8_t kOpConnection = 0x07;
// Bytes of one index-data entry: u32 sec, u32 nsec, u32 offset.
constexpr uint32_t kIndexEntryBytes = 12;
// Smallest record: u32 header length + u32 data length.
constexpr uint64_t kMinRecordBytes = 8;

using HeaderFields = std::map<std::string, std::string>;

Status ParseHeaderFields(const uint8_t* data, size_t size, HeaderFields* fields) {
  fields->clear();
  WireReader reader(data, size);
  while (reader.remaining() > 0) {
    std::string field;
    SWARMLIO_RETURN_IF_ERROR(reader.ReadString("record header field", &field));
    const size_t equals = field.find('=');
    if (equals == std::string::npos) return Status::DataLoss("record header field without '='");
    (*fields)[field.substr(0, equals)] = field.substr(equals + 1);
  }
  return Status::Ok();
}

// Reads a little-endian integer header field of exactly sizeof(UInt) bytes.
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

Status CheckOp(const HeaderFields& fields, uint8_t expected, const std::string& where) {
  uint8_t op = 0;
  SWARMLIO_RETURN_IF_ERROR(GetField(fields, "op", where, &op));
  if (op != expected) {
    return Status::DataLoss(where + ": record type " + std::to_string(op) + ", expected " +
                            std::to_string(expected));
  }
  return Status::Ok();
}

// One record as stored: header fields and where its data lies.
struct Record {
  HeaderFields fields;
  uint64_t data_offset = 0;
  uint32_t data_bytes = 0;
  uint64_t end() const { return data_offset + data_bytes; }
};

class BagFile {
 public:
  BagFile(const std::string& path, uint64_t size) : file_(path, std::ios::binary), size_(size) {}

  bool is_open() const { return file_.is_open(); }
  uint64_t size() const { return size_; }

  bool Read(uint64_t offset, size_t count, std::vector<uint8_t>* bytes) {
    bytes->resize(count);
    if (count == 0) return true;
    file_.clear();
    file_.seekg(static_cast<std::streamoff>(offset));
    file_.read(reinterpret_cast<char*>(bytes->data()), static_cast<std::streamsize>(count));
    return static_cast<size_t>(file_.gcount()) == count;
  }

  // Reads the record at `offset`, which must end by `limit`.
  Status ReadRecord(uint64_t offset, uint64_t limit, const std::string& what, Record* record) {
    const std::string where = what + " at offset " + std::to_string(offset);
    if (offset + 4 > limit || !Read(offset, 4, &bytes_)) {
      return Status::DataLoss(where + " is cut off (truncated or corrupt file of " +
                              std::to_string(size_) + " bytes)");
    }
    const uint32_t header_bytes = LoadLittleEndian<uint32_t>(bytes_.data());
    if (header_bytes > kMaxRecordHeaderBytes || offset + 4 + header_bytes + 4 > limit) {
      return Status::DataLoss(where + " claims a " + std::to_string(header_bytes) +
                              "-byte header, which does not fit (file has " +
                              std::to_string(size_) + " bytes)");
    }
    if (!Read(offset + 4, header_bytes + 4, &bytes_)) {
      return Status::IoError(where + ": read failed");
    }
    SWARMLIO_RETURN_IF_ERROR(
        ParseHeaderFields(bytes_.data(), header_bytes, &record->fields).WithContext(where));
    record->data_bytes = LoadLittleEndian<uint32_t>(bytes_.data() + header_bytes);
    record->data_offset = offset + 4 + header_bytes + 4;
    if (record->end() > limit) {
      return Status::DataLoss(
          where + " claims " + std::to_string(record->data_bytes) + " data bytes, but only " +
          std::to_string(limit - record->data_offset) + " remain (truncated or corrupt file)");
    }
    return Status::Ok();
  }

 private:
  std::ifstream file_;
  uint64_t size_;
  std::vector<uint8_t> bytes_;
};

class BagChecker {
 public:
  BagChecker(BagFile* file, const BagPrecheckOptions& options) : file_(file), options_(options) {}

  Status Run() {
    std::vector<uint8_t> magic;
    if (file_->size() < kMagicBytes || !file_->Read(0, kMagicBytes, &magic)) {
      return Status::DataLoss("not a ROS1 bag: file is too short (" +
                              std::to_string(file_->size()) + " bytes)");
    }
    const std::string line(magic.begin(), magic.end());
    if (line != kMagic) {
      if (line.rfind(kVersionPrefix, 0) == 0) return Status::Ok();  // rosbag's job
      return Status::DataLoss("not a ROS1 bag: no '#ROSBAG V2.0' line at the start");
    }
    SWARMLIO_RETURN_IF_ERROR(CheckFileHeader());
    SWARMLIO_RETURN_IF_ERROR(CheckIndexSection());
    std::sort(chunk_positions_.begin(), chunk_positions_.end());
    for (size_t i = 0; i < chunk_positions_.size(); ++i) {
      const uint64_t limit = i + 1 < chunk_positions_.size() ? chunk_positions_[i + 1] : index_pos_;
      SWARMLIO_RETURN_IF_ERROR(
          CheckChunk(chunk_positions_[i], limit)
              .WithContext("chunk at offset " + std::to_string(chunk_positions_[i])));
    }
    return Status::Ok();
  }

 private:
  Status CheckFileHeader() {
    Record record;
    const std::string where = "file header record";
    SWARMLIO_RETURN_IF_ERROR(file_->ReadRecord(kMagicBytes, file_->size(), where, &record));
    SWARMLIO_RETURN_IF_ERROR(CheckOp(record.fields, kOpFileHeader, where));
    SWARMLIO_RETURN_IF_ERROR(GetField(record.fields, "index_pos", where, &index_pos_));
    SWARMLIO_RETURN_IF_ERROR(GetField(record.fields, "conn_count", where, &conn_count_));
    SWARMLIO_RETURN_IF_ERROR(GetField(record.fields, "chunk_count", where, &chunk_count_));
    first_record_ = record.end();
    if (index_pos_ == 0) {
      return Status::DataLoss(
          "bag is not indexed (recording interrupted?); `rosbag reindex` can repair it");
    }
    if (index_pos_ < first_record_ || index_pos_ > file_->size()) {
      return Status::DataLoss("bag is truncated: its index starts at offset " +
                              std::to_string(index_pos_) + " but the file has " +
                              std::to_string(file_->size()) + " bytes");
    }
    return Status::Ok();
  }

  // Connection and chunk-info records from index_pos to the end of file.
  Status CheckIndexSection() {
    uint32_t connections = 0;
    Record record;
    for (uint64_t pos = index_pos_; pos < file_->size(); pos = record.end()) {
      SWARMLIO_RETURN_IF_ERROR(file_->ReadRecord(pos, file_->size(), "index record", &record));
      uint8_t op = 0;
      SWARMLIO_RETURN_IF_ERROR(GetField(record.fields, "op", "index record", &op));
      const std::string where = "index record at offset " + std::to_string(pos);
      if (op == kOpConnection) {
        // The data is the connection header, itself a list of header fields.
        if (!file_->Read(record.data_offset, record.data_bytes, &bytes_)) {
          return Status::IoError(where + ": read failed");
        }
        SWARMLIO_RETURN_IF_ERROR(ParseHeaderFields(bytes_.data(), bytes_.size(), &fields_)
                                     .WithContext(where + " (connection header)"));
        ++connections;
      } else if (op == kOpChunkInfo) {
        uint64_t chunk_pos = 0;
        uint32_t count = 0;
        SWARMLIO_RETURN_IF_ERROR(GetField(record.fields, "chunk_pos", where, &chunk_pos));
        SWARMLIO_RETURN_IF_ERROR(GetField(record.fields, "count", where, &count));
        if (chunk_pos < first_record_ || chunk_pos >= index_pos_) {
          return Status::DataLoss(where + ": chunk position outside the data section");
        }
        if (static_cast<uint64_t>(count) * 8 != record.data_bytes) {
          return Status::DataLoss(where + ": chunk info count " + std::to_string(count) +
                                  " does not match " + std::to_string(record.data_bytes) +
                                  " data bytes");
        }
        chunk_positions_.push_back(chunk_pos);
      } else {
        return Status::DataLoss("unexpected record type " + std::to_string(op) +
                                " in the index section at offset " + std::to_string(pos));
      }
    }
    if (connections != conn_count_ || chunk_positions_.size() != chunk_count_) {
      return Status::DataLoss("index section lists " + std::to_string(connections) +
                              " connections and " + std::to_string(chunk_positions_.size()) +
                              " chunks, the file header says " + std::to_string(conn_count_) +
                              " and " + std::to_string(chunk_count_) +
                              " (truncated or corrupt file)");
    }
    return Status::Ok();
  }

  // The chunk record at `pos` and its index-data records, all before `limit`.
  Status CheckChunk(uint64_t pos, uint64_t limit) {
    Record chunk;
    SWARMLIO_RETURN_IF_ERROR(file_->ReadRecord(pos, limit, "chunk record", &chunk));
    SWARMLIO_RETURN_IF_ERROR(CheckOp(chunk.fields, kOpChunk, "chunk record"));
    uint32_t uncompressed_bytes = 0;
    SWARMLIO_RETURN_IF_ERROR(GetField(chunk.fields, "size", "chunk record", &uncompressed_bytes));
    const auto compression = chunk.fields.find("compression");
    if (compression == chunk.fields.end()) return Status::DataLoss("no compression field");
    // Compression ratios beyond these mean a corrupt size field (which rosbag
    // would allocate).
    const uint64_t compressed = chunk.data_bytes;
    if (compression->second == "none") {
      if (uncompressed_bytes != compressed) {
        return Status::DataLoss("size " + std::to_string(uncompressed_bytes) + " != stored bytes " +
                                std::to_string(compressed));
      }
    } else if (compression->second == "lz4" || compression->second == "bz2") {
      const uint64_t max_ratio = compression->second == "lz4" ? 256 : 4096;
      if (uncompressed_bytes > compressed * max_ratio + (1u << 16)) {
        return Status::DataLoss("implausible uncompressed size " +
                                std::to_string(uncompressed_bytes) + " for " +
                                std::to_string(compressed) + " " + compression->second + " bytes");
      }
    } else {
      return Status::DataLoss("unknown compression '" + compression->second + "'");
    }

    // Index data records: message offsets inside the uncompressed chunk.
    offsets_.clear();
    Record index;
    for (uint64_t at = chunk.end(); at < limit; at = index.end()) {
      SWARMLIO_RETURN_IF_ERROR(file_->ReadRecord(at, limit, "index data record", &index));
      const std::string where = "index data record at offset " + std::to_string(at);
      SWARMLIO_RETURN_IF_ERROR(CheckOp(index.fields, kOpIndexData, where));
      uint32_t count = 0;
      SWARMLIO_RETURN_IF_ERROR(GetField(index.fields, "count", where, &count));
      if (static_cast<uint64_t>(count) * kIndexEntryBytes != index.data_bytes) {
        return Status::DataLoss(where + ": count " + std::to_string(count) + " does not match " +
                                std::to_string(index.data_bytes) + " data bytes");
      }
      if (!file_->Read(index.data_offset, index.data_bytes, &bytes_)) {
        return Status::IoError(where + ": read failed");
      }
      for (uint32_t i = 0; i < count; ++i) {
        const uint32_t offset = LoadLittleEndian<uint32_t>(bytes_.data() + i * 12 + 8);
        if (offset + kMinRecordBytes > uncompressed_bytes) {
          return Status::DataLoss(where + ": message offset " + std::to_string(offset) +
                                  " lies outside the " + std::to_string(uncompressed_bytes) +
                                  "-byte chunk");
        }
        offsets_.push_back(offset);
      }
    }
    if (!options_.verify_chunk_records) return Status::Ok();
    SWARMLIO_RETURN_IF_ERROR(LoadChunk(chunk, compression->second, uncompressed_bytes));
    for (uint32_t offset : offsets_) SWARMLIO_RETURN_IF_ERROR(CheckMessageRecord(offset));
    return Status::Ok();
  }

  // Reads (and decompresses) a chunk's content into chunk_.
  Status LoadChunk(const Record& chunk, const std::string& compression, uint32_t size) {
    if (!file_->Read(chunk.data_offset, chunk.data_bytes, &bytes_)) {
      return Status::IoError("chunk data: read failed");
    }
    if (compression == "none") {
      chunk_.swap(bytes_);
      return Status::Ok();
    }
    chunk_.resize(size);
    unsigned int out_bytes = size;
    char* in = reinterpret_cast<char*>(bytes_.data());
    char* out = reinterpret_cast<char*>(chunk_.data());
    const unsigned int in_bytes = static_cast<unsigned int>(bytes_.size());
    int result = 0;
    bool ok = false;
    if (compression == "lz4") {
      result = roslz4_buffToBuffDecompress(in, in_bytes, out, &out_bytes);
      ok = result == ROSLZ4_OK;
    } else {
      result = BZ2_bzBuffToBuffDecompress(out, &out_bytes, in, in_bytes, 0, 0);
      ok = result == BZ_OK;
    }
    if (!ok || out_bytes != size) {
      return Status::DataLoss(compression + " chunk does not decompress to its " +
                              std::to_string(size) + " bytes (error " + std::to_string(result) +
                              ")");
    }
    return Status::Ok();
  }

  Status CheckMessageRecord(uint32_t offset) {
    const std::string where = "message record at chunk offset " + std::to_string(offset);
    const uint64_t size = chunk_.size();
    const uint8_t* start = chunk_.data() + offset;  // offset + 8 <= size (checked)
    const uint32_t header_bytes = LoadLittleEndian<uint32_t>(start);
    if (offset + 4 + static_cast<uint64_t>(header_bytes) + 4 > size) {
      return Status::DataLoss(where + ": header length " + std::to_string(header_bytes) +
                              " runs past the chunk");
    }
    SWARMLIO_RETURN_IF_ERROR(
        ParseHeaderFields(start + 4, header_bytes, &fields_).WithContext(where));
    SWARMLIO_RETURN_IF_ERROR(CheckOp(fields_, kOpMessageData, where));
    const uint32_t data_bytes = LoadLittleEndian<uint32_t>(start + 4 + header_bytes);
    if (offset + 4 + static_cast<uint64_t>(header_bytes) + 4 + data_bytes > size) {
      return Status::DataLoss(where + ": data length " + std::to_string(data_bytes) +
                              " runs past the chunk");
    }
    return Status::Ok();
  }

  BagFile* file_;
  BagPrecheckOptions options_;
  uint64_t index_pos_ = 0;
  uint32_t conn_count_ = 0;
  uint32_t chunk_count_ = 0;
  uint64_t first_record_ = 0;
  std::vector<uint64_t> chunk_positions_;
  std::vector<uint32_t> offsets_;
  std::vector<uint8_t> bytes_;
  std::vector<uint8_t> chunk_;
  HeaderFields fields_;
};

}  // namespace

Status PrecheckBagFile(const std::string& path, const BagPrecheckOptions& options) {
  std::error_code ec;
  const uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) return Status::IoError("bag '" + path + "': cannot get the file size: " + ec.message());
  BagFile file(path, size);
  if (!file.is_open()) return Status::IoError("bag '" + path + "': cannot open the file");
  return BagChecker(&file, options).Run().WithContext("bag '" + path + "'");
}

}  // namespace swarmlio::io::internal
