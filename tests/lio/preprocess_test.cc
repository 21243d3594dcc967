#include "swarmlio/lio/preprocess.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <vector>

namespace swarmlio::lio {
namespace {

LidarPoint MakePoint(float x, float y, float z, double t, uint8_t tag = 0x10, uint8_t line = 0) {
  LidarPoint p;
  p.x = x;
  p.y = y;
  p.z = z;
  p.offset_time_s = t;
  p.tag = tag;
  p.line = line;
  p.reflectivity = 10.f;
  return p;
}

// Options with every rule off except the ones a test turns on.
PreprocessOptions Plain() {
  PreprocessOptions o;
  o.blind_range_m = 0.0;
  o.max_range_m = 1000.0;
  o.point_stride = 1;
  o.num_lines = 0;
  o.livox_tag_filter = false;
  o.livox_reject_noise = false;
  o.voxel_leaf_size_m = 0.0;
  return o;
}

std::vector<PointXYZT> RunPre(const PreprocessOptions& options, const LidarScan& scan,
                           PreprocessStats* stats = nullptr) {
  Preprocess pre(options, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  std::vector<PointXYZT> out;
  pre.Run(scan, &out, stats);
  return out;
}

TEST(PreprocessTest, BlindAndMaxRange) {
  PreprocessOptions o = Plain();
  o.blind_range_m = 0.5;
  o.max_range_m = 10.0;
  LidarScan scan;
  scan.points = {MakePoint(0.3f, 0, 0, 0.0), MakePoint(0.6f, 0, 0, 0.1),
                 MakePoint(0, 9.9f, 0, 0.2), MakePoint(0, 0, 10.1f, 0.3)};
  PreprocessStats stats;
  const auto out = RunPre(o, scan, &stats);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].time_s, 0.1);
  EXPECT_EQ(out[1].time_s, 0.2);
  EXPECT_EQ(stats.blind, 1);
  EXPECT_EQ(stats.too_far, 1);
  EXPECT_EQ(stats.output, 2);
}

TEST(PreprocessTest, StrideCountsOnlyValidPoints) {
  PreprocessOptions o = Plain();
  o.point_stride = 3;
  LidarScan scan;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int i = 0; i < 10; ++i) {
    scan.points.push_back(MakePoint(1.f + i, 0, 0, 0.01 * i));
    if (i == 1) scan.points.push_back(MakePoint(nan, 0, 0, 0.0));  // does not shift the stride
  }
  PreprocessStats stats;
  const auto out = RunPre(o, scan, &stats);
  ASSERT_EQ(out.size(), 4u);  // valid points 0, 3, 6, 9
  EXPECT_DOUBLE_EQ(out[0].p_in_b.x(), 1.0);
  EXPECT_DOUBLE_EQ(out[1].p_in_b.x(), 4.0);
  EXPECT_DOUBLE_EQ(out[2].p_in_b.x(), 7.0);
  EXPECT_DOUBLE_EQ(out[3].p_in_b.x(), 10.0);
  EXPECT_EQ(stats.stride_skipped, 6);
  EXPECT_EQ(stats.non_finite, 1);
}

TEST(PreprocessTest, NonFiniteRejected) {
  LidarScan scan;
  const float inf = std::numeric_limits<float>::infinity();
  scan.points = {MakePoint(inf, 0, 0, 0.0), MakePoint(0, -inf, 0, 0.0),
                 MakePoint(0, 0, std::numeric_limits<float>::quiet_NaN(), 0.0),
                 MakePoint(1, 1, 1, std::numeric_limits<double>::quiet_NaN()),
                 MakePoint(1, 1, 1, 0.0)};
  PreprocessStats stats;
  EXPECT_EQ(RunPre(Plain(), scan, &stats).size(), 1u);
  EXPECT_EQ(stats.non_finite, 4);
}

