#include "src/io/mcap_scan.h"

#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <limits>
#include <system_error>
#include <utility>

#include "src/io/crc32.h"
#include "src/io/mcap_compression.h"
#include "src/io/mcap_format.h"
#include "src/io/ros_message_reader.h"

namespace swarmlio::io::internal {
namespace {

// Chunks McapChunkCache keeps: the topic streams of one file (IMU, lidar,
// ground truth) are within a chunk or two of each other.
constexpr size_t kKeptMcapChunks = 4;

struct McapSchema {
  std::string name;
  std::string encoding;
};

std::string Hex(uint8_t op) {
  static const char kDigits[] = "0123456789abcdef";
  return std::string("0x") + kDigits[op >> 4] + kDigits[op & 15];
}

// Reads an MCAP map<string, string>: u32 byte length, then key/value strings.
Status ReadStringMap(RosMessageReader* reader, std::map<std::string, std::string>* map) {
  uint32_t bytes = 0;
  SWARMLIO_RETURN_IF_ERROR(reader->ReadArrayLength("metadata", 1, &bytes));
  const size_t end = reader->position() + bytes;
  while (reader->position() < end) {
    std::string key;
    std::string value;
    SWARMLIO_RETURN_IF_ERROR(reader->ReadString("metadata key", &key));
    SWARMLIO_RETURN_IF_ERROR(reader->ReadString("metadata value", &value));
    (*map)[key] = value;
  }
  if (reader->position() != end) return Status::DataLoss("metadata overruns its byte length");
  return Status::Ok();
}

class Scanner {
 public:
  Scanner(std::string path, bool recover, McapFile* out)
      : path_(std::move(path)), recover_(recover), out_(out) {}

  Status Run();

 private:
  // Records damage: an error without recovery, else counted. `bytes` were lost.
  Status Damage(uint64_t offset, uint64_t bytes, const std::string& what);
  // Reads the record at `offset` into content_ and adds its prefix to crc_.
  Status ReadRecordAt(uint64_t offset, uint8_t* op);
  Status OnRecord(uint8_t op,
                  const uint8_t* content,
                  uint64_t size,
                  uint64_t content_offset,
                  int64_t chunk,
                  uint64_t file_offset);
  Status OnSchema(RosMessageReader* reader);
  Status OnChannel(RosMessageReader* reader);
  Status OnMessage(RosMessageReader* reader, uint64_t content_offset, uint64_t size, int64_t chunk);
  Status OnChunk(uint64_t file_offset);
  Status ChunkRecords(const McapChunk& chunk,
                      const uint8_t* stored,
                      uint32_t crc,
                      const uint8_t** records);
  Status WalkChunk(const uint8_t* records, uint64_t size, int64_t chunk, uint64_t file_offset);

