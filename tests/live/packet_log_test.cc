// Packet log (net/packet_log.h): round trip, a truncated or corrupt file
// keeps the complete records before the damage and says where it is, a bad
// magic or version is an error; RecordedPacketTransport plays a log back by
// arrival time and refuses a log of another drone.
#include "swarmlio/net/packet_log.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "swarmlio/replay/recorded_packet_transport.h"
#include "test_utils/temp_dir.h"

namespace swarmlio::net {
namespace {

std::vector<Datagram> SomeDatagrams() {
  std::vector<Datagram> out;
  for (int i = 0; i < 5; ++i) {
    Datagram d;
    d.source_id = i % 2 == 0 ? 1 : -1;
    d.arrival_ns = 1'000'000'000 + 7'000'000 * (i / 2);  // ties allowed
    d.bytes.assign(static_cast<size_t>(10 + 50 * i), static_cast<uint8_t>(i));
    d.bytes.front() = 0xA5;
    out.push_back(d);
  }
  return out;
}

std::string Write(const swarmlio::testing::TempDir& dir, const std::vector<Datagram>& data) {
  const std::string path = dir.File("received.bin");
  std::unique_ptr<PacketLogWriter> w;
  PacketLogHeader header;
  header.self_id = 2;
  header.sensor_start_ns = 999'000'000;
  EXPECT_TRUE(PacketLogWriter::Open(path, header, &w).ok());
  for (const Datagram& d : data) EXPECT_TRUE(w->Append(d).ok());
  EXPECT_EQ(w->records(), static_cast<int64_t>(data.size()));
  EXPECT_TRUE(w->Close().ok());
  return path;
}

void ExpectEqual(const std::vector<Datagram>& a, const std::vector<Datagram>& b, size_t n) {
  ASSERT_GE(a.size(), n);
  ASSERT_GE(b.size(), n);
  for (size_t i = 0; i < n; ++i) {
    EXPECT_EQ(a[i].source_id, b[i].source_id) << i;
    EXPECT_EQ(a[i].arrival_ns, b[i].arrival_ns) << i;
    EXPECT_EQ(a[i].bytes, b[i].bytes) << i;
  }
}

TEST(PacketLog, RoundTrip) {
  swarmlio::testing::TempDir dir;
  const std::vector<Datagram> data = SomeDatagrams();
  const std::string path = Write(dir, data);
  PacketLogHeader header;
  std::vector<Datagram> read;
  const Status s = ReadPacketLog(path, &header, &read);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(header.self_id, 2);
  EXPECT_EQ(header.sensor_start_ns, 999'000'000);
  ASSERT_EQ(read.size(), data.size());
  ExpectEqual(read, data, data.size());
  size_t expected_bytes = PacketLogHeader::kHeaderBytes;
  for (const Datagram& d : data) expected_bytes += PacketLogHeader::kRecordHeaderBytes + d.bytes.size();
  EXPECT_EQ(std::filesystem::file_size(path), expected_bytes);
}

TEST(PacketLog, TruncatedFileKeepsTheCompleteRecords) {
  swarmlio::testing::TempDir dir;
  const std::vector<Datagram> data = SomeDatagrams();
  const std::string path = Write(dir, data);
  // Cut inside the payload of the 4th record, then inside the header of the 3rd.
  size_t end_of_3 = PacketLogHeader::kHeaderBytes;
  for (int i = 0; i < 3; ++i) end_of_3 += PacketLogHeader::kRecordHeaderBytes + data[i].bytes.size();
  for (const auto& [cut, kept] : {std::pair<size_t, size_t>{end_of_3 + 25, 3},
                                  std::pair<size_t, size_t>{end_of_3 - data[2].bytes.size() - 5, 2}}) {
    std::filesystem::resize_file(path, cut);
    PacketLogHeader header;
    std::vector<Datagram> read;
    const Status s = ReadPacketLog(path, &header, &read);
    EXPECT_EQ(s.code(), Status::Code::kDataLoss);
    EXPECT_NE(s.message().find(path), std::string::npos) << s.message();
    EXPECT_NE(s.message().find("record " + std::to_string(kept)), std::string::npos) << s.message();
    EXPECT_NE(s.message().find("truncated"), std::string::npos) << s.message();
    ASSERT_EQ(read.size(), kept);
    ExpectEqual(read, data, kept);
  }
}

TEST(PacketLog, CorruptRecordIsDetectedByItsChecksum) {
  swarmlio::testing::TempDir dir;
  const std::vector<Datagram> data = SomeDatagrams();
  const std::string path = Write(dir, data);
  const size_t in_record_1 = PacketLogHeader::kHeaderBytes + PacketLogHeader::kRecordHeaderBytes +
                             data[0].bytes.size() + PacketLogHeader::kRecordHeaderBytes + 3;
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(in_record_1));
    f.put(static_cast<char>(0x5A));
  }
  PacketLogHeader header;
  std::vector<Datagram> read;
  const Status s = ReadPacketLog(path, &header, &read);
  EXPECT_EQ(s.code(), Status::Code::kDataLoss);
  EXPECT_NE(s.message().find("record 1"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("checksum"), std::string::npos) << s.message();
  ASSERT_EQ(read.size(), 1u);
  ExpectEqual(read, data, 1);
}

TEST(PacketLog, BadMagicOrVersionIsAnError) {
  swarmlio::testing::TempDir dir;
  const std::string path = Write(dir, SomeDatagrams());
  PacketLogHeader header;
  std::vector<Datagram> read;
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(8);
    f.put(2);  // version 2
  }
  Status s = ReadPacketLog(path, &header, &read);
  EXPECT_EQ(s.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(s.message().find("version 2"), std::string::npos) << s.message();
  {
    std::ofstream f(path, std::ios::binary);
    f << "RIFF....not a packet log";
  }
  s = ReadPacketLog(path, &header, &read);
  EXPECT_EQ(s.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(s.message().find("bad magic"), std::string::npos) << s.message();
  EXPECT_TRUE(read.empty());
  s = ReadPacketLog(dir.File("missing.bin"), &header, &read);
  EXPECT_EQ(s.code(), Status::Code::kIoError);
  EXPECT_NE(s.message().find("missing.bin"), std::string::npos) << s.message();
}

TEST(PacketLog, WriterRefusesBadRecords) {
  swarmlio::testing::TempDir dir;
  std::unique_ptr<PacketLogWriter> w;
  ASSERT_TRUE(PacketLogWriter::Open(dir.File("x.bin"), PacketLogHeader(), &w).ok());
  Datagram d;
  d.arrival_ns = 10;
  EXPECT_EQ(w->Append(d).code(), Status::Code::kInvalidArgument);  // empty
  d.bytes.assign(kMaxPacketBytes + 1, 0);
  EXPECT_EQ(w->Append(d).code(), Status::Code::kInvalidArgument);  // oversized
  d.bytes.assign(4, 0);
  EXPECT_TRUE(w->Append(d).ok());
  d.arrival_ns = 9;
  EXPECT_EQ(w->Append(d).code(), Status::Code::kInvalidArgument);  // arrival goes back
  EXPECT_EQ(w->records(), 1);
  EXPECT_EQ(PacketLogWriter::Open(dir.File("no/such/dir/x.bin"), PacketLogHeader(), &w).code(),
            Status::Code::kIoError);
}

TEST(PacketLog, Crc32MatchesTheStandardCheckValue) {
  const std::string text = "123456789";
  EXPECT_EQ(Crc32(reinterpret_cast<const uint8_t*>(text.data()), text.size()), 0xCBF43926u);
}

TEST(RecordedPacketTransport, PlaysBackByArrivalTime) {
  swarmlio::testing::TempDir dir;
  const std::vector<Datagram> data = SomeDatagrams();
  const std::string path = Write(dir, data);
  std::unique_ptr<replay::RecordedPacketTransport> t;
  ASSERT_TRUE(replay::RecordedPacketTransport::Open(path, 2, &t).ok());
  EXPECT_EQ(t->num_datagrams(), 5);
  std::vector<Datagram> got;
  ASSERT_TRUE(t->Poll(999'999'999, &got).ok());
  EXPECT_TRUE(got.empty());
  ASSERT_TRUE(t->Poll(1'000'000'000, &got).ok());  // arrival <= now
  EXPECT_EQ(got.size(), 2u);
  ASSERT_TRUE(t->Poll(2'000'000'000, &got).ok());
  ASSERT_EQ(got.size(), 5u);
  ExpectEqual(got, data, 5);
  const uint8_t byte = 1;
  EXPECT_TRUE(t->Send(0, kBroadcastId, &byte, 1).ok());
  EXPECT_EQ(t->sent_discarded(), 1);
  const Status other = replay::RecordedPacketTransport::Open(path, 0, &t);
  EXPECT_EQ(other.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(other.message().find("drone id 2"), std::string::npos) << other.message();
}

TEST(RecordedPacketTransport, DamagedLogPlaysItsCompleteRecords) {
  swarmlio::testing::TempDir dir;
  const std::vector<Datagram> data = SomeDatagrams();
  const std::string path = Write(dir, data);
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 3);  // a killed writer
  std::unique_ptr<replay::RecordedPacketTransport> t;
  const Status s = replay::RecordedPacketTransport::Open(path, 2, &t);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(t->damage().code(), Status::Code::kDataLoss);
  EXPECT_NE(t->damage().message().find("record 4"), std::string::npos) << t->damage().message();
  std::vector<Datagram> got;
  ASSERT_TRUE(t->Poll(2'000'000'000, &got).ok());
  ASSERT_EQ(got.size(), 4u);
  ExpectEqual(got, data, 4);
}

}  // namespace
}  // namespace swarmlio::net