TEST(PreprocessTest, LineRuleAppliesToEveryTag) {
  PreprocessOptions o = Plain();
  o.num_lines = 6;
  o.livox_tag_filter = true;
  LidarScan scan;
  scan.points = {
      MakePoint(1, 0, 0, 0.0, 0x10, 5),  // kept
      MakePoint(1, 0, 0, 0.1, 0x00, 5),  // kept
      MakePoint(1, 0, 0, 0.2, 0x00, 6),  // line 6 >= 6: dropped (FAST-LIO's precedence keeps it)
      MakePoint(1, 0, 0, 0.3, 0x10, 7),  // dropped
      MakePoint(1, 0, 0, 0.4, 0x20, 0),  // second return: dropped by the tag rule
      MakePoint(1, 0, 0, 0.5, 0x30, 0),  // third return: dropped
      MakePoint(1, 0, 0, 0.6, 0x11, 0),  // first return, noise flag: kept (noise rule off)
  };
  PreprocessStats stats;
  const auto out = RunPre(o, scan, &stats);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0].time_s, 0.0);
  EXPECT_EQ(out[1].time_s, 0.1);
  EXPECT_EQ(out[2].time_s, 0.6);
  EXPECT_EQ(stats.line_rejected, 2);
  EXPECT_EQ(stats.tag_rejected, 2);

  o.livox_reject_noise = true;
  EXPECT_EQ(RunPre(o, scan).size(), 2u);
  o.livox_tag_filter = false;
  o.livox_reject_noise = false;
  o.num_lines = 0;
  EXPECT_EQ(RunPre(o, scan).size(), scan.points.size());  // all rules off
}

TEST(PreprocessTest, BodyFrameSortedAndDownsampled) {
  PreprocessOptions o = Plain();
  o.voxel_leaf_size_m = 1.0;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d t(0.1, 0.2, 0.3);
  Preprocess pre(o, R, t);
  LidarScan scan;
  scan.points = {MakePoint(5.2f, 0.1f, 0.1f, 0.05),  // same body voxel as the next one
                 MakePoint(5.3f, 0.2f, 0.2f, 0.01), MakePoint(1.5f, 2.5f, 0.5f, 0.02)};
  std::vector<PointXYZT> out;
  PreprocessStats stats;
  pre.Run(scan, &out, &stats);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(stats.voxel_merged, 1);
  EXPECT_LE(out[0].time_s, out[1].time_s);  // sorted by time
  for (const PointXYZT& p : out) {
    const LidarPoint& src = p.time_s == 0.02 ? scan.points[2]
                                              : (p.time_s == 0.01 ? scan.points[1] : scan.points[0]);
    const Eigen::Vector3d expected = R * Eigen::Vector3d(src.x, src.y, src.z) + t;
    EXPECT_LT((p.p_in_b - expected).norm(), 1e-12);
    EXPECT_EQ(p.reflectivity, 10.f);
  }
}

TEST(PreprocessTest, PresetsAndValidation) {
  LidarOptions lidar;
  lidar.type = LidarType::kLivoxMid360;
  lidar.blind_range_m = 0.2;
  lidar.num_lines = 4;
  const PreprocessOptions o = PreprocessOptionsFor(lidar);
  EXPECT_EQ(o.point_stride, 2);
  EXPECT_EQ(o.num_lines, 4);
  EXPECT_DOUBLE_EQ(o.blind_range_m, 0.2);
  EXPECT_DOUBLE_EQ(o.voxel_leaf_size_m, 0.2);
  EXPECT_EQ(o.Validate(), "");
  lidar.type = LidarType::kSpinning;
  EXPECT_FALSE(PreprocessOptionsFor(lidar).livox_tag_filter);
  PreprocessOptions bad;
  bad.blind_range_m = 500.0;
  EXPECT_NE(bad.Validate().find("blind_range_m"), std::string::npos);
  bad = PreprocessOptions();
  bad.point_stride = 0;
  EXPECT_NE(bad.Validate().find("point_stride"), std::string::npos);
}

}  // namespace
}  // namespace swarmlio::lio
