// Per-point time sanity: a PointCloud2 time field read in the wrong
// point_time_unit spans far more (or far less) than a scan; the error names
// the option and the unit that fits.
#include "src/io/point_time_check.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "tests/io/bag_test_util.h"
#include "tests/io/io_test_util.h"

namespace swarmlio::io {
namespace {

using testing::ReadAll;
using testing::TempDir;

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A scan of `n` points whose offsets spread evenly over [0, span_s].
LidarScan SpanScan(int64_t stamp_ns, int n, double span_s, double first_s = 0.0) {
  LidarScan scan = testing::MakeScan(0, stamp_ns, n);
  for (int k = 0; k < n; ++k) {
    scan.points[k].offset_time_s = first_s + span_s * k / (n - 1);
  }
  return scan;
}

// Ten 10 Hz PointCloud2 scans of 200 points spanning 0.1 s, the time field
// written in `unit`.
std::string WriteCloudBag(const TempDir& dir, TimestampUnit unit, double first_s = 0.0) {
  const std::string path = dir.File(std::string("clouds_") + config::EnumToString(unit) + ".bag");
  BagWriterOptions options;
  options.lidar_format = LidarMessageFormat::kPointCloud2;
  options.point_time_unit = unit;
  std::unique_ptr<BagWriter> writer;
  EXPECT_TRUE(BagWriter::Open(path, options, &writer).ok());
  for (int i = 0; i < 10; ++i) {
    const int64_t stamp = 1000000000 + i * 100000000LL;
    EXPECT_TRUE(writer->WriteImu(testing::MakeImu(i, stamp)).ok());
    EXPECT_TRUE(writer->WriteScan(SpanScan(stamp, 200, 0.0999, first_s), stamp + 100000000).ok());
  }
  EXPECT_TRUE(writer->Close().ok());
  return path;
}

TEST(PointTimeCheckTest, ScanPeriodIsTheMedianSpacingClamped) {
  using internal::EstimateScanPeriodS;
  EXPECT_EQ(EstimateScanPeriodS({}), 0.1);
  EXPECT_EQ(EstimateScanPeriodS({5}), 0.1);
  EXPECT_EQ(EstimateScanPeriodS({5, 5, 5}), 0.1);  // no positive step
  EXPECT_DOUBLE_EQ(EstimateScanPeriodS({0, 50000000, 100000000, 900000000, 950000000}), 0.05);
  EXPECT_EQ(EstimateScanPeriodS({0, 10}), internal::kMinScanPeriodS);
  EXPECT_EQ(EstimateScanPeriodS({0, 60000000000}), internal::kMaxScanPeriodS);
}

TEST(PointTimeCheckTest, FormatDuration) {
  using internal::FormatDuration;
  EXPECT_EQ(FormatDuration(100000.0), "27.7778 h");
  EXPECT_EQ(FormatDuration(900.0), "15 min");
  EXPECT_EQ(FormatDuration(99.9), "99.9 s");
  EXPECT_EQ(FormatDuration(0.1), "100 ms");
  EXPECT_EQ(FormatDuration(1.5), "1.5 s");
  EXPECT_EQ(FormatDuration(1e-7), "100 ns");
  EXPECT_EQ(FormatDuration(2.5e-5), "25 us");
  EXPECT_EQ(FormatDuration(0.0), "0 s");
}

TEST(PointTimeCheckTest, SpansThatFitPass) {
  using internal::CheckPointTimeSpan;
  for (TimestampUnit unit : {TimestampUnit::kSecond, TimestampUnit::kNanosecond}) {
    EXPECT_EQ(CheckPointTimeSpan(SpanScan(0, 200, 0.1), unit, "t", 0.1, true), "");
    EXPECT_EQ(CheckPointTimeSpan(SpanScan(0, 200, 0.1, -0.1), unit, "t", 0.1, true), "");
    EXPECT_EQ(CheckPointTimeSpan(SpanScan(0, 200, 0.0), unit, "t", 0.1, true), "");
  }
  // A cropped field of view covers part of the period.
  EXPECT_EQ(CheckPointTimeSpan(SpanScan(0, 200, 0.02), TimestampUnit::kSecond, "t", 0.1, true), "");
  // Few points with a tiny span (tests, sparse scans) are not judged.
  EXPECT_EQ(CheckPointTimeSpan(SpanScan(0, 20, 1e-4), TimestampUnit::kSecond, "t", 0.1, true), "");
  LidarScan one = SpanScan(0, 2, 50.0);
  one.points.resize(1);
  EXPECT_EQ(CheckPointTimeSpan(one, TimestampUnit::kSecond, "t", 0.1, true), "");
}

TEST(PointTimeCheckTest, TheBriefsExample) {
  // 0.1 s written in us (100000) but read as seconds.
  const std::string problem = internal::CheckPointTimeSpan(SpanScan(0, 200, 100000.0),
                                                           TimestampUnit::kSecond, "t", 0.1, true);
  EXPECT_EQ(problem,
            "per-point time field 't' spans 100000 (in point_time_unit 's' that is 27.7778 h), "
            "longer than a scan can be (scan period 100 ms (median spacing of the LiDAR "
            "messages)); with 'us' it is 100 ms: set point_time_unit: us (in a sensor preset "
            "or manifest: lidar.timestamp_unit: us)");
}

TEST(PointTimeCheckTest, NoUnitFitsOrAbsoluteTimes) {
  // 5000 s in seconds: 5 s in ms, 5 ms in us (too short), ... nothing fits.
  std::string problem = internal::CheckPointTimeSpan(SpanScan(0, 200, 5000.0),
                                                     TimestampUnit::kSecond, "time", 0.1, false);
  EXPECT_TRUE(Contains(problem, "no unit gives a plausible span")) << problem;
  EXPECT_TRUE(Contains(problem, "(assumed)")) << problem;
  // Times since the epoch: a fine span, but far from the header stamp.
  problem = internal::CheckPointTimeSpan(SpanScan(0, 200, 0.1, 1.7e9), TimestampUnit::kSecond,
                                         "timestamp", 0.1, true);
  EXPECT_TRUE(Contains(problem, "look absolute")) << problem;
  EXPECT_TRUE(Contains(problem, "check_point_time_span")) << problem;
}

TEST(PointTimeCheckTest, AWrongUnitInABagIsAnErrorNamingTheOption) {
  TempDir dir;
  struct Case {
    TimestampUnit written;
    TimestampUnit read;
    const char* expected;
  };
  const Case cases[] = {
      // ns read as us: 1000x too long.
      {TimestampUnit::kNanosecond, TimestampUnit::kMicrosecond,
       "spans 99900000 (in point_time_unit 'us' that is 99.9 s), longer than a scan can be "
       "(scan period 100 ms (median spacing of the LiDAR messages)); with 'ns' it is 99.9 ms: "
       "set point_time_unit: ns (in a sensor preset or manifest: lidar.timestamp_unit: ns)"},
      // s read as us (Velodyne-style seconds with the default): 1e6x too short.
      {TimestampUnit::kSecond, TimestampUnit::kMicrosecond,
       "far shorter than a scan (scan period 100 ms (median spacing of the LiDAR messages)); "
       "with 's' it is 99.9 ms: set point_time_unit: s"},
      // us read as s.
      {TimestampUnit::kMicrosecond, TimestampUnit::kSecond,
       "that is 27.75 h), longer than a scan can be"},
  };
  for (const Case& c : cases) {
    const std::string path = WriteCloudBag(dir, c.written);
    BagReaderOptions options;
    options.point_time_unit = c.read;
    std::vector<BagRecord> records;
    const Status status = ReadAll(path, options, &records);
    EXPECT_EQ(status.code(), Status::Code::kInvalidArgument) << status.message();
    EXPECT_TRUE(Contains(status.message(), path)) << status.message();
    EXPECT_TRUE(Contains(status.message(), "topic '/livox/lidar' message #0")) << status.message();
    EXPECT_TRUE(Contains(status.message(), c.expected)) << status.message();

    // The right unit reads; so does the wrong one with the check off.
    options.point_time_unit = c.written;
    ReadStats stats;
    ASSERT_TRUE(ReadAll(path, options, &records, &stats).ok());
    EXPECT_EQ(stats.scans, 10);
    options.point_time_unit = c.read;
    options.check_point_time_span = false;
    ASSERT_TRUE(ReadAll(path, options, &records, &stats).ok());
    EXPECT_EQ(stats.scans, 10);
  }
  std::unique_ptr<BagReader> reader;
  ASSERT_TRUE(
      BagReader::Open(WriteCloudBag(dir, TimestampUnit::kMillisecond), BagReaderOptions(), &reader)
          .ok());
  EXPECT_DOUBLE_EQ(reader->scan_period_s(), 0.1);
}

TEST(PointTimeCheckTest, AbsolutePerPointTimesAreAnError) {
  TempDir dir;
  const std::string path = WriteCloudBag(dir, TimestampUnit::kSecond, 1.7e9);
  BagReaderOptions options;
  options.point_time_unit = TimestampUnit::kSecond;
  std::vector<BagRecord> records;
  const Status status = ReadAll(path, options, &records);
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_TRUE(Contains(status.message(), "relative to the header stamp")) << status.message();
}

}  // namespace
}  // namespace swarmlio::io
