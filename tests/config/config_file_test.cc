#include "swarmlio/config/config_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "swarmlio/config/dump_options.h"
#include "swarmlio/sensors/imu_options.h"
#include "swarmlio/sensors/lidar_options.h"
#include "tests/config/config_test_util.h"
#include "tests/config/test_options.h"

namespace swarmlio::config {
namespace {

using config_test::Color;
using config_test::ParseAndRead;
using config_test::TestOptions;
using ::testing::AllOf;
using ::testing::HasSubstr;

std::string WriteTempFile(const std::string& name, const std::string& contents) {
  const std::string path = ::testing::TempDir() + "/swarmlio_config_test_" + name;
  std::ofstream(path) << contents;
  return path;
}

TEST(ConfigFileTest, ReadsEveryFieldType) {
  const std::string yaml = R"(
test:
  enabled: false
  count: 42
  small: 255
  big: -9000000000
  ratio: 0.25
  distance_m: 1e-3
  time_s: 2
  name: "hello: world"
  color: blue
  offset_m: [1, -2.5, 3]
  rotation: [0, -1, 0,  1, 0, 0,  0, 0, 1]
  weights: []
  tags: [x, "y z"]
  inner:
    gain: 0.5
)";
  TestOptions options;
  ASSERT_TRUE(ParseAndRead(yaml, "test", &options).ok());
  EXPECT_FALSE(options.enabled);
  EXPECT_EQ(options.count, 42);
  EXPECT_EQ(options.small, 255);
  EXPECT_EQ(options.big, -9000000000LL);
  EXPECT_EQ(options.ratio, 0.25f);
  EXPECT_EQ(options.distance_m, 1e-3);
  EXPECT_EQ(options.time_s, 2.0);
  EXPECT_EQ(options.name, "hello: world");
  EXPECT_EQ(options.color, Color::kBlue);
  EXPECT_EQ(options.offset_m, Eigen::Vector3d(1, -2.5, 3));
  EXPECT_EQ(options.rotation(0, 1), -1.0);  // row-major
  EXPECT_EQ(options.rotation(1, 0), 1.0);
  EXPECT_TRUE(options.weights.empty());
  EXPECT_EQ(options.tags, (std::vector<std::string>{"x", "y z"}));
  EXPECT_EQ(options.inner.gain, 0.5);
  EXPECT_EQ(options.inner.steps, 3);  // missing nested key keeps its default
}

TEST(ConfigFileTest, PartialFileKeepsDefaults) {
  LidarOptions lidar;
  ImuOptions imu;
  ConfigFile file;
  ASSERT_TRUE(ConfigFile::Parse("lidar:\n  blind_range_m: 1.25\nimu:\n", "x.yaml", &file).ok());
  ASSERT_TRUE(file.Read("lidar", &lidar).ok());
  ASSERT_TRUE(file.Read("imu", &imu).ok());  // an empty section keeps everything
  LidarOptions expected;
  expected.blind_range_m = 1.25;
  EXPECT_EQ(DumpOptions(lidar), DumpOptions(expected));
  EXPECT_EQ(imu.rate_hz, ImuOptions().rate_hz);
  EXPECT_TRUE(file.CheckNoUnusedSections().ok());
}

TEST(ConfigFileTest, MissingSectionAndEmptyFileKeepDefaults) {
  TestOptions options;
  options.count = 9;
  EXPECT_TRUE(ParseAndRead("", "test", &options).ok());
  EXPECT_TRUE(ParseAndRead("other: {}\n", "test", &options).ok());
  EXPECT_EQ(options.count, 9);
}

TEST(ConfigFileTest, UnknownKeyNamesFileLineKeyAndSuggestion) {
  LidarOptions lidar;
  const Status status =
      ParseAndRead("lidar:\n  scan_rate_hz: 10\n  blind_rnge_m: 1\n", "lidar", &lidar);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
  EXPECT_THAT(status.message(),
              AllOf(HasSubstr("x.yaml:3: lidar.blind_rnge_m: unknown key"),
                    HasSubstr("did you mean 'blind_range_m'?"), HasSubstr("valid keys: type,")));
}

TEST(ConfigFileTest, UnknownNestedKeyHasFullPath) {
  TestOptions options;
  const Status status = ParseAndRead("test:\n  inner:\n    gian: 1\n", "test", &options);
  EXPECT_THAT(status.message(),
              HasSubstr("x.yaml:3: test.inner.gian: unknown key; did you mean 'gain'?"));
}

TEST(ConfigFileTest, WrongTypesAreErrors) {
  const config_test::ReadErrorCase cases[] = {
      {"test:\n  distance_m: abc\n", "x.yaml:2: test.distance_m: expected a number, got 'abc'"},
      {"test:\n  distance_m: \"1.5\"\n",
       "x.yaml:2: test.distance_m: expected a number, got the quoted string '1.5'"},
      {"test:\n  distance_m: [1]\n",
       "x.yaml:2: test.distance_m: expected a number, got a sequence of 1 element"},
      {"test:\n  distance_m:\n",
       "x.yaml:2: test.distance_m: expected a number, got an empty value"},
      {"test:\n  count: 1.5\n", "x.yaml:2: test.count: expected an integer, got '1.5'"},
      {"test:\n  small: 256\n", "x.yaml:2: test.small: value 256 does not fit"},
      {"test:\n  enabled: 1\n", "x.yaml:2: test.enabled: expected true or false, got '1'"},
      {"test:\n  name: {a: 1}\n", "x.yaml:2: test.name: expected a string, got a map"},
      {"test:\n  inner: 5\n",
       "x.yaml:2: test.inner: expected a section (a map of key: value), got '5'"},
      {"test: 5\n", "x.yaml:1: test: expected a section (a map of key: value), got '5'"},
      {"test:\n  offset_m: [1, 2]\n",
       "x.yaml:2: test.offset_m: expected a sequence of 3 numbers [x, y, z], got a sequence of 2"},
      {"test:\n  offset_m: [1, x, 2]\n", "x.yaml:2: test.offset_m[1]: expected a number, got 'x'"},
      {"test:\n  rotation: [1, 0, 0]\n",
       "x.yaml:2: test.rotation: expected a sequence of 9 numbers (3x3 matrix, row-major)"},
      {"test:\n  weights:\n    - 1\n    - [2]\n",
       "x.yaml:4: test.weights[1]: expected a number, got a sequence"},
      {"test:\n  tags: x\n", "x.yaml:2: test.tags: expected a sequence of strings, got 'x'"},
      {"test:\n  count: 1\n  count: 2\n",
       "x.yaml:3: test.count: duplicate key (first set on line 2)"},
  };
  config_test::ExpectReadErrors<TestOptions>(cases);
}

TEST(ConfigFileTest, OutOfRangeNamesFileLineKeyAndBound) {
  LidarOptions lidar;
  const Status status = ParseAndRead("lidar:\n  blind_range_m: -1\n", "lidar", &lidar);
  EXPECT_EQ(status.message(),
            "x.yaml:2: lidar.blind_range_m: value -1 is out of range (must be >= 0 m)");
  ImuOptions imu;
  EXPECT_EQ(ParseAndRead("imu:\n  rate_hz: 0\n", "imu", &imu).message(),
            "x.yaml:2: imu.rate_hz: value 0 is out of range (must be in (0, 10000] Hz)");
  EXPECT_THAT(ParseAndRead("imu:\n  rate_hz: .nan\n", "imu", &imu).message(),
              HasSubstr("imu.rate_hz: value nan is out of range"));
  TestOptions options;
  EXPECT_THAT(
      ParseAndRead("test:\n  offset_m: [0, 0, 6]\n", "test", &options).message(),
      HasSubstr("x.yaml:2: test.offset_m[2]: value 6 is out of range (must be in [-5, 5] m)"));
  EXPECT_THAT(ParseAndRead("test:\n  inner: {gain: 0}\n", "test", &options).message(),
              HasSubstr("x.yaml:2: test.inner.gain: value 0 is out of range (must be > 0)"));
}

TEST(ConfigFileTest, CrossFieldErrorNamesKeyAndLine) {
  LidarOptions lidar;
  const Status status = ParseAndRead(
      "lidar:\n  fov_vertical_min_deg: 10\n  fov_vertical_max_deg: 5\n", "lidar", &lidar);
  EXPECT_THAT(
      status.message(),
      HasSubstr("x.yaml:2: lidar.fov_vertical_min_deg: must be below fov_vertical_max_deg"));
}

TEST(ConfigFileTest, BadEnumNameListsChoices) {
  LidarOptions lidar;
  const Status status = ParseAndRead("lidar:\n  type: velodyne\n", "lidar", &lidar);
  EXPECT_EQ(status.message(),
            "x.yaml:2: lidar.type: unknown value 'velodyne' (choices: livox_avia, livox_mid360, "
            "spinning)");
}

TEST(ConfigFileTest, SyntaxErrorNamesFileAndLine) {
  const std::string path = WriteTempFile("syntax.yaml", "lidar:\n  type: [livox_avia\n  x: 1\n");
  ConfigFile file;
  const Status status = ConfigFile::Load(path, &file);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr(path + ":"));
  EXPECT_THAT(status.message(), HasSubstr("YAML syntax error"));
  EXPECT_THAT(ConfigFile::Parse("a: 1\nb: [\n", "y.yaml", &file).message(),
              HasSubstr("y.yaml:3: YAML syntax error"));
  EXPECT_THAT(ConfigFile::Parse("a: 1\n b: 2\n", "y.yaml", &file).message(),
              HasSubstr("y.yaml:2: YAML syntax error"));
}

