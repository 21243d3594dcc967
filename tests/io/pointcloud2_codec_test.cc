// PointCloud2 decoding: field datatypes, layouts, time units and field
// names, cross-checked against ROS's deserialization and point iterators.
#include "src/io/pointcloud2_codec.h"

#include <gtest/gtest.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/PointField.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include <cstring>
#include <string>
#include <vector>

#include "tests/io/io_test_util.h"

namespace swarmlio::io::internal {
namespace {

using sensor_msgs::PointField;
using testing::Deserialize;
using testing::Serialize;

struct TestField {
  std::string name;
  uint32_t offset;
  uint8_t datatype;
};

sensor_msgs::PointCloud2 MakeCloud(const std::vector<TestField>& fields,
                                   uint32_t point_step,
                                   uint32_t width,
                                   uint32_t height,
                                   uint32_t row_step) {
  sensor_msgs::PointCloud2 cloud;
  cloud.header.stamp.sec = 100;
  cloud.header.stamp.nsec = 5;
  cloud.header.frame_id = "os_lidar";
  cloud.width = width;
  cloud.height = height;
  cloud.point_step = point_step;
  cloud.row_step = row_step;
  for (const TestField& f : fields) {
    PointField field;
    field.name = f.name;
    field.offset = f.offset;
    field.datatype = f.datatype;
    field.count = 1;
    cloud.fields.push_back(field);
  }
  cloud.data.assign(static_cast<size_t>(row_step) * height, 0xAB);  // garbage padding
  return cloud;
}

template <class T>
void PutRaw(uint8_t* dst, T value) {
  std::memcpy(dst, &value, sizeof(T));
}

void Put(
    sensor_msgs::PointCloud2* cloud, uint32_t row, uint32_t col, const TestField& f, double value) {
  uint8_t* p = cloud->data.data() + row * cloud->row_step + col * cloud->point_step + f.offset;
  switch (f.datatype) {
    case PointField::INT8:
      PutRaw(p, static_cast<int8_t>(value));
      break;
    case PointField::UINT8:
      PutRaw(p, static_cast<uint8_t>(value));
      break;
    case PointField::INT16:
      PutRaw(p, static_cast<int16_t>(value));
      break;
    case PointField::UINT16:
      PutRaw(p, static_cast<uint16_t>(value));
      break;
    case PointField::INT32:
      PutRaw(p, static_cast<int32_t>(value));
      break;
    case PointField::UINT32:
      PutRaw(p, static_cast<uint32_t>(value));
      break;
    case PointField::FLOAT32:
      PutRaw(p, static_cast<float>(value));
      break;
    case PointField::FLOAT64:
      PutRaw(p, value);
      break;
    default:
      FAIL() << "bad datatype";
  }
}

Status Decode(const sensor_msgs::PointCloud2& cloud,
              const PointCloud2DecodeOptions& options,
              LidarScan* scan,
              PointCloud2DecodeInfo* info) {
  const std::vector<uint8_t> bytes = Serialize(cloud);
  return DecodePointCloud2(bytes.data(), bytes.size(), options, scan, info);
}

// An Ouster-like organized cloud: FLOAT64 xyz, UINT16 intensity (as
// "reflectivity"), UINT32 "t" in ns, UINT16 "ring", padded points and rows.
TEST(PointCloud2CodecTest, OrganizedCloudWithMixedDatatypesAndPadding) {
  const TestField x{"x", 0, PointField::FLOAT64}, y{"y", 8, PointField::FLOAT64},
      z{"z", 16, PointField::FLOAT64}, refl{"reflectivity", 24, PointField::UINT16},
      t{"t", 28, PointField::UINT32}, ring{"ring", 32, PointField::UINT16};
  const uint32_t width = 5, height = 3, point_step = 40, row_step = width * point_step + 12;
  sensor_msgs::PointCloud2 cloud =
      MakeCloud({x, y, z, refl, t, ring}, point_step, width, height, row_step);
  for (uint32_t r = 0; r < height; ++r) {
    for (uint32_t c = 0; c < width; ++c) {
      const double i = r * width + c;
      Put(&cloud, r, c, x, 0.5 * i);
      Put(&cloud, r, c, y, -0.25 * i);
      Put(&cloud, r, c, z, 1.0 + i);
      Put(&cloud, r, c, refl, 100 + i);
      Put(&cloud, r, c, t, 1000 * i);
      Put(&cloud, r, c, ring, r == 2 ? 300 : r);  // 300 clamps to 255
    }
  }
  PointCloud2DecodeOptions options;
  options.time_unit = TimestampUnit::kNanosecond;
  LidarScan scan;
  PointCloud2DecodeInfo info;
  ASSERT_TRUE(Decode(cloud, options, &scan, &info).ok());
  EXPECT_TRUE(info.has_time_field);
  EXPECT_EQ(info.time_field, "t");
  EXPECT_EQ(scan.stamp_ns, 100000000005LL);
  EXPECT_EQ(scan.frame_id, "os_lidar");
  ASSERT_EQ(scan.points.size(), width * height);

  // Cross-check against ROS's deserialization and iterators.
  const auto ros_cloud = Deserialize<sensor_msgs::PointCloud2>(Serialize(cloud));
  sensor_msgs::PointCloud2ConstIterator<double> it_x(ros_cloud, "x");
  sensor_msgs::PointCloud2ConstIterator<uint32_t> it_t(ros_cloud, "t");
  for (uint32_t r = 0; r < height; ++r) {
    for (uint32_t c = 0; c < width; ++c) {
      const size_t i = r * width + c;
      // The iterator walks point_step strides within each row.
      const uint8_t* row = ros_cloud.data.data() + r * ros_cloud.row_step;
      double ros_x;
      uint32_t ros_t;
      std::memcpy(&ros_x, row + c * point_step + 0, 8);
      std::memcpy(&ros_t, row + c * point_step + 28, 4);
      if (r == 0) {
        EXPECT_EQ(*it_x, ros_x);
        EXPECT_EQ(*it_t, ros_t);
        ++it_x;
        ++it_t;
      }
      const LidarPoint& p = scan.points[i];
      EXPECT_EQ(p.x, static_cast<float>(ros_x));
      EXPECT_EQ(p.y, static_cast<float>(-0.25 * i));
      EXPECT_EQ(p.z, static_cast<float>(1.0 + i));
      EXPECT_EQ(p.reflectivity, static_cast<float>(100 + i));
      EXPECT_EQ(p.offset_time_s, static_cast<double>(ros_t) / 1e9);
      EXPECT_EQ(p.line, r == 2 ? 255 : r);
      EXPECT_EQ(p.tag, 0);
    }
  }
}

class PointCloud2DatatypeTest : public ::testing::TestWithParam<uint8_t> {};

TEST_P(PointCloud2DatatypeTest, AnyDatatypeForEveryField) {
  const uint8_t type = GetParam();
  // Eight-byte slots so that every datatype fits.
  const TestField x{"x", 0, type}, y{"y", 8, type}, z{"z", 16, type},
      intensity{"intensity", 24, type}, time{"time", 32, type};
  sensor_msgs::PointCloud2 cloud = MakeCloud({x, y, z, intensity, time}, 40, 4, 1, 160);
  for (uint32_t c = 0; c < 4; ++c) {
    Put(&cloud, 0, c, x, 1 + c);
    Put(&cloud, 0, c, y, 2 + c);
    Put(&cloud, 0, c, z, 3 + c);
    Put(&cloud, 0, c, intensity, 10 + c);
    Put(&cloud, 0, c, time, 4 * c);
  }
  PointCloud2DecodeOptions options;
  options.time_unit = TimestampUnit::kMillisecond;
  LidarScan scan;
  PointCloud2DecodeInfo info;
  ASSERT_TRUE(Decode(cloud, options, &scan, &info).ok());
  ASSERT_EQ(scan.points.size(), 4u);
  for (uint32_t c = 0; c < 4; ++c) {
    EXPECT_EQ(scan.points[c].x, 1.f + c);
    EXPECT_EQ(scan.points[c].y, 2.f + c);
    EXPECT_EQ(scan.points[c].z, 3.f + c);
    EXPECT_EQ(scan.points[c].reflectivity, 10.f + c);
    EXPECT_EQ(scan.points[c].offset_time_s, 4.0 * c / 1e3);
  }
}

INSTANTIATE_TEST_SUITE_P(AllDatatypes,
                         PointCloud2DatatypeTest,
                         ::testing::Values(PointField::INT8,
                                           PointField::UINT8,
                                           PointField::INT16,
                                           PointField::UINT16,
                                           PointField::INT32,
                                           PointField::UINT32,
                                           PointField::FLOAT32,
                                           PointField::FLOAT64),
                         [](const ::testing::TestParamInfo<uint8_t>& param_info) {
                           return "datatype" + std::to_string(param_info.param);
                         });

TEST(PointCloud2CodecTest, TimeFieldAutoDetectionAndConfiguredName) {
  for (const char* name : {"time", "t", "timestamp", "offset_time"}) {
    sensor_msgs::PointCloud2 cloud = MakeCloud({{"x", 0, PointField::FLOAT32},
                                                {"y", 4, PointField::FLOAT32},
                                                {"z", 8, PointField::FLOAT32},
                                                {name, 12, PointField::FLOAT32}},
                                               16, 1, 1, 16);
    Put(&cloud, 0, 0, {name, 12, PointField::FLOAT32}, 0.5);
    LidarScan scan;
    PointCloud2DecodeInfo info;
    PointCloud2DecodeOptions options;
    options.time_unit = TimestampUnit::kSecond;
    ASSERT_TRUE(Decode(cloud, options, &scan, &info).ok()) << name;
    EXPECT_EQ(info.time_field, name);
    EXPECT_EQ(scan.points[0].offset_time_s, 0.5) << name;
  }
  sensor_msgs::PointCloud2 cloud = MakeCloud({{"x", 0, PointField::FLOAT32},
                                              {"y", 4, PointField::FLOAT32},
                                              {"z", 8, PointField::FLOAT32},
                                              {"stamp_us", 12, PointField::UINT32},
                                              {"time", 16, PointField::FLOAT32}},
                                             20, 1, 1, 20);
  Put(&cloud, 0, 0, {"stamp_us", 12, PointField::UINT32}, 250);
  Put(&cloud, 0, 0, {"time", 16, PointField::FLOAT32}, 99);
  PointCloud2DecodeOptions options;
  options.time_unit = TimestampUnit::kMicrosecond;
  options.time_field = "stamp_us";
  LidarScan scan;
  PointCloud2DecodeInfo info;
  ASSERT_TRUE(Decode(cloud, options, &scan, &info).ok());
  EXPECT_EQ(scan.points[0].offset_time_s, 250 / 1e6);
  options.time_field = "no_such_field";
  const Status status = Decode(cloud, options, &scan, &info);
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(status.message().find("no_such_field"), std::string::npos);
  EXPECT_NE(status.message().find("stamp_us"), std::string::npos) << "lists the fields";
}

TEST(PointCloud2CodecTest, CloudWithoutTimeFieldHasZeroOffsets) {
  sensor_msgs::PointCloud2 cloud = MakeCloud(
      {{"x", 0, PointField::FLOAT32}, {"y", 4, PointField::FLOAT32}, {"z", 8, PointField::FLOAT32}},
      12, 3, 1, 36);
  for (uint32_t c = 0; c < 3; ++c) Put(&cloud, 0, c, {"x", 0, PointField::FLOAT32}, c);
  LidarScan scan;
  PointCloud2DecodeInfo info;
  ASSERT_TRUE(Decode(cloud, PointCloud2DecodeOptions(), &scan, &info).ok());
  EXPECT_FALSE(info.has_time_field);
  ASSERT_EQ(scan.points.size(), 3u);
  for (const LidarPoint& p : scan.points) EXPECT_EQ(p.offset_time_s, 0.0);
}

TEST(PointCloud2CodecTest, MalformedCloudsAreErrors) {
  const std::vector<TestField> xyz = {
      {"x", 0, PointField::FLOAT32}, {"y", 4, PointField::FLOAT32}, {"z", 8, PointField::FLOAT32}};
  LidarScan scan;
  PointCloud2DecodeInfo info;
  const PointCloud2DecodeOptions options;

  sensor_msgs::PointCloud2 big_endian = MakeCloud(xyz, 12, 2, 1, 24);
  big_endian.is_bigendian = true;
  EXPECT_EQ(Decode(big_endian, options, &scan, &info).code(), Status::Code::kInvalidArgument);

  sensor_msgs::PointCloud2 no_z = MakeCloud({xyz[0], xyz[1]}, 12, 2, 1, 24);
  EXPECT_FALSE(Decode(no_z, options, &scan, &info).ok());

  sensor_msgs::PointCloud2 field_outside = MakeCloud(xyz, 10, 2, 1, 20);  // z ends at 12
  EXPECT_FALSE(Decode(field_outside, options, &scan, &info).ok());

  sensor_msgs::PointCloud2 short_data = MakeCloud(xyz, 12, 2, 2, 24);
  short_data.data.resize(40);
  EXPECT_EQ(Decode(short_data, options, &scan, &info).code(), Status::Code::kDataLoss);

  sensor_msgs::PointCloud2 short_rows = MakeCloud(xyz, 12, 2, 1, 24);
  short_rows.row_step = 20;
  EXPECT_FALSE(Decode(short_rows, options, &scan, &info).ok());

  sensor_msgs::PointCloud2 huge = MakeCloud(xyz, 12, 2, 1, 24);
  huge.width = 0xFFFFFFFFu;
  huge.height = 0xFFFFFFFFu;
  EXPECT_FALSE(Decode(huge, options, &scan, &info).ok());

  sensor_msgs::PointCloud2 bad_type = MakeCloud(xyz, 12, 2, 1, 24);
  bad_type.fields[0].datatype = 9;
  EXPECT_FALSE(Decode(bad_type, options, &scan, &info).ok());

  // An unknown datatype on a field we do not use is fine.
  sensor_msgs::PointCloud2 extra =
      MakeCloud({xyz[0], xyz[1], xyz[2], {"normal_x", 0, 42}}, 12, 2, 1, 24);
  EXPECT_TRUE(Decode(extra, options, &scan, &info).ok());

  // Every truncation of a valid message.
  const std::vector<uint8_t> bytes = Serialize(MakeCloud(xyz, 12, 2, 1, 24));
  for (size_t n = 0; n < bytes.size(); ++n) {
    EXPECT_FALSE(DecodePointCloud2(bytes.data(), n, options, &scan, &info).ok()) << n;
  }
}

TEST(PointCloud2CodecTest, EmptyCloudDecodesToNoPoints) {
  sensor_msgs::PointCloud2 cloud = MakeCloud(
      {{"x", 0, PointField::FLOAT32}, {"y", 4, PointField::FLOAT32}, {"z", 8, PointField::FLOAT32}},
      12, 0, 1, 0);
  LidarScan scan;
  scan.points.resize(3);
  PointCloud2DecodeInfo info;
  ASSERT_TRUE(Decode(cloud, PointCloud2DecodeOptions(), &scan, &info).ok());
  EXPECT_TRUE(scan.points.empty());
}

class PointCloud2UnitTest : public ::testing::TestWithParam<TimestampUnit> {};

TEST_P(PointCloud2UnitTest, EncodeDecodeRoundTripAndRosView) {
  const TimestampUnit unit = GetParam();
  const LidarScan in = testing::MakeScan(2, 7000000001LL, 50);
  sensor_msgs::PointCloud2 msg;
  ASSERT_TRUE(EncodePointCloud2(in, 4, unit, "time", &msg).ok());
  const std::vector<uint8_t> bytes = Serialize(msg);

  const auto ros_cloud = Deserialize<sensor_msgs::PointCloud2>(bytes);
  EXPECT_EQ(ros_cloud.point_step, 32u);
  EXPECT_EQ(ros_cloud.width, 50u);
  EXPECT_FALSE(ros_cloud.is_bigendian);
  sensor_msgs::PointCloud2ConstIterator<float> it_x(ros_cloud, "x");
  sensor_msgs::PointCloud2ConstIterator<float> it_i(ros_cloud, "intensity");
  sensor_msgs::PointCloud2ConstIterator<double> it_t(ros_cloud, "time");
  sensor_msgs::PointCloud2ConstIterator<uint8_t> it_line(ros_cloud, "line");
  for (const LidarPoint& p : in.points) {
    EXPECT_EQ(it_x[0], p.x);
    EXPECT_EQ(it_x[1], p.y);
    EXPECT_EQ(it_x[2], p.z);
    EXPECT_EQ(*it_i, p.reflectivity);
    EXPECT_EQ(*it_t, p.offset_time_s * TimestampUnitTicksPerSecond(unit));
    EXPECT_EQ(*it_line, p.line);
    ++it_x;
    ++it_i;
    ++it_t;
    ++it_line;
  }

  PointCloud2DecodeOptions options;
  options.time_unit = unit;
  LidarScan out;
  PointCloud2DecodeInfo info;
  ASSERT_TRUE(DecodePointCloud2(bytes.data(), bytes.size(), options, &out, &info).ok());
  testing::ExpectScanEqual(in, out);
}

INSTANTIATE_TEST_SUITE_P(AllUnits,
                         PointCloud2UnitTest,
                         ::testing::Values(TimestampUnit::kSecond,
                                           TimestampUnit::kMillisecond,
                                           TimestampUnit::kMicrosecond,
                                           TimestampUnit::kNanosecond),
                         [](const ::testing::TestParamInfo<TimestampUnit>& param_info) {
                           return std::string(config::EnumToString(param_info.param));
                         });

}  // namespace
}  // namespace swarmlio::io::internal
