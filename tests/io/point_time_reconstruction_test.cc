// Clouds without a per-point time field: a spinning LiDAR's per-point time is
// reconstructed from azimuth (BagReaderOptions::reconstruct_point_time), other
// sensors are read as one instant.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "src/io/pointcloud2_codec.h"
#include "swarmlio/io/bag_reader.h"
#include "swarmlio/io/bag_writer.h"
#include "tests/io/bag_test_util.h"
#include "tests/io/io_test_util.h"

namespace swarmlio::io {
namespace {

using testing::ReadAll;
using testing::Select;
using testing::TempDir;

constexpr double kPeriodS = 0.1;
constexpr int kRings = 32;
constexpr int kColumns = 360;

// A synthetic spinning scan of one turn in kPeriodS: `columns` firings, each
// of all rings, starting at azimuth `start_deg` and turning in `direction`
// (+1 counter-clockwise). Rings fire a little behind or ahead of their
// column (up to 0.4 deg), as real sensors do. In firing order, or ring by
// ring (`ring_major`, an organized cloud's row order). The true time is kept
// in offset_time_s.
LidarScan SpinningScan(int64_t stamp_ns, double start_deg, int direction, bool ring_major) {
  LidarScan scan;
  scan.stamp_ns = stamp_ns;
  scan.frame_id = "lidar";
  auto point = [&](int column, int ring) {
    const double offset_deg = 0.4 * std::sin(ring);
    const double azimuth = (start_deg + direction * (360.0 * column / kColumns + offset_deg)) *
                           M_PI / 180.0;
    const double elevation = (-15.0 + 30.0 * ring / (kRings - 1)) * M_PI / 180.0;
    const double range = 5.0 + 0.01 * column;
    LidarPoint p;
    p.x = static_cast<float>(range * std::cos(elevation) * std::cos(azimuth));
    p.y = static_cast<float>(range * std::cos(elevation) * std::sin(azimuth));
    p.z = static_cast<float>(range * std::sin(elevation));
    p.line = static_cast<uint8_t>(ring);
    p.offset_time_s = kPeriodS * column / kColumns;
    return p;
  };
  if (ring_major) {
    for (int r = 0; r < kRings; ++r) {
      for (int c = 0; c < kColumns; ++c) scan.points.push_back(point(c, r));
    }
  } else {
    for (int c = 0; c < kColumns; ++c) {
      for (int r = 0; r < kRings; ++r) scan.points.push_back(point(c, r));
    }
  }
  return scan;
}

// Largest |reconstructed - true| time over the scan.
double MaxTimeError(const LidarScan& truth, const LidarScan& reconstructed) {
  double worst = 0.0;
  for (size_t i = 0; i < truth.points.size(); ++i) {
    worst = std::max(worst, std::abs(reconstructed.points[i].offset_time_s -
                                     truth.points[i].offset_time_s));
  }
  return worst;
}

TEST(PointTimeReconstruction, FromAzimuthInEitherDirectionAndOrder) {
  // 0.4 deg of ring offset is 0.11 ms of a 0.1 s turn; points whose ring fires
  // before the first point are clamped to 0 (the same error).
  constexpr double kTolS = 2e-4;
  for (const int direction : {1, -1}) {
    for (const double start_deg : {0.0, 170.0, -95.0}) {  // 170: crosses the +-180 seam
      for (const bool ring_major : {false, true}) {
        SCOPED_TRACE("direction " + std::to_string(direction) + ", start " +
                     std::to_string(start_deg) + (ring_major ? ", ring by ring" : ", firing order"));
        const LidarScan truth = SpinningScan(1'000'000'000, start_deg, direction, ring_major);
        LidarScan scan = truth;
        for (LidarPoint& p : scan.points) p.offset_time_s = 0.0;
        const internal::AzimuthTimeInfo info =
            internal::ReconstructPointTimeFromAzimuth(kPeriodS, &scan);
        ASSERT_TRUE(info.reconstructed);
        EXPECT_EQ(info.direction, direction);
        EXPECT_EQ(scan.points[0].offset_time_s, 0.0);  // first point = stamp
        EXPECT_NEAR(info.span_s, kPeriodS * (kColumns - 1) / kColumns, kTolS);
        EXPECT_LT(MaxTimeError(truth, scan), kTolS);
      }
    }
  }
}

TEST(PointTimeReconstruction, DegenerateCloudsStayOneInstant) {
  LidarScan scan;
  scan.points.resize(3);  // all on the rotation axis: no azimuth
  for (LidarPoint& p : scan.points) p.z = 1.0f;
  const internal::AzimuthTimeInfo info = internal::ReconstructPointTimeFromAzimuth(kPeriodS, &scan);
  EXPECT_FALSE(info.reconstructed);
  for (const LidarPoint& p : scan.points) EXPECT_EQ(p.offset_time_s, 0.0);
}

// A PointCloud2 bag without a time field (BagWriterOptions::write_point_time
// false), scans 0.1 s apart: the reader reconstructs the time for a spinning
// LiDAR (auto + spinning_lidar, or azimuth) and reads one instant otherwise.
TEST(PointTimeReconstruction, BagReaderOptionsSelectTheReconstruction) {
  TempDir dir;
  const std::string path = dir.File("spinning_no_time.bag");
  constexpr int kScans = 4;
  std::vector<LidarScan> truth;
  {
    BagWriterOptions options;
    options.lidar_format = LidarMessageFormat::kPointCloud2;
    options.write_point_time = false;
    std::unique_ptr<BagWriter> writer;
    ASSERT_TRUE(BagWriter::Open(path, options, &writer).ok());
    const int64_t t0 = 1'000'000'000;
    for (int i = 0; i < 20 * kScans; ++i) {
      const int64_t stamp = t0 + i * 5'000'000LL;
      ASSERT_TRUE(writer->WriteImu(testing::MakeImu(i, stamp)).ok());
      if (i % 20 == 0) {
        truth.push_back(SpinningScan(stamp, 30.0 * i, -1, false));
        ASSERT_TRUE(writer->WriteScan(truth.back(), stamp + 100'000'000).ok());
      }
    }
    ASSERT_TRUE(writer->Close().ok());
  }
  struct Case {
    PointTimeReconstruction mode;
    bool spinning;
    bool reconstructed;
  };
  for (const Case c : {Case{PointTimeReconstruction::kAuto, true, true},
                       Case{PointTimeReconstruction::kAuto, false, false},
                       Case{PointTimeReconstruction::kAzimuth, false, true},
                       Case{PointTimeReconstruction::kNone, true, false}}) {
    SCOPED_TRACE(std::string(config::EnumToString(c.mode)) + (c.spinning ? ", spinning" : ""));
    BagReaderOptions options;
    options.reconstruct_point_time = c.mode;
    options.spinning_lidar = c.spinning;
    std::vector<BagRecord> records;
    ReadStats stats;
    ASSERT_TRUE(ReadAll(path, options, &records, &stats).ok());
    const std::vector<LidarScan> scans = Select<LidarScan>(records);
    ASSERT_EQ(scans.size(), truth.size());
    EXPECT_EQ(stats.scans_without_point_time, kScans);
    EXPECT_EQ(stats.scans_point_time_from_azimuth, c.reconstructed ? kScans : 0);
    for (size_t s = 0; s < scans.size(); ++s) {
      if (c.reconstructed) {
        EXPECT_LT(MaxTimeError(truth[s], scans[s]), 2e-4);
      } else {
        for (const LidarPoint& p : scans[s].points) ASSERT_EQ(p.offset_time_s, 0.0);
      }
    }
    const std::string summary = stats.PointTimeSummary();
    EXPECT_NE(summary.find(c.reconstructed ? "reconstructed from azimuth" : "one instant"),
              std::string::npos)
        << summary;
  }
}

TEST(PointTimeReconstruction, OptionsParseByName) {
  BagReaderOptions options;
  EXPECT_EQ(options.reconstruct_point_time, PointTimeReconstruction::kAuto);
  EXPECT_FALSE(options.spinning_lidar);
  PointTimeReconstruction mode = PointTimeReconstruction::kAuto;
  ASSERT_TRUE(config::EnumFromString("azimuth", &mode));
  EXPECT_EQ(mode, PointTimeReconstruction::kAzimuth);
  ASSERT_TRUE(config::EnumFromString("none", &mode));
  EXPECT_EQ(mode, PointTimeReconstruction::kNone);
  EXPECT_EQ(options.Validate(), "");
}

}  // namespace
}  // namespace swarmlio::io