TEST(ConfigFileTest, TopLevelMustBeAMap) {
  ConfigFile file;
  EXPECT_THAT(ConfigFile::Parse("- a\n- b\n", "y.yaml", &file).message(),
              HasSubstr("y.yaml:1: expected a map of sections at the top level, got a sequence"));
  EXPECT_THAT(ConfigFile::Parse("a: 1\n---\nb: 2\n", "y.yaml", &file).message(),
              HasSubstr("single YAML document"));
}

TEST(ConfigFileTest, MissingFileIsNotFound) {
  ConfigFile file;
  const Status status = ConfigFile::Load("/nonexistent/dir/none.yaml", &file);
  EXPECT_EQ(status.code(), Status::Code::kNotFound);
  EXPECT_THAT(status.message(), HasSubstr("/nonexistent/dir/none.yaml"));
  EXPECT_FALSE(ConfigFile::Load(::testing::TempDir(), &file).ok());  // a directory
}

TEST(ConfigFileTest, LoadsFromDisk) {
  const std::string path = WriteTempFile("ok.yaml", "lidar:\n  num_lines: 4\n");
  ConfigFile file;
  ASSERT_TRUE(ConfigFile::Load(path, &file).ok());
  EXPECT_EQ(file.name(), path);
  LidarOptions lidar;
  ASSERT_TRUE(file.Read("lidar", &lidar).ok());
  EXPECT_EQ(lidar.num_lines, 4);
  EXPECT_THAT(file.Read("lidar", &lidar).message(), ::testing::IsEmpty());
}

