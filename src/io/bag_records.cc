#include "src/io/bag_records.h"

#include <bzlib.h>
#include <roslz4/lz4s.h>

namespace swarmlio::io::internal {

Status ParseHeaderFields(const uint8_t* data, size_t size, HeaderFields* fields) {
  fields->clear();
  RosMessageReader reader(data, size);
  while (reader.remaining() > 0) {
    std::string field;
    SWARMLIO_RETURN_IF_ERROR(reader.ReadString("record header field", &field));
    const size_t equals = field.find('=');
    if (equals == std::string::npos) return Status::DataLoss("record header field without '='");
    (*fields)[field.substr(0, equals)] = field.substr(equals + 1);
  }
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

BagFile::BagFile(const std::string& path, uint64_t size)
    : file_(path, std::ios::binary), size_(size) {}

bool BagFile::Read(uint64_t offset, size_t count, std::vector<uint8_t>* bytes) {
  bytes->resize(count);
  return Read(offset, count, bytes->data());
}

bool BagFile::Read(uint64_t offset, size_t count, uint8_t* bytes) {
  if (count == 0) return true;
  if (offset > size_ || count > size_ - offset) return false;
  file_.clear();
  file_.seekg(static_cast<std::streamoff>(offset));
  file_.read(reinterpret_cast<char*>(bytes), static_cast<std::streamsize>(count));
  return static_cast<size_t>(file_.gcount()) == count;
}

Status BagFile::ReadRecord(uint64_t offset,
                           uint64_t limit,
                           const std::string& what,
                           Record* record) {
  const std::string where = what + " at offset " + std::to_string(offset);
  if (offset + 4 > limit || !Read(offset, 4, &bytes_)) {
    return Status::DataLoss(where + " is cut off (truncated or corrupt file of " +
                            std::to_string(size_) + " bytes)");
  }
  const uint32_t header_bytes = LoadLittleEndian<uint32_t>(bytes_.data());
  if (header_bytes > kMaxRecordHeaderBytes || offset + 4 + header_bytes + 4 > limit) {
    return Status::DataLoss(where + " claims a " + std::to_string(header_bytes) +
                            "-byte header, which does not fit (file has " + std::to_string(size_) +
                            " bytes)");
  }
  if (!Read(offset + 4, header_bytes + 4, &bytes_)) {
    return Status::IoError(where + ": read failed");
  }
  SWARMLIO_RETURN_IF_ERROR(
      ParseHeaderFields(bytes_.data(), header_bytes, &record->fields).WithContext(where));
  record->data_bytes = LoadLittleEndian<uint32_t>(bytes_.data() + header_bytes);
  record->data_offset = offset + 4 + header_bytes + 4;
  if (record->end() > limit) {
    return Status::DataLoss(where + " claims " + std::to_string(record->data_bytes) +
                            " data bytes, but only " + std::to_string(limit - record->data_offset) +
                            " remain (truncated or corrupt file)");
  }
  return Status::Ok();
}

Status CheckChunkSizes(const std::string& compression, uint64_t stored, uint64_t uncompressed) {
  if (compression == "none") {
    if (uncompressed != stored) {
      return Status::DataLoss("size " + std::to_string(uncompressed) + " != stored bytes " +
                              std::to_string(stored));
    }
    return Status::Ok();
  }
  if (compression == "lz4" || compression == "bz2") {
    // Compression ratios beyond these mean a corrupt size field.
    const uint64_t max_ratio = compression == "lz4" ? 256 : 4096;
    if (uncompressed > stored * max_ratio + (1u << 16)) {
      return Status::DataLoss("implausible uncompressed size " + std::to_string(uncompressed) +
                              " for " + std::to_string(stored) + " " + compression + " bytes");
    }
    return Status::Ok();
  }
  return Status::DataLoss("unknown compression '" + compression + "'");
}

Status DecompressChunk(const std::string& compression,
                       std::vector<uint8_t>* stored,
                       uint32_t uncompressed_bytes,
                       std::vector<uint8_t>* out) {
  if (compression == "none") {
    out->swap(*stored);
    if (out->size() != uncompressed_bytes) {
      return Status::DataLoss("uncompressed chunk holds " + std::to_string(out->size()) +
                              " bytes, its header says " + std::to_string(uncompressed_bytes));
    }
    return Status::Ok();
  }
  if (uncompressed_bytes == 0 || stored->empty()) {
    return Status::DataLoss("empty " + compression + " chunk");
  }
  out->resize(uncompressed_bytes);
  unsigned int out_bytes = uncompressed_bytes;
  char* in = reinterpret_cast<char*>(stored->data());
  char* dst = reinterpret_cast<char*>(out->data());
  const unsigned int in_bytes = static_cast<unsigned int>(stored->size());
  int result = 0;
  bool ok = false;
  if (compression == "lz4") {
    result = roslz4_buffToBuffDecompress(in, in_bytes, dst, &out_bytes);
    ok = result == ROSLZ4_OK;
  } else if (compression == "bz2") {
    result = BZ2_bzBuffToBuffDecompress(dst, &out_bytes, in, in_bytes, 0, 0);
    ok = result == BZ_OK;
  } else {
    return Status::DataLoss("unknown compression '" + compression + "'");
  }
  if (!ok || out_bytes != uncompressed_bytes) {
    return Status::DataLoss(compression + " chunk does not decompress to its " +
                            std::to_string(uncompressed_bytes) + " bytes (error " +
                            std::to_string(result) + ")");
  }
  return Status::Ok();
}

}  // namespace swarmlio::io::internal