  std::string path_;
  bool recover_;
  McapFile* out_;
  std::unique_ptr<BagFile> file_;
  uint64_t size_ = 0;
  uint32_t crc_ = 0;         // of the data section so far
  ByteBuffer content_;       // the current record's content
  ByteBuffer decompressed_;  // the current chunk's records when compressed
  std::map<uint16_t, McapSchema> schemas_;
  std::map<uint16_t, uint32_t> channels_;  // id -> index into out_->channels
};

Status Scanner::Damage(uint64_t offset, uint64_t bytes, const std::string& what) {
  if (!recover_) {
    return Status::DataLoss("bag '" + path_ + "': " + what +
                            " (recover_damaged_bags is false; with true the complete messages "
                            "before the damage are read)");
  }
  BagRecoveryStats& damage = out_->damage;
  if (!damage.recovered) {
    damage.recovered = true;
    damage.reason = what;
    damage.damage_offset = offset;
  }
  ++damage.damaged_records;
  damage.damaged_bytes += bytes;
  return Status::Ok();
}

Status Scanner::OnSchema(RosMessageReader* reader) {
  uint16_t id = 0;
  McapSchema schema;
  SWARMLIO_RETURN_IF_ERROR(reader->ReadU16("schema id", &id));
  SWARMLIO_RETURN_IF_ERROR(reader->ReadString("schema name", &schema.name));
  SWARMLIO_RETURN_IF_ERROR(reader->ReadString("schema encoding", &schema.encoding));
  uint32_t data_bytes = 0;
  SWARMLIO_RETURN_IF_ERROR(reader->ReadArrayLength("schema data", 1, &data_bytes));
  if (id != 0) schemas_.emplace(id, std::move(schema));  // the first definition counts
  return Status::Ok();
}

Status Scanner::OnChannel(RosMessageReader* reader) {
  McapChannel channel;
  uint16_t schema_id = 0;
  SWARMLIO_RETURN_IF_ERROR(reader->ReadU16("channel id", &channel.id));
  SWARMLIO_RETURN_IF_ERROR(reader->ReadU16("channel schema_id", &schema_id));
  SWARMLIO_RETURN_IF_ERROR(reader->ReadString("channel topic", &channel.topic));
  SWARMLIO_RETURN_IF_ERROR(
      reader->ReadString("channel message_encoding", &channel.message_encoding));
  SWARMLIO_RETURN_IF_ERROR(ReadStringMap(reader, &channel.metadata));
  if (schema_id != 0) {
    const auto schema = schemas_.find(schema_id);
    if (schema == schemas_.end()) {
      return Status::DataLoss("channel '" + channel.topic + "' refers to schema " +
                              std::to_string(schema_id) + ", which comes nowhere before it");
    }
    channel.schema_name = schema->second.name;
    channel.schema_encoding = schema->second.encoding;
  }
  if (channels_.count(channel.id) > 0) return Status::Ok();  // repeated (e.g. in every chunk)
  channels_[channel.id] = static_cast<uint32_t>(out_->channels.size());
  out_->channels.push_back(std::move(channel));
  return Status::Ok();
}

Status Scanner::OnMessage(RosMessageReader* reader,
                          uint64_t content_offset,
                          uint64_t size,
                          int64_t chunk) {
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time = 0;
  uint64_t publish_time = 0;
  SWARMLIO_RETURN_IF_ERROR(reader->ReadU16("message channel_id", &channel_id));
  SWARMLIO_RETURN_IF_ERROR(reader->ReadU32("message sequence", &sequence));
  SWARMLIO_RETURN_IF_ERROR(reader->ReadU64("message log_time", &log_time));
  SWARMLIO_RETURN_IF_ERROR(reader->ReadU64("message publish_time", &publish_time));
  const auto channel = channels_.find(channel_id);
  if (channel == channels_.end()) {
    return Status::DataLoss("unknown channel " + std::to_string(channel_id));
  }
  if (log_time > static_cast<uint64_t>(std::numeric_limits<int64_t>::max())) {
    return Status::DataLoss("log_time " + std::to_string(log_time) + " beyond int64 ns");
  }
  McapMessage message;
  message.channel = channel->second;
  message.log_time_ns = static_cast<int64_t>(log_time);
  message.chunk = chunk;
  message.offset = content_offset + kMcapMessageHeaderBytes;
  message.size = size - kMcapMessageHeaderBytes;
  out_->messages.push_back(message);
  return Status::Ok();
}

// One Schema, Channel, Message (or ignored) record's content; `content_offset`
// locates it (file or chunk), `file_offset` is the record's (or its chunk's)
// place in the file, for messages.
Status Scanner::OnRecord(uint8_t op,
                         const uint8_t* content,
                         uint64_t size,
                         uint64_t content_offset,
                         int64_t chunk,
                         uint64_t file_offset) {
  RosMessageReader reader(content, static_cast<size_t>(size));
  Status status;
  if (op == kMcapSchema) {
    status = OnSchema(&reader);
  } else if (op == kMcapChannel) {
    status = OnChannel(&reader);
  } else if (op == kMcapMessage) {
    status = OnMessage(&reader, content_offset, size, chunk);
  }
  if (status.ok()) return Status::Ok();
  return Damage(file_offset, size + kMcapRecordPrefixBytes,
                "malformed record " + Hex(op) + " at offset " + std::to_string(file_offset) + ": " +
                    status.message());
}

Status Scanner::WalkChunk(const uint8_t* records,
                          uint64_t size,
                          int64_t chunk,
                          uint64_t file_offset) {
  uint64_t at = 0;
  while (at < size) {
    const uint64_t left = size - at;
    const uint64_t length =
        left < kMcapRecordPrefixBytes ? 0 : LoadLittleEndian<uint64_t>(records + at + 1);
    if (left < kMcapRecordPrefixBytes || length > left - kMcapRecordPrefixBytes) {
      return Damage(file_offset, left,
                    "chunk at offset " + std::to_string(file_offset) + ": record at chunk offset " +
                        std::to_string(at) + " is cut off");
    }
    const uint64_t content = at + kMcapRecordPrefixBytes;
    SWARMLIO_RETURN_IF_ERROR(
        OnRecord(records[at], records + content, length, content, chunk, file_offset));
    at = content + length;
  }
  return Status::Ok();
}

// The records of `chunk`, whose stored bytes (chunk.records_bytes) are at
// `stored`: those bytes themselves when uncompressed, else decompressed into
// decompressed_; checked against `crc` unless it is 0. Adds the stored bytes
// to crc_; for an uncompressed chunk by combining the records' CRC, which is
// the chunk's too, so each byte goes through the CRC once.
Status Scanner::ChunkRecords(const McapChunk& chunk,
                             const uint8_t* stored,
                             uint32_t crc,
                             const uint8_t** records) {
  const size_t size = static_cast<size_t>(chunk.records_bytes);
  uint32_t records_crc = 0;
  if (chunk.compression.empty()) {
    records_crc = Crc32(stored, size);
    crc_ = Crc32Combine(crc_, records_crc, size);
  } else {
    crc_ = Crc32(stored, size, crc_);
  }
  SWARMLIO_RETURN_IF_ERROR(McapChunkRecords(chunk.compression, stored, size,
                                            chunk.uncompressed_bytes, &decompressed_, records));
  if (crc == 0) return Status::Ok();
  if (!chunk.compression.empty()) {
    records_crc = Crc32(*records, static_cast<size_t>(chunk.uncompressed_bytes));
  }
  if (records_crc != crc) return Status::DataLoss("uncompressed CRC mismatch");
  return Status::Ok();
}

// A Chunk record, in content_; adds it to crc_.
Status Scanner::OnChunk(uint64_t file_offset) {
  const uint8_t* content = content_.data();
  const uint64_t record_bytes = content_.size() + kMcapRecordPrefixBytes;
  const std::string where = "chunk at offset " + std::to_string(file_offset);
  RosMessageReader reader(content, content_.size());
  uint64_t start_time = 0, end_time = 0;
  uint32_t crc = 0;
  McapChunk chunk;
  Status status = reader.ReadU64("message_start_time", &start_time);
  if (status.ok()) status = reader.ReadU64("message_end_time", &end_time);
  if (status.ok()) status = reader.ReadU64("uncompressed_size", &chunk.uncompressed_bytes);
  if (status.ok()) status = reader.ReadU32("uncompressed_crc", &crc);
  if (status.ok()) status = reader.ReadString("compression", &chunk.compression);
  if (status.ok()) status = reader.ReadU64("records length", &chunk.records_bytes);
  if (status.ok() && chunk.records_bytes != reader.remaining()) {
    status = Status::DataLoss("records length " + std::to_string(chunk.records_bytes) + " but " +
                              std::to_string(reader.remaining()) + " bytes remain");
  }
  if (!status.ok()) {
    crc_ = Crc32(content, content_.size(), crc_);
    return Damage(file_offset, record_bytes, where + ": " + status.message());
  }
  if (!IsSupportedMcapCompression(chunk.compression)) {
    return Status::InvalidArgument("bag '" + path_ + "': " + where + " has compression '" +
                                   chunk.compression + "' (supported: none, zstd, lz4)");
  }
  crc_ = Crc32(content, reader.position(), crc_);
  chunk.records_offset = file_offset + kMcapRecordPrefixBytes + reader.position();
  const uint8_t* records = nullptr;
  status = ChunkRecords(chunk, content + reader.position(), crc, &records);
  if (!status.ok()) return Damage(file_offset, record_bytes, where + ": " + status.message());
  out_->chunks.push_back(chunk);
  return WalkChunk(records, chunk.uncompressed_bytes, static_cast<int64_t>(out_->chunks.size() - 1),
                   file_offset);
}

Status Scanner::ReadRecordAt(uint64_t offset, uint8_t* op) {
  uint8_t prefix[kMcapRecordPrefixBytes];
  const uint64_t left = size_ - offset;
  if (left < kMcapRecordPrefixBytes || !file_->Read(offset, sizeof(prefix), prefix)) {
    return Status::DataLoss("truncated: record at offset " + std::to_string(offset) +
                            " is cut off (" + std::to_string(left) + " bytes remain)");
  }
  *op = prefix[0];
  const uint64_t length = LoadLittleEndian<uint64_t>(prefix + 1);
  if (length > left - kMcapRecordPrefixBytes) {
    return Status::DataLoss("truncated: record " + Hex(*op) + " at offset " +
                            std::to_string(offset) + " claims " + std::to_string(length) +
                            " bytes, " + std::to_string(left - kMcapRecordPrefixBytes) + " remain");
  }
  // Straight from the file into the buffer the record is parsed (and, for
  // an uncompressed chunk, its messages found) in.
  uint8_t* content = content_.Resize(static_cast<size_t>(length));
  if (!file_->Read(offset + kMcapRecordPrefixBytes, static_cast<size_t>(length), content)) {
    return Status::IoError("bag '" + path_ + "': read failed at offset " + std::to_string(offset));
  }
  crc_ = Crc32(prefix, sizeof(prefix), crc_);
  return Status::Ok();
}

Status Scanner::Run() {
  std::error_code ec;
  if (!std::filesystem::exists(path_, ec)) {
    return Status::NotFound("bag '" + path_ + "': no such file");
  }
  size_ = std::filesystem::file_size(path_, ec);
  file_ = std::make_unique<BagFile>(path_, ec ? 0 : size_);
  if (ec || !file_->is_open()) return Status::IoError("bag '" + path_ + "': cannot open");
  std::vector<uint8_t> magic;
  if (!file_->Read(0, kMcapMagicBytes, &magic) || !IsMcapMagic(magic.data())) {
    return Status::DataLoss("bag '" + path_ + "': not an MCAP file (no magic)");
  }
  out_->path = path_;
  crc_ = Crc32(magic.data(), magic.size());
  uint64_t offset = kMcapMagicBytes;
  for (bool first = true;; first = false) {
    if (offset == size_) {
      return Damage(offset, 0, "unfinished: the file ends without DataEnd record and footer");
    }
    uint8_t op = 0;
    const uint32_t crc_before = crc_;
    const Status read = ReadRecordAt(offset, &op);
    if (read.code() == Status::Code::kIoError) return read;
    if (!read.ok() || (first && op != kMcapHeader)) {
      const std::string what = read.ok() ? "first record is not a Header" : read.message();
      if (first) return Status::DataLoss("bag '" + path_ + "': " + what);
      return Damage(offset, size_ - offset, what);
    }
    const uint8_t* content = content_.data();
    const uint64_t length = content_.size();
    if (op == kMcapDataEnd || op == kMcapFooter) {
      RosMessageReader reader(content, length);
      uint32_t data_crc = 0;
      if (op == kMcapDataEnd && reader.ReadU32("data_section_crc", &data_crc).ok() &&
          data_crc != 0 && data_crc != crc_before && !out_->damage.recovered) {
        return Damage(offset, 0, "data section CRC mismatch (some message bytes are corrupt)");
      }
      return Status::Ok();
    }
    if (op == kMcapChunk) {
      SWARMLIO_RETURN_IF_ERROR(OnChunk(offset));  // adds the chunk to crc_
    } else {
      crc_ = Crc32(content, length, crc_);
      if (op == kMcapHeader) {
        RosMessageReader reader(content, length);
        static_cast<void>(reader.ReadString("profile", &out_->profile));
      } else {
        SWARMLIO_RETURN_IF_ERROR(
            OnRecord(op, content, length, offset + kMcapRecordPrefixBytes, -1, offset));
      }
    }
    offset += kMcapRecordPrefixBytes + length;
  }
}

}  // namespace

Status ScanMcapFile(const std::string& path, bool recover, McapFile* file) {
  *file = McapFile();
  Scanner scanner(path, recover, file);
  SWARMLIO_RETURN_IF_ERROR(scanner.Run());
  file->damage.messages = static_cast<int64_t>(file->messages.size());
  return Status::Ok();
}

McapChunkCache::McapChunkCache(const McapFile* file) : file_(file) {}

BagFile* McapChunkCache::File() {
  if (reader_ == nullptr) {
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(file_->path, ec);
    reader_ = std::make_unique<BagFile>(file_->path, ec ? 0 : size);
  }
  return reader_.get();
}

Status McapChunkCache::Read(uint64_t offset, uint64_t size, ByteBuffer* bytes) {
  if (!File()->Read(offset, static_cast<size_t>(size), bytes->Resize(static_cast<size_t>(size)))) {
    return Status::IoError("read failed (file changed?)");
  }
  return Status::Ok();
}

Status McapChunkCache::Get(int64_t chunk, std::shared_ptr<const McapCachedChunk>* records) {
  for (size_t i = 0; i < kept_.size(); ++i) {
    if (kept_[i]->chunk != chunk) continue;
    std::rotate(kept_.begin(), kept_.begin() + static_cast<std::ptrdiff_t>(i),
                kept_.begin() + static_cast<std::ptrdiff_t>(i) + 1);
    *records = kept_.front();
    return Status::Ok();
  }
  // The least recently used chunk makes room; its buffers are reused unless
  // a stream still holds it.
  std::shared_ptr<McapCachedChunk> entry;
  if (kept_.size() >= kKeptMcapChunks) {
    entry = std::move(kept_.back());
    kept_.pop_back();
    if (entry.use_count() > 1) entry.reset();
  }
  if (entry == nullptr) entry = std::make_shared<McapCachedChunk>();
  const McapChunk& c = file_->chunks[static_cast<size_t>(chunk)];
  const size_t stored_bytes = static_cast<size_t>(c.records_bytes);
  entry->chunk = -1;
  uint8_t* stored = entry->stored.Resize(stored_bytes);
  if (!File()->Read(c.records_offset, stored_bytes, stored)) {
    return Status::IoError("chunk read failed (file changed?)");
  }
  SWARMLIO_RETURN_IF_ERROR(McapChunkRecords(c.compression, stored, stored_bytes,
                                            c.uncompressed_bytes, &entry->decompressed,
                                            &entry->data));
  entry->size = c.uncompressed_bytes;
  entry->chunk = chunk;
  kept_.insert(kept_.begin(), entry);
  *records = std::move(entry);
  return Status::Ok();
}

McapMessageReader::McapMessageReader(const McapFile* file, McapChunkCache* cache)
    : file_(file), cache_(cache) {}

Status McapMessageReader::Read(const McapMessage& message, const uint8_t** data) {
  const auto where = [&] {
    return "bag '" + file_->path + "': message at offset " + std::to_string(message.offset);
  };
  if (message.chunk < 0) {
    const Status status = cache_->Read(message.offset, message.size, &stored_);
    if (!status.ok()) return status.WithContext(where());
    *data = stored_.data();
    return Status::Ok();
  }
  if (chunk_ == nullptr || chunk_->chunk != message.chunk) {
    chunk_.reset();  // so that the cache may reuse its buffers
    const Status status = cache_->Get(message.chunk, &chunk_);
    if (!status.ok()) return status.WithContext(where());
  }
  if (message.offset > chunk_->size || message.size > chunk_->size - message.offset) {
    return Status::DataLoss(where() + ": outside its chunk");
  }
  *data = chunk_->data + message.offset;
  return Status::Ok();
}

}  // namespace swarmlio::io::internal