TEST(ConfigFileTest, ErrorLeavesOptionsUnchanged) {
  TestOptions options;
  options.count = 11;
  options.name = "before";
  const TestOptions before = options;
  // Valid keys come first, so a naive loader would already have written them.
  const std::string yaml =
      "test:\n  count: 12\n  name: after\n  inner: {gain: 5}\n  distance_m: -3\n";
  EXPECT_FALSE(ParseAndRead(yaml, "test", &options).ok());
  EXPECT_TRUE(options == before);
  EXPECT_FALSE(ParseAndRead("test:\n  count: 101\n", "test", &options).ok());  // Validate()
  EXPECT_TRUE(options == before);
  EXPECT_FALSE(ParseAndRead("test:\n  count: 3\n  colour: red\n", "test", &options).ok());
  EXPECT_TRUE(options == before);
}

TEST(ConfigFileTest, UnusedSectionIsReported) {
  ConfigFile file;
  ASSERT_TRUE(ConfigFile::Parse("lidar: {}\nimu: {}\nlidr: {}\n", "x.yaml", &file).ok());
  LidarOptions lidar;
  ImuOptions imu;
  ASSERT_TRUE(file.Read("lidar", &lidar).ok());
  ASSERT_TRUE(file.Read("imu", &imu).ok());
  EXPECT_THAT(file.CheckNoUnusedSections().message(),
              HasSubstr("x.yaml:3: lidr: unknown section; did you mean 'lidar'?"));
  EXPECT_TRUE(file.HasSection("lidr"));
  EXPECT_FALSE(file.HasSection("estimator"));
  EXPECT_EQ(file.TopLevelKeys(), (std::vector<std::string>{"lidar", "imu", "lidr"}));
}

TEST(ConfigFileTest, DottedSectionAndRoot) {
  ConfigFile file;
  ASSERT_TRUE(
      ConfigFile::Parse("drone:\n  sensors:\n    test:\n      count: 8\n", "x.yaml", &file).ok());
  TestOptions options;
  ASSERT_TRUE(file.Read("drone.sensors.test", &options).ok());
  EXPECT_EQ(options.count, 8);
  EXPECT_TRUE(file.HasSection("drone.sensors"));
  EXPECT_TRUE(file.CheckNoUnusedSections().ok());
  EXPECT_TRUE(file.Read("drone.missing.test", &options).ok());  // missing: defaults kept

  config_test::InnerOptions inner;
  ASSERT_TRUE(ParseAndRead("gain: 4\nsteps: 2\n", "", &inner).ok());
  EXPECT_EQ(inner.gain, 4.0);
  EXPECT_THAT(ParseAndRead("gain: 4\nextra: 2\n", "", &inner).message(),
              HasSubstr("x.yaml:2: extra: unknown key"));
  EXPECT_THAT(ParseAndRead("drone: 3\n", "drone.test", &options).message(),
              HasSubstr("x.yaml:1: drone: expected a section"));
}

}  // namespace
}  // namespace swarmlio::config
