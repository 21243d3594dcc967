#include "src/io/bag_recovery.h"

#include <algorithm>
#include <filesystem>
#include <functional>
#include <map>
#include <system_error>
#include <utility>

#include "src/io/header_codec.h"

namespace swarmlio::io::internal {
namespace {

// Largest connection header we read (the message definition of real
// message types is a few KiB).
constexpr uint32_t kMaxConnectionHeaderBytes = 16u << 20;

// Reads `count` bytes at `offset` of a chunk's content (in the file or in
// memory); false if they are not all there.
using ReadFn = std::function<bool(uint64_t offset, size_t count, std::vector<uint8_t>* bytes)>;

class RecordScanner {
 public:
  RecordScanner(BagFile* file, RecoveredBag* out) : file_(file), out_(out) {}

  Status Run() {
    SWARMLIO_RETURN_IF_ERROR(ReadFileHeader());
    uint64_t pos = first_record_;
    while (pos < data_end_ && !stopped_) pos = ScanTopLevelRecord(pos);
    Finish();
    return Status::Ok();
  }

 private:
  Status ReadFileHeader() {
    std::vector<uint8_t> magic;
    if (!file_->Read(0, kBagMagicBytes, &magic) ||
        std::string(magic.begin(), magic.end()) != kBagMagic) {
      return Status::DataLoss("not a ROS1 2.0 bag: no '#ROSBAG V2.0' line at the start");
    }
    Record header;
    const std::string where = "file header record";
    SWARMLIO_RETURN_IF_ERROR(file_->ReadRecord(kBagMagicBytes, file_->size(), where, &header));
    SWARMLIO_RETURN_IF_ERROR(CheckOp(header.fields, kOpFileHeader, where));
    uint64_t index_pos = 0;
    SWARMLIO_RETURN_IF_ERROR(GetField(header.fields, "index_pos", where, &index_pos));
    first_record_ = header.end();
    data_end_ = index_pos > first_record_ && index_pos <= file_->size() ? index_pos : file_->size();
    return Status::Ok();
  }

  // Counts a damaged region [offset, end) of `records` records; the first
  // one is described in stats.reason. `stop`: nothing after it can be read.
  void Damage(uint64_t offset, uint64_t end, int64_t records, const std::string& what, bool stop) {
    BagRecoveryStats& stats = out_->stats;
    if (!damage_seen_) {
      damage_seen_ = true;
      stats.damage_offset = offset;
      stats.reason += "; damage at offset " + std::to_string(offset) + ": " + what;
    }
    stats.damaged_records += records;
    if (end > offset) stats.damaged_bytes += end - offset;
    if (stop) stopped_ = true;
  }

  // What to do with damage found while scanning a region: where the
  // unreadable part ends, whether scanning stops, and the file offset to
  // report (for a decompressed chunk, its record's).
  struct DamagePolicy {
    int64_t chunk = -1;       // -1: offsets are file offsets
    uint64_t report_at = 0;   // file offset reported for damage inside a chunk
    uint64_t damage_end = 0;  // end of the unreadable part (file offset)
    bool stop = true;
  };

  // Reads the header of the record at `at` of a region ending at `limit`.
  // Returns "" or what is wrong.
  std::string ReadHeader(const ReadFn& read,
                         uint64_t at,
                         uint64_t limit,
                         HeaderFields* fields,
                         uint64_t* data_offset,
                         uint32_t* data_bytes,
                         uint8_t* op) {
    if (at + 4 > limit || !read(at, 4, &bytes_)) return "record header cut off";
    const uint32_t header_bytes = LoadLittleEndian<uint32_t>(bytes_.data());
    if (header_bytes > kMaxRecordHeaderBytes) {
      return "corrupt record (" + std::to_string(header_bytes) + "-byte header)";
    }
    if (at + 4 + header_bytes + 4 > limit || !read(at + 4, header_bytes + 4, &bytes_)) {
      return "record header cut off";
    }
    if (!ParseHeaderFields(bytes_.data(), header_bytes, fields).ok() ||
        !GetField(*fields, "op", "record", op).ok()) {
      return "corrupt record header";
    }
    *data_bytes = LoadLittleEndian<uint32_t>(bytes_.data() + header_bytes);
    *data_offset = at + 4 + header_bytes + 4;
    return "";
  }

