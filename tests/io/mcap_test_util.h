// A test-side MCAP builder, written from the spec independently of
// src/io/mcap_writer.cc, so the reader is checked against files it did not
// write: records appended one by one, chunks compressed here with libzstd /
// liblz4 (frame format), CRCs from zlib. Offsets of each record are kept for
// truncation tests.
#pragma once

#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace swarmlio::io::testing {

using Bytes = std::vector<uint8_t>;

class McapBuilder {
 public:
  McapBuilder() {
    const uint8_t magic[] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
    file_.assign(magic, magic + 8);
    Bytes header;
    Str(&header, "ros2");
    Str(&header, "test");
    Record(&file_, 0x01, header);
  }

  // Record contents.
  static Bytes Schema(uint16_t id, const std::string& name, const std::string& encoding) {
    Bytes c;
    Int<uint16_t>(&c, id);
    Str(&c, name);
    Str(&c, encoding);
    Str(&c, "field lines");
    return c;
  }
  static Bytes Channel(uint16_t id,
                       uint16_t schema,
                       const std::string& topic,
                       const std::string& encoding,
                       const std::string& md5sum = "") {
    Bytes c;
    Int<uint16_t>(&c, id);
    Int<uint16_t>(&c, schema);
    Str(&c, topic);
    Str(&c, encoding);
    Bytes map;
    Str(&map, "offered_qos_profiles");
    Str(&map, "");
    if (!md5sum.empty()) {
      Str(&map, "md5sum");
      Str(&map, md5sum);
    }
    Int<uint32_t>(&c, static_cast<uint32_t>(map.size()));
    c.insert(c.end(), map.begin(), map.end());
    return c;
  }
  static Bytes Message(uint16_t channel, uint64_t log_time, const Bytes& data) {
    Bytes c;
    Int<uint16_t>(&c, channel);
    Int<uint32_t>(&c, 0);
    Int<uint64_t>(&c, log_time);
    Int<uint64_t>(&c, log_time);
    c.insert(c.end(), data.begin(), data.end());
    return c;
  }

  /// Appends a record to the data section; returns the file offset after it.
  size_t Add(uint8_t op, const Bytes& content) {
    Record(&file_, op, content);
    return file_.size();
  }

  /// Appends a chunk of `records` (each (op, content)) compressed with
  /// "", "zstd" or "lz4"; `crc` false writes CRC 0 (unchecked).
  size_t AddChunk(const std::vector<std::pair<uint8_t, Bytes>>& records,
                  const std::string& compression,
                  bool crc = true) {
    Bytes raw;
    for (const auto& [op, content] : records) Record(&raw, op, content);
    Bytes stored = raw;
    if (compression == "zstd") {
      stored.resize(ZSTD_compressBound(raw.size()));
      stored.resize(ZSTD_compress(stored.data(), stored.size(), raw.data(), raw.size(), 1));
    } else if (compression == "lz4") {
      stored.resize(LZ4F_compressFrameBound(raw.size(), nullptr));
      stored.resize(
          LZ4F_compressFrame(stored.data(), stored.size(), raw.data(), raw.size(), nullptr));
    }
    Bytes c;
    Int<uint64_t>(&c, 0);
    Int<uint64_t>(&c, 0);
    Int<uint64_t>(&c, raw.size());
    Int<uint32_t>(&c, crc ? static_cast<uint32_t>(crc32(0, raw.data(), raw.size())) : 0);
    Str(&c, compression);
    Int<uint64_t>(&c, stored.size());
    c.insert(c.end(), stored.begin(), stored.end());
    return Add(0x06, c);
  }

  /// DataEnd (with the data CRC), an empty summary, Footer and magic.
  Bytes Finish() const {
    Bytes out = file_;
    Bytes data_end;
    Int<uint32_t>(&data_end, static_cast<uint32_t>(crc32(0, file_.data(), file_.size())));
    Record(&out, 0x0F, data_end);
    Bytes footer;
    Int<uint64_t>(&footer, 0);
    Int<uint64_t>(&footer, 0);
    Int<uint32_t>(&footer, 0);
    Record(&out, 0x02, footer);
    const uint8_t magic[] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
    out.insert(out.end(), magic, magic + 8);
    return out;
  }

  /// The data section so far (no DataEnd, no footer: an unfinished file).
  const Bytes& data_section() const { return file_; }

  template <class T>
  static void Int(Bytes* out, T value) {
    for (size_t i = 0; i < sizeof(T); ++i) out->push_back(static_cast<uint8_t>(value >> (8 * i)));
  }
  static void Str(Bytes* out, const std::string& s) {
    Int<uint32_t>(out, static_cast<uint32_t>(s.size()));
    out->insert(out->end(), s.begin(), s.end());
  }
  static void Record(Bytes* out, uint8_t op, const Bytes& content) {
    out->push_back(op);
    Int<uint64_t>(out, content.size());
    out->insert(out->end(), content.begin(), content.end());
  }

 private:
  Bytes file_;
};

}  // namespace swarmlio::io::testing
