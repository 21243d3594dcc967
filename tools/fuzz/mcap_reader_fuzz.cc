// libFuzzer target for the MCAP reader (docs/bag_format.md, "ROS 2 logs
// (MCAP)"): each input, after the 8-byte MCAP magic the target prepends, is
// written to a file and read to the end with BagReader (with recovery, and
// without it while skipping malformed messages) and ReadBagInfo. A bug is any
// crash, hang or sanitizer report; errors are expected and ignored.
//
//   swarmlio_mcap_reader_fuzz --write_seeds=DIR   writes MCAP seeds, exits
//   swarmlio_mcap_reader_fuzz -runs=20000 CORPUS_DIR SEED_DIR
#include <glog/logging.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/io/bag_info.h"
#include "swarmlio/io/bag_reader.h"
#include "swarmlio/io/bag_writer.h"

namespace {

using swarmlio::Status;
namespace io = swarmlio::io;
namespace fs = std::filesystem;

constexpr char kMagic[] = "\x89MCAP0\r\n";
constexpr size_t kMagicBytes = 8;

const std::string& InputPath() {
  static const std::string* const kPath = new std::string(
      (fs::temp_directory_path() / ("swarmlio_mcap_fuzz_" + std::to_string(::getpid()) + ".mcap"))
          .string());
  return *kPath;
}

void ReadToEnd(const io::BagReaderOptions& options) {
  std::unique_ptr<io::BagReader> reader;
  if (!io::BagReader::Open(InputPath(), options, &reader).ok()) return;
  io::BagRecord record;
  bool has_record = true;
  while (has_record && reader->Next(&record, &has_record).ok()) {
  }
}

// A small log of `compression` with `lidar` scans, as the writer makes it.
Status WriteSeed(const std::string& path,
                 io::BagCompression compression,
                 swarmlio::LidarMessageFormat lidar) {
  io::BagWriterOptions options;
  options.format = io::BagFormat::kMcap;
  options.compression = compression;
  options.lidar_format = lidar;
  std::unique_ptr<io::BagWriter> writer;
  SWARMLIO_RETURN_IF_ERROR(io::BagWriter::Open(path, options, &writer));
  for (int i = 0; i < 12; ++i) {
    const int64_t stamp = 1000000000 + i * 5000000LL;
    swarmlio::ImuSample imu;
    imu.stamp_ns = stamp;
    imu.linear_acceleration.z() = 9.81;
    SWARMLIO_RETURN_IF_ERROR(writer->WriteImu(imu));
    if (i % 4 == 0) {
      swarmlio::LidarScan scan;
      scan.stamp_ns = stamp;
      for (int k = 0; k < 3; ++k) {
        swarmlio::LidarPoint p;
        p.x = 1.0f + static_cast<float>(k);
        p.offset_time_s = k * 1e-3;
        scan.points.push_back(p);
      }
      SWARMLIO_RETURN_IF_ERROR(writer->WriteScan(scan));
      swarmlio::PoseStamped pose;
      pose.stamp_ns = stamp;
      SWARMLIO_RETURN_IF_ERROR(writer->WriteGroundTruth(pose));
    }
  }
  return writer->Close();
}

// Seeds: the logs without their first 8 bytes (the target adds the magic).
Status WriteSeeds(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return Status::IoError(dir + ": " + ec.message());
  int n = 0;
  for (io::BagCompression c :
       {io::BagCompression::kNone, io::BagCompression::kZstd, io::BagCompression::kLz4}) {
    for (auto lidar : {swarmlio::LidarMessageFormat::kLivoxCustomMsg,
                       swarmlio::LidarMessageFormat::kPointCloud2}) {
      const std::string log = dir + "/log.tmp";
      SWARMLIO_RETURN_IF_ERROR(WriteSeed(log, c, lidar));
      std::ifstream in(log, std::ios::binary);
      std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                              std::istreambuf_iterator<char>());
      std::ofstream out(dir + "/seed_" + std::to_string(n++), std::ios::binary);
      out.write(bytes.data() + kMagicBytes,
                static_cast<std::streamsize>(bytes.size() - kMagicBytes));
      fs::remove(log, ec);
    }
  }
  return Status::Ok();
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv) {
  const char* const kFlag = "--write_seeds=";
  for (int i = 1; i < *argc; ++i) {
    const char* arg = (*argv)[i];
    if (std::strncmp(arg, kFlag, std::strlen(kFlag)) != 0) continue;
    const Status s = WriteSeeds(arg + std::strlen(kFlag));
    if (!s.ok()) {
      std::fprintf(stderr, "mcap_reader_fuzz: %s\n", s.message().c_str());
      std::exit(1);
    }
    std::exit(0);
  }
  FLAGS_minloglevel = google::GLOG_ERROR;  // damaged inputs are the norm here
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  {
    std::ofstream out(InputPath(), std::ios::binary | std::ios::trunc);
    out.write(kMagic, kMagicBytes);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  io::BagReaderOptions options;
  options.ground_truth_topic = io::kAutoTopic;
  ReadToEnd(options);
  options.recover_damaged_bags = false;
  options.skip_malformed_messages = true;
  ReadToEnd(options);
  io::BagInfo info;
  static_cast<void>(io::ReadBagInfo(InputPath(), &info));
  return 0;
}