  // Scans the record at `pos` of the data section; returns where the next
  // record starts (data_end_ when nothing more can be read).
  uint64_t ScanTopLevelRecord(uint64_t pos) {
    const ReadFn read_file = [this](uint64_t offset, size_t count, std::vector<uint8_t>* bytes) {
      return file_->Read(offset, count, bytes);
    };
    HeaderFields fields;
    uint64_t data_offset = 0;
    uint32_t data_bytes = 0;
    uint8_t op = 0;
    const std::string problem =
        ReadHeader(read_file, pos, data_end_, &fields, &data_offset, &data_bytes, &op);
    if (!problem.empty()) {
      Damage(pos, data_end_, 1, problem, true);
      return data_end_;
    }
    const uint64_t end = data_offset + data_bytes;
    if (op == kOpChunk) {
      const auto compression = fields.find("compression");
      uint32_t size = 0;
      if (compression == fields.end() || !GetField(fields, "size", "chunk", &size).ok()) {
        Damage(pos, data_end_, 1, "corrupt chunk header", true);
        return data_end_;
      }
      if (compression->second == "none") {
        // An unterminated chunk (placeholder sizes 0) or a cut-off one holds
        // records up to where the file ends; a complete one exactly its size.
        const bool unterminated = data_bytes == 0 && size == 0;
        const bool cut = end > data_end_;
        DamagePolicy policy;
        if (unterminated || cut) {
          policy.damage_end = data_end_;
          const uint64_t stop_at =
              ScanChunkRecords(read_file, data_offset, data_end_, policy, unterminated);
          if (cut && !stopped_) {
            Damage(data_end_, data_end_, 0,
                   "chunk at offset " + std::to_string(pos) + " cut off after a complete record",
                   true);
          }
          return stopped_ ? data_end_ : stop_at;
        }
        policy.damage_end = end;
        policy.stop = false;
        ScanChunkRecords(read_file, data_offset, end, policy, false);
        return end;
      }
      if (data_bytes == 0 || end > data_end_) {
        Damage(pos, data_end_, 1,
               (data_bytes == 0 ? "unterminated " : "cut-off ") + compression->second +
                   " chunk (its messages cannot be decompressed)",
               true);
        return data_end_;
      }
      std::vector<uint8_t> stored;
      std::vector<uint8_t> content;
      Status loaded = CheckChunkSizes(compression->second, data_bytes, size);
      if (loaded.ok() && !file_->Read(data_offset, data_bytes, &stored)) {
        loaded = Status::IoError("read failed");
      }
      if (loaded.ok()) loaded = DecompressChunk(compression->second, &stored, size, &content);
      if (!loaded.ok()) {
        Damage(pos, end, 1, "chunk: " + loaded.message(), false);
        return end;
      }
      RecoveredChunk chunk;
      chunk.data_offset = data_offset;
      chunk.stored_bytes = data_bytes;
      chunk.uncompressed_bytes = size;
      chunk.compression = compression->second;
      DamagePolicy policy;
      policy.chunk = static_cast<int64_t>(out_->chunks.size());
      policy.report_at = pos;
      policy.damage_end = pos;  // the chunk's extent is known: no file bytes lost
      policy.stop = false;
      out_->chunks.push_back(std::move(chunk));
      const ReadFn read_memory = [&content](uint64_t offset, size_t count,
                                            std::vector<uint8_t>* bytes) {
        if (offset > content.size() || count > content.size() - offset) return false;
        bytes->assign(content.begin() + static_cast<std::ptrdiff_t>(offset),
                      content.begin() + static_cast<std::ptrdiff_t>(offset + count));
        return true;
      };
      ScanChunkRecords(read_memory, 0, size, policy, false);
      return end;
    }
    if (end > data_end_) {
      Damage(pos, data_end_, 1, "record cut off", true);
      return data_end_;
    }
    if (op == kOpConnection || op == kOpMessageData) {
      DamagePolicy policy;
      policy.damage_end = end;
      policy.stop = false;
      ScanChunkRecords(read_file, pos, end, policy, false);
      return end;
    }
    if (op == kOpIndexData || op == kOpChunkInfo) return end;
    Damage(pos, data_end_, 1, "unexpected record type " + std::to_string(op), true);
    return data_end_;
  }

  // Scans message and connection records in [begin, limit) of a chunk's
  // content (policy.chunk -1: the file itself). `open_ended`: an unterminated
  // chunk, which ends at the first record of another type. Returns where
  // scanning stopped.
  uint64_t ScanChunkRecords(const ReadFn& read,
                            uint64_t begin,
                            uint64_t limit,
                            const DamagePolicy& policy,
                            bool open_ended) {
    uint64_t at = begin;
    while (at < limit) {
      const uint64_t report_at = policy.chunk < 0 ? at : policy.report_at;
      const auto damage = [&](const std::string& what) {
        Damage(report_at, std::max(report_at, policy.damage_end), 1, what, policy.stop);
        return at;
      };
      HeaderFields fields;
      uint64_t data_offset = 0;
      uint32_t data_bytes = 0;
      uint8_t op = 0;
      const std::string problem =
          ReadHeader(read, at, limit, &fields, &data_offset, &data_bytes, &op);
      if (!problem.empty()) return damage(problem);
      if (op != kOpMessageData && op != kOpConnection) {
        if (open_ended) return at;  // the unterminated chunk ended here
        return damage("unexpected record type " + std::to_string(op) + " inside a chunk");
      }
      const uint64_t end = data_offset + data_bytes;
      if (end > limit) {
        return damage(op == kOpMessageData ? "message record cut off"
                                           : "connection record cut off");
      }
      if (op == kOpMessageData) {
        uint32_t conn = 0;
        uint64_t time = 0;
        if (!GetField(fields, "conn", "message", &conn).ok() ||
            !GetField(fields, "time", "message", &time).ok()) {
          return damage("corrupt message record header");
        }
        RecoveredMessage message;
        message.connection = conn;  // the connection id until Finish()
        message.time_ns = StampNsFromRos(static_cast<uint32_t>(time & 0xffffffffu),
                                         static_cast<uint32_t>(time >> 32));
        message.chunk = policy.chunk;
        message.offset = data_offset;
        message.size = data_bytes;
        out_->messages.push_back(message);
      } else if (!AddConnection(read, fields, data_offset, data_bytes)) {
        return damage("corrupt connection record");
      }
      at = end;
    }
    return at;
  }

