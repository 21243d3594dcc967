// Bag-level helpers for the io tests: write a bag from records, read a bag
// to the end.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "swarmlio/io/bag_reader.h"
#include "swarmlio/io/bag_writer.h"
#include "tests/io/io_test_util.h"

namespace swarmlio::io::testing {

/// Reads every record; returns the first error (records read so far are kept).
inline Status ReadAll(const std::string& path,
                      const BagReaderOptions& options,
                      std::vector<BagRecord>* records,
                      ReadStats* stats = nullptr) {
  records->clear();
  std::unique_ptr<BagReader> reader;
  SWARMLIO_RETURN_IF_ERROR(BagReader::Open(path, options, &reader));
  while (true) {
    BagRecord record;
    bool has_record = false;
    const Status status = reader->Next(&record, &has_record);
    if (stats != nullptr) *stats = reader->stats();
    if (!status.ok()) return status;
    if (!has_record) return Status::Ok();
    records->push_back(std::move(record));
  }
}

template <class T>
std::vector<T> Select(const std::vector<BagRecord>& records) {
  std::vector<T> out;
  for (const BagRecord& r : records) {
    if (const T* value = std::get_if<T>(&r.data)) out.push_back(*value);
  }
  return out;
}

/// A bag with `num_imu` IMU samples at 200 Hz, a scan every 20 samples and a
/// pose every 10, starting at 1 s.
inline void WriteSimpleBag(const std::string& path,
                           const BagWriterOptions& options,
                           int num_imu,
                           int points_per_scan = 20) {
  std::unique_ptr<BagWriter> writer;
  ASSERT_TRUE(BagWriter::Open(path, options, &writer).ok());
  const int64_t t0 = 1000000000;
  for (int i = 0; i < num_imu; ++i) {
    const int64_t stamp = t0 + i * 5000000LL;
    ASSERT_TRUE(writer->WriteImu(MakeImu(i, stamp)).ok());
    if (i % 20 == 0) {
      const LidarScan scan = options.lidar_format == LidarMessageFormat::kLivoxCustomMsg
                                 ? MakeLivoxScan(i, stamp, points_per_scan)
                                 : MakeScan(i, stamp, points_per_scan);
      // Drivers publish a scan at its end: record time after the stamp.
      ASSERT_TRUE(writer->WriteScan(scan, stamp + 100000000).ok());
    }
    if (i % 10 == 0) {
      ASSERT_TRUE(writer->WriteGroundTruth(MakePose(i, stamp)).ok());
    }
  }
  ASSERT_TRUE(writer->Close().ok());
}

}  // namespace swarmlio::io::testing
