// A small MCAP writer (https://mcap.dev/spec): magic, Header, Schema and
// Channel records in the data section as they are added, messages in chunks
// ("" = uncompressed, "zstd" or "lz4" frame) each followed by its
// MessageIndex records, then DataEnd with the data-section CRC, a summary
// section (Schema, Channel, Statistics, ChunkIndex records), the Footer
// with the summary CRC, and the magic again.
#pragma once

#include <cstdint>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"

namespace swarmlio::io::internal {

struct McapWriterOptions {
  std::string profile = "ros2";
  std::string compression;                   // "", "zstd" or "lz4"
  uint64_t chunk_bytes = uint64_t{1} << 20;  // a chunk is closed past this many record bytes
};

class McapWriter {
 public:
  McapWriter() = default;
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// Creates (or truncates) `path` and writes the magic and Header.
  Status Open(const std::string& path, const McapWriterOptions& options);
  /// Adds a schema; *id is its id (from 1).
  Status AddSchema(const std::string& name,
                   const std::string& encoding,
                   const std::string& data,
                   uint16_t* id);
  /// Adds a channel of schema `schema_id`; *id is its id (from 0).
  Status AddChannel(uint16_t schema_id,
                    const std::string& topic,
                    const std::string& message_encoding,
                    uint16_t* id);
  Status WriteMessage(uint16_t channel_id, uint64_t log_time_ns, const std::vector<uint8_t>& data);
  /// Flushes the open chunk and writes DataEnd, summary and footer.
  Status Close();

 private:
  Status WriteRecord(uint8_t op, const std::vector<uint8_t>& content, bool data_section = true);
  Status FlushChunk();

  std::string path_;
  McapWriterOptions options_;
  std::ofstream file_;
  bool open_ = false;
  uint64_t offset_ = 0;                         // bytes written
  uint32_t data_crc_ = 0;                       // CRC of the data section so far
  std::vector<std::vector<uint8_t>> schemas_;   // Schema record contents
  std::vector<std::vector<uint8_t>> channels_;  // Channel record contents
  std::map<uint16_t, uint32_t> channel_sequence_;
  std::map<uint16_t, uint64_t> channel_counts_;
  // The open chunk: its records, times and per-channel (log time, offset).
  std::vector<uint8_t> chunk_records_;
  uint64_t chunk_start_ns_ = 0;
  uint64_t chunk_end_ns_ = 0;
  std::map<uint16_t, std::vector<std::pair<uint64_t, uint64_t>>> chunk_index_;
  std::vector<std::vector<uint8_t>> chunk_indexes_;  // ChunkIndex record contents
  uint64_t message_count_ = 0;
  uint64_t start_ns_ = 0;
  uint64_t end_ns_ = 0;
};

}  // namespace swarmlio::io::internal
