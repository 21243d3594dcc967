#include "src/io/mcap_writer.h"

#include <algorithm>
#include <utility>

#include "src/io/crc32.h"
#include "src/io/mcap_compression.h"
#include "src/io/mcap_format.h"

namespace swarmlio::io::internal {
namespace {

template <class UInt>
void PutLe(std::vector<uint8_t>* out, UInt value) {
  for (size_t i = 0; i < sizeof(UInt); ++i) out->push_back(static_cast<uint8_t>(value >> (8 * i)));
}

void PutString(std::vector<uint8_t>* out, const std::string& value) {
  PutLe<uint32_t>(out, static_cast<uint32_t>(value.size()));
  out->insert(out->end(), value.begin(), value.end());
}

void PutRecord(std::vector<uint8_t>* out, uint8_t op, const std::vector<uint8_t>& content) {
  out->push_back(op);
  PutLe<uint64_t>(out, content.size());
  out->insert(out->end(), content.begin(), content.end());
}

}  // namespace

McapWriter::~McapWriter() {
  if (open_) static_cast<void>(Close());
}

Status McapWriter::Open(const std::string& path, const McapWriterOptions& options) {
  if (!IsSupportedMcapCompression(options.compression)) {
    return Status::InvalidArgument("MCAP compression '" + options.compression +
                                   "' is not one of none, zstd, lz4");
  }
  path_ = path;
  options_ = options;
  file_.open(path, std::ios::binary | std::ios::trunc);
  if (!file_.is_open()) return Status::IoError("bag '" + path + "': cannot open for writing");
  open_ = true;
  file_.write(reinterpret_cast<const char*>(kMcapMagic), kMcapMagicBytes);
  offset_ = kMcapMagicBytes;
  data_crc_ = Crc32(kMcapMagic, kMcapMagicBytes);
  std::vector<uint8_t> header;
  PutString(&header, options_.profile);
  PutString(&header, "swarmlio");
  return WriteRecord(kMcapHeader, header);
}

Status McapWriter::WriteRecord(uint8_t op, const std::vector<uint8_t>& content, bool data_section) {
  std::vector<uint8_t> bytes;
  bytes.reserve(content.size() + kMcapRecordPrefixBytes);
  PutRecord(&bytes, op, content);
  file_.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
  if (!file_.good()) return Status::IoError("bag '" + path_ + "': write failed");
  offset_ += bytes.size();
  if (data_section) data_crc_ = Crc32(bytes.data(), bytes.size(), data_crc_);
  return Status::Ok();
}

Status McapWriter::AddSchema(const std::string& name,
                             const std::string& encoding,
                             const std::string& data,
                             uint16_t* id) {
  if (!open_) return Status::FailedPrecondition("bag '" + path_ + "': writer is closed");
  *id = static_cast<uint16_t>(schemas_.size() + 1);
  std::vector<uint8_t> content;
  PutLe<uint16_t>(&content, *id);
  PutString(&content, name);
  PutString(&content, encoding);
  PutString(&content, data);
  schemas_.push_back(content);
  return WriteRecord(kMcapSchema, content);
}

Status McapWriter::AddChannel(uint16_t schema_id,
                              const std::string& topic,
                              const std::string& message_encoding,
                              uint16_t* id) {
  if (!open_) return Status::FailedPrecondition("bag '" + path_ + "': writer is closed");
  *id = static_cast<uint16_t>(channels_.size());
  std::vector<uint8_t> content;
  PutLe<uint16_t>(&content, *id);
  PutLe<uint16_t>(&content, schema_id);
  PutString(&content, topic);
  PutString(&content, message_encoding);
  PutLe<uint32_t>(&content, 0);  // no metadata
  channels_.push_back(content);
  channel_sequence_[*id] = 0;
  channel_counts_[*id] = 0;
  return WriteRecord(kMcapChannel, content);
}

Status McapWriter::WriteMessage(uint16_t channel_id,
                                uint64_t log_time_ns,
                                const std::vector<uint8_t>& data) {
  if (!open_) return Status::FailedPrecondition("bag '" + path_ + "': writer is closed");
  if (channel_id >= channels_.size()) {
    return Status::InvalidArgument("bag '" + path_ + "': no channel " + std::to_string(channel_id));
  }
  if (chunk_records_.empty()) chunk_start_ns_ = chunk_end_ns_ = log_time_ns;
  chunk_start_ns_ = std::min(chunk_start_ns_, log_time_ns);
  chunk_end_ns_ = std::max(chunk_end_ns_, log_time_ns);
  if (message_count_ == 0) start_ns_ = end_ns_ = log_time_ns;
  start_ns_ = std::min(start_ns_, log_time_ns);
  end_ns_ = std::max(end_ns_, log_time_ns);
  ++message_count_;
  ++channel_counts_[channel_id];
  chunk_index_[channel_id].emplace_back(log_time_ns, chunk_records_.size());
  chunk_records_.push_back(kMcapMessage);
  PutLe<uint64_t>(&chunk_records_, kMcapMessageHeaderBytes + data.size());
  PutLe<uint16_t>(&chunk_records_, channel_id);
  PutLe<uint32_t>(&chunk_records_, channel_sequence_[channel_id]++);
  PutLe<uint64_t>(&chunk_records_, log_time_ns);  // log time
  PutLe<uint64_t>(&chunk_records_, log_time_ns);  // publish time
  chunk_records_.insert(chunk_records_.end(), data.begin(), data.end());
  if (chunk_records_.size() >= options_.chunk_bytes) return FlushChunk();
  return Status::Ok();
}

Status McapWriter::FlushChunk() {
  if (chunk_records_.empty()) return Status::Ok();
  std::vector<uint8_t> stored;
  SWARMLIO_RETURN_IF_ERROR(CompressMcapChunk(options_.compression, chunk_records_.data(),
                                             chunk_records_.size(), &stored));
  std::vector<uint8_t> chunk;
  PutLe<uint64_t>(&chunk, chunk_start_ns_);
  PutLe<uint64_t>(&chunk, chunk_end_ns_);
  PutLe<uint64_t>(&chunk, chunk_records_.size());
  PutLe<uint32_t>(&chunk, Crc32(chunk_records_.data(), chunk_records_.size()));
  PutString(&chunk, options_.compression);
  PutLe<uint64_t>(&chunk, stored.size());
  chunk.insert(chunk.end(), stored.begin(), stored.end());
  const uint64_t chunk_offset = offset_;
  SWARMLIO_RETURN_IF_ERROR(WriteRecord(kMcapChunk, chunk));
  const uint64_t chunk_length = offset_ - chunk_offset;
  std::vector<uint8_t> index_offsets;
  for (const auto& [channel, entries] : chunk_index_) {
    PutLe<uint16_t>(&index_offsets, channel);
    PutLe<uint64_t>(&index_offsets, offset_);
    std::vector<uint8_t> index;
    PutLe<uint16_t>(&index, channel);
    PutLe<uint32_t>(&index, static_cast<uint32_t>(entries.size() * 16));
    for (const auto& [time, at] : entries) {
      PutLe<uint64_t>(&index, time);
      PutLe<uint64_t>(&index, at);
    }
    SWARMLIO_RETURN_IF_ERROR(WriteRecord(kMcapMessageIndex, index));
  }
  std::vector<uint8_t> chunk_index;
  PutLe<uint64_t>(&chunk_index, chunk_start_ns_);
  PutLe<uint64_t>(&chunk_index, chunk_end_ns_);
  PutLe<uint64_t>(&chunk_index, chunk_offset);
  PutLe<uint64_t>(&chunk_index, chunk_length);
  PutLe<uint32_t>(&chunk_index, static_cast<uint32_t>(index_offsets.size()));
  chunk_index.insert(chunk_index.end(), index_offsets.begin(), index_offsets.end());
  PutLe<uint64_t>(&chunk_index, offset_ - chunk_offset - chunk_length);  // message index bytes
  PutString(&chunk_index, options_.compression);
  PutLe<uint64_t>(&chunk_index, stored.size());
  PutLe<uint64_t>(&chunk_index, chunk_records_.size());
  chunk_indexes_.push_back(std::move(chunk_index));
  chunk_records_.clear();
  chunk_index_.clear();
  return Status::Ok();
}

Status McapWriter::Close() {
  if (!open_) return Status::Ok();
  SWARMLIO_RETURN_IF_ERROR(FlushChunk());
  open_ = false;
  std::vector<uint8_t> data_end;
  PutLe<uint32_t>(&data_end, data_crc_);
  SWARMLIO_RETURN_IF_ERROR(WriteRecord(kMcapDataEnd, data_end, /*data_section=*/false));
  const uint64_t summary_start = offset_;
  std::vector<uint8_t> summary;
  for (const std::vector<uint8_t>& schema : schemas_) PutRecord(&summary, kMcapSchema, schema);
  for (const std::vector<uint8_t>& channel : channels_) PutRecord(&summary, kMcapChannel, channel);
  std::vector<uint8_t> statistics;
  PutLe<uint64_t>(&statistics, message_count_);
  PutLe<uint16_t>(&statistics, static_cast<uint16_t>(schemas_.size()));
  PutLe<uint32_t>(&statistics, static_cast<uint32_t>(channels_.size()));
  PutLe<uint32_t>(&statistics, 0);  // attachments
  PutLe<uint32_t>(&statistics, 0);  // metadata
  PutLe<uint32_t>(&statistics, static_cast<uint32_t>(chunk_indexes_.size()));
  PutLe<uint64_t>(&statistics, start_ns_);
  PutLe<uint64_t>(&statistics, end_ns_);
  PutLe<uint32_t>(&statistics, static_cast<uint32_t>(channel_counts_.size() * 10));
  for (const auto& [channel, count] : channel_counts_) {
    PutLe<uint16_t>(&statistics, channel);
    PutLe<uint64_t>(&statistics, count);
  }
  PutRecord(&summary, kMcapStatistics, statistics);
  for (const std::vector<uint8_t>& index : chunk_indexes_) {
    PutRecord(&summary, kMcapChunkIndex, index);
  }
  // Footer: summary_start, summary_offset_start (0: no summary offsets),
  // and the CRC of the summary section through summary_offset_start.
  summary.push_back(kMcapFooter);
  PutLe<uint64_t>(&summary, 20);
  PutLe<uint64_t>(&summary, summary_start);
  PutLe<uint64_t>(&summary, 0);
  PutLe<uint32_t>(&summary, Crc32(summary.data(), summary.size()));
  summary.insert(summary.end(), kMcapMagic, kMcapMagic + kMcapMagicBytes);
  file_.write(reinterpret_cast<const char*>(summary.data()),
              static_cast<std::streamsize>(summary.size()));
  file_.close();
  if (!file_) return Status::IoError("bag '" + path_ + "': write failed on close");
  return Status::Ok();
}

}  // namespace swarmlio::io::internal