  bool AddConnection(const ReadFn& read,
                     const HeaderFields& fields,
                     uint64_t data_offset,
                     uint32_t data_bytes) {
    uint32_t id = 0;
    const auto topic = fields.find("topic");
    if (topic == fields.end() || !GetField(fields, "conn", "connection", &id).ok()) return false;
    if (data_bytes > kMaxConnectionHeaderBytes || !read(data_offset, data_bytes, &bytes_)) {
      return false;
    }
    HeaderFields header;
    if (!ParseHeaderFields(bytes_.data(), bytes_.size(), &header).ok()) return false;
    if (connection_index_.count(id) > 0) return true;  // also in the index section
    RecoveredConnection connection;
    connection.id = id;
    connection.topic = topic->second;
    connection.datatype = header.count("type") > 0 ? header.at("type") : "";
    connection.md5sum = header.count("md5sum") > 0 ? header.at("md5sum") : "";
    connection_index_[id] = static_cast<uint32_t>(out_->connections.size());
    out_->connections.push_back(std::move(connection));
    return true;
  }

  // Maps connection ids to indices; drops messages of unknown connections.
  void Finish() {
    std::vector<RecoveredMessage> kept;
    kept.reserve(out_->messages.size());
    int64_t orphans = 0;
    for (RecoveredMessage message : out_->messages) {
      const auto it = connection_index_.find(message.connection);
      if (it == connection_index_.end()) {
        ++orphans;
        continue;
      }
      message.connection = it->second;
      kept.push_back(message);
    }
    out_->messages = std::move(kept);
    out_->stats.messages = static_cast<int64_t>(out_->messages.size());
    if (orphans > 0) {
      out_->stats.damaged_records += orphans;
      out_->stats.reason +=
          "; " + std::to_string(orphans) + " messages without a connection record dropped";
    }
  }

  BagFile* file_;
  RecoveredBag* out_;
  uint64_t first_record_ = 0;
  uint64_t data_end_ = 0;
  bool stopped_ = false;
  bool damage_seen_ = false;
  std::map<uint32_t, uint32_t> connection_index_;  // connection id -> index
  std::vector<uint8_t> bytes_;
};

}  // namespace

Status ScanBagRecords(const std::string& path, const std::string& reason, RecoveredBag* bag) {
  *bag = RecoveredBag();
  bag->path = path;
  bag->stats.recovered = true;
  bag->stats.reason = reason;
  std::error_code ec;
  const uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) return Status::IoError("bag '" + path + "': cannot get the file size: " + ec.message());
  BagFile file(path, size);
  if (!file.is_open()) return Status::IoError("bag '" + path + "': cannot open the file");
  return RecordScanner(&file, bag).Run().WithContext("bag '" + path + "'");
}

RecoveredMessageReader::RecoveredMessageReader(const RecoveredBag* bag) : bag_(bag) {}

Status RecoveredMessageReader::Read(const RecoveredMessage& message, std::vector<uint8_t>* bytes) {
  if (file_ == nullptr) {
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(bag_->path, ec);
    if (ec) return Status::IoError("bag '" + bag_->path + "': " + ec.message());
    file_ = std::make_unique<BagFile>(bag_->path, size);
    if (!file_->is_open()) return Status::IoError("bag '" + bag_->path + "': cannot open");
  }
  if (message.chunk < 0) {
    if (!file_->Read(message.offset, message.size, bytes)) {
      return Status::IoError("bag '" + bag_->path + "': reading a message at offset " +
                             std::to_string(message.offset) + " failed");
    }
    return Status::Ok();
  }
  if (message.chunk != cached_chunk_) {
    cached_chunk_ = -1;
    const RecoveredChunk& chunk = bag_->chunks.at(static_cast<size_t>(message.chunk));
    if (!file_->Read(chunk.data_offset, chunk.stored_bytes, &stored_)) {
      return Status::IoError("bag '" + bag_->path + "': reading a chunk failed");
    }
    SWARMLIO_RETURN_IF_ERROR(
        DecompressChunk(chunk.compression, &stored_, chunk.uncompressed_bytes, &chunk_)
            .WithContext("bag '" + bag_->path + "'"));
    cached_chunk_ = message.chunk;
  }
  if (message.offset > chunk_.size() || message.size > chunk_.size() - message.offset) {
    return Status::Internal("recovered message lies outside its chunk");
  }
  bytes->assign(chunk_.begin() + static_cast<std::ptrdiff_t>(message.offset),
                chunk_.begin() + static_cast<std::ptrdiff_t>(message.offset + message.size));
  return Status::Ok();
}

}  // namespace swarmlio::io::internal
