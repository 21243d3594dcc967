#include "src/io/bag_precheck.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "src/io/bag_records.h"

namespace swarmlio::io::internal {
namespace {

class BagChecker {
 public:
  BagChecker(BagFile* file, const BagPrecheckOptions& options, BagPrecheckResult* result)
      : file_(file), options_(options), result_(result) {}

  Status Run() {
    std::vector<uint8_t> magic;
    if (file_->size() < kBagMagicBytes || !file_->Read(0, kBagMagicBytes, &magic)) {
      return Status::DataLoss("not a ROS1 bag: file is too short (" +
                              std::to_string(file_->size()) + " bytes)");
    }
    const std::string line(magic.begin(), magic.end());
    if (line != kBagMagic) {
      if (line.rfind(kBagVersionPrefix, 0) == 0) return Status::Ok();  // rosbag's job
      return Status::DataLoss("not a ROS1 bag: no '#ROSBAG V2.0' line at the start");
    }
    SWARMLIO_RETURN_IF_ERROR(CheckFileHeader());
    // From here on the file header is intact: a missing or broken index
    // leaves the records scannable (bag_recovery.h).
    const Status index = CheckIndexSection();
    if (!index.ok()) {
      result_->index_damaged = true;
      return index;
    }
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
    SWARMLIO_RETURN_IF_ERROR(file_->ReadRecord(kBagMagicBytes, file_->size(), where, &record));
    SWARMLIO_RETURN_IF_ERROR(CheckOp(record.fields, kOpFileHeader, where));
    SWARMLIO_RETURN_IF_ERROR(GetField(record.fields, "index_pos", where, &index_pos_));
    SWARMLIO_RETURN_IF_ERROR(GetField(record.fields, "conn_count", where, &conn_count_));
    SWARMLIO_RETURN_IF_ERROR(GetField(record.fields, "chunk_count", where, &chunk_count_));
    first_record_ = record.end();
    if (index_pos_ == 0) {
      result_->index_damaged = true;
      return Status::DataLoss(
          "bag is not indexed (recording interrupted?); `rosbag reindex` can repair it");
    }
    if (index_pos_ < first_record_ || index_pos_ > file_->size()) {
      result_->index_damaged = true;
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
    SWARMLIO_RETURN_IF_ERROR(
        CheckChunkSizes(compression->second, chunk.data_bytes, uncompressed_bytes));

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
    return DecompressChunk(compression, &bytes_, size, &chunk_);
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
  BagPrecheckResult* result_;
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

Status PrecheckBagFile(const std::string& path,
                       const BagPrecheckOptions& options,
                       BagPrecheckResult* result) {
  BagPrecheckResult unused;
  if (result == nullptr) result = &unused;
  *result = BagPrecheckResult();
  std::error_code ec;
  const uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) return Status::IoError("bag '" + path + "': cannot get the file size: " + ec.message());
  BagFile file(path, size);
  if (!file.is_open()) return Status::IoError("bag '" + path + "': cannot open the file");
  return BagChecker(&file, options, result).Run().WithContext("bag '" + path + "'");
}

}  // namespace swarmlio::io::internal
