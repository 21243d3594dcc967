#include "swarmlio/eval/trajectory_io.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "tests/eval/eval_test_util.h"

namespace swarmlio::eval {
namespace {

bool BitEqual(double a, double b) { return std::memcmp(&a, &b, sizeof(a)) == 0; }

TEST(TumReader, ReadsCommentsBlankLinesTabsAndCrlf) {
  testing::TempDir dir;
  const std::string path = dir.Write("t.txt",
                                     "# timestamp tx ty tz qx qy qz qw\n"
                                     "\n"
                                     "1305031102.160407 1.5 -2 3e-1 0 0 0 1\r\n"
                                     "  1305031102.194330\t1 2 3 0 0 0.7071068 0.7071068\n"
                                     "1305031102.2 +1 2 3 0 0 0 2\n");
  Trajectory trajectory;
  TrajectoryReadStats stats;
  const Status status = ReadTumTrajectory(path, {}, &trajectory, &stats);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(trajectory.size(), 3u);
  EXPECT_EQ(stats.pose_lines, 3);
  EXPECT_EQ(stats.skipped_lines, 2);
  EXPECT_TRUE(BitEqual(trajectory.stamps_s[0], 1305031102.160407));
  EXPECT_EQ(trajectory.T_G_b[0].translation(), Eigen::Vector3d(1.5, -2.0, 0.3));
  // qz = qw: 90 degrees about z.
  EXPECT_LT(
      (trajectory.T_G_b[1].linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(),
      1e-6);
  // A non-unit quaternion is normalised.
  EXPECT_LT((trajectory.T_G_b[2].linear() - Eigen::Matrix3d::Identity()).norm(), 1e-15);
}

struct BadFile {
  const char* text;
  const char* expected;  // part of the message after "path:line: "
  int line;
};

TEST(TumReader, BadInputNamesFileAndLine) {
  const BadFile cases[] = {
      {"# c\n1 0 0 0 0 0 0 1\n2 0 0 x 0 0 0 1\n", "value 4 'x' is not a number", 3},
      {"1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n", "expected 8 values, got 7", 2},
      {"1 0 0 0 0 0 0 1 5\n", "expected 8 values, got 9", 1},
      {"1 0 0 nan 0 0 0 1\n", "value 4 'nan' is not finite", 1},
      {"1 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n", "does not increase (line 1)", 2},
      {"2 0 0 0 0 0 0 1\n\n1 0 0 0 0 0 0 1\n", "does not increase (line 1)", 3},
      {"1 0 0 0 0 0 0 0\n", "zero quaternion", 1},
      {"1 0 0 0 0 0 0 1,\n", "is not a number", 1},
  };
  testing::TempDir dir;
  for (const BadFile& c : cases) {
    const std::string path = dir.Write("bad.txt", c.text);
    Trajectory trajectory;
    const Status status = ReadTumTrajectory(path, {}, &trajectory);
    ASSERT_FALSE(status.ok()) << c.text;
    EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
    const std::string where = path + ":" + std::to_string(c.line) + ": ";
    EXPECT_EQ(status.message().rfind(where, 0), 0u) << status.message();
    EXPECT_NE(status.message().find(c.expected), std::string::npos) << status.message();
  }
}

TEST(TumReader, DuplicateStampsOnlyWhenAllowed) {
  testing::TempDir dir;
  const std::string path =
      dir.Write("dup.txt", "1 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n");
  Trajectory trajectory;
  EXPECT_FALSE(ReadTumTrajectory(path, {}, &trajectory).ok());
  TrajectoryReadOptions options;
  options.allow_duplicate_stamps = true;
  TrajectoryReadStats stats;
  ASSERT_TRUE(ReadTumTrajectory(path, options, &trajectory, &stats).ok());
  EXPECT_EQ(trajectory.size(), 3u);
  EXPECT_EQ(stats.duplicate_stamps, 1);
  // Decreasing stamps stay an error.
  const std::string back = dir.Write("back.txt", "2 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n");
  EXPECT_FALSE(ReadTumTrajectory(back, options, &trajectory).ok());
}

TEST(TumReader, MissingAndEmptyFiles) {
  testing::TempDir dir;
  Trajectory trajectory;
  const Status missing = ReadTumTrajectory(dir.File("nope.txt"), {}, &trajectory);
  EXPECT_EQ(missing.code(), Status::Code::kNotFound);
  EXPECT_NE(missing.message().find("nope.txt"), std::string::npos);
  const Status empty =
      ReadTumTrajectory(dir.Write("empty.txt", "# only a comment\n"), {}, &trajectory);
  EXPECT_EQ(empty.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(empty.message().find("no poses"), std::string::npos);
}

// The first lines of EuRoC MH_01_easy's state_groundtruth_estimate0/data.csv
// (17 columns: position, quaternion w x y z, velocity, gyro and accel biases).
constexpr char kEurocHead[] =
    "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
    "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], "
    "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
    "b_a_RS_S_z [m s^-2]\n"
    "1403636580838555648,4.688319,-1.786938,0.783338,0.534108,-0.153029,-0.827383,-0.082152,"
    "-0.027876,0.033207,0.800006,-0.003172,0.021267,0.078502,-0.025266,0.136696,0.075593\n"
    "1403636580843555328,4.688177,-1.786770,0.787004,0.534640,-0.152702,-0.826862,-0.082240,"
    "-0.029272,0.033992,0.804100,-0.003172,0.021267,0.078502,-0.025266,0.136696,0.075593\r\n";

TEST(EurocReader, ReadsTheGroundTruthCsvAsEvoDoes) {
  testing::TempDir dir;
  const std::string path = dir.Write("data.csv", kEurocHead);
  Trajectory trajectory;
  TrajectoryReadStats stats;
  const Status status = ReadEurocTrajectory(path, {}, &trajectory, &stats);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(trajectory.size(), 2u);
  EXPECT_EQ(stats.pose_lines, 2);
  EXPECT_EQ(stats.skipped_lines, 1);
  // evo: float64 of the ns stamp, divided by 1e9.
  EXPECT_TRUE(BitEqual(trajectory.stamps_s[0], 1403636580838555648.0 / 1e9));
  EXPECT_TRUE(BitEqual(trajectory.stamps_s[1], 1403636580843555328.0 / 1e9));
  EXPECT_EQ(trajectory.T_G_b[0].translation(), Eigen::Vector3d(4.688319, -1.786938, 0.783338));
  // Quaternion scalar first, normalised.
  const Eigen::Quaterniond q =
      Eigen::Quaterniond(0.534108, -0.153029, -0.827383, -0.082152).normalized();
  EXPECT_LT((trajectory.T_G_b[0].linear() - q.toRotationMatrix()).norm(), 1e-15);

  // The same through ReadTrajectory, and spaces around values.
  const std::string spaced = dir.Write(
      "spaced.csv", "# t, x, y, z, qw, qx, qy, qz\n\n 2000000000 , 1, 2, 3, 1, 0, 0, 0\n");
  ASSERT_TRUE(ReadTrajectory(spaced, TrajectoryFormat::kEuroc, {}, &trajectory).ok());
  ASSERT_EQ(trajectory.size(), 1u);
  EXPECT_EQ(trajectory.stamps_s[0], 2.0);
  EXPECT_EQ(trajectory.T_G_b[0].translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE(trajectory.T_G_b[0].linear().isIdentity());
}

TEST(EurocReader, BadInputNamesFileAndLine) {
  const BadFile cases[] = {
      {"#h\n1,0,0,0,1,0,0\n", "expected at least 8 comma-separated values", 2},
      {"1,0,0,0,1,0,0,0\n2,0,x,0,1,0,0,0\n", "value 3 'x' is not a number", 2},
      {"1,0,0,0,1,0,0,0\n2,0,,0,1,0,0,0\n", "value 3 '' is not a number", 2},
      {"2,0,0,0,1,0,0,0\n1,0,0,0,1,0,0,0\n", "does not increase (line 1)", 2},
      {"1,0,0,0,0,0,0,0\n", "zero quaternion", 1},
      {"1 0 0 0 1 0 0 0\n", "expected at least 8 comma-separated values", 1},
  };
  testing::TempDir dir;
  for (const BadFile& c : cases) {
    const std::string path = dir.Write("bad.csv", c.text);
    Trajectory trajectory;
    const Status status = ReadEurocTrajectory(path, {}, &trajectory);
    ASSERT_FALSE(status.ok()) << c.text;
    EXPECT_EQ(status.code(), Status::Code::kInvalidArgument);
    const std::string where = path + ":" + std::to_string(c.line) + ": ";
    EXPECT_EQ(status.message().rfind(where, 0), 0u) << status.message();
    EXPECT_NE(status.message().find(c.expected), std::string::npos) << status.message();
  }
  Trajectory trajectory;
  EXPECT_EQ(ReadEurocTrajectory(dir.File("none.csv"), {}, &trajectory).code(),
            Status::Code::kNotFound);
  // A EuRoC file read as TUM says what it probably is.
  const Status as_tum = ReadTumTrajectory(dir.Write("gt.csv", kEurocHead), {}, &trajectory);
  EXPECT_NE(as_tum.message().find("euroc format"), std::string::npos) << as_tum.message();
}

TEST(TrajectoryFiles, KittiRoundTripIsBitExact) {
  testing::TempDir dir;
  const Trajectory written = testing::Curve(25);
  const std::string path = dir.File("poses.kitti");
  ASSERT_TRUE(WriteKittiTrajectory(path, written).ok());
  Trajectory read;
  const Status status = ReadKittiTrajectory(path, &read);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_FALSE(read.has_stamps());
  ASSERT_EQ(read.size(), written.size());
  for (size_t i = 0; i < read.size(); ++i) {
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) {
        EXPECT_TRUE(BitEqual(read.T_G_b[i].matrix()(r, c), written.T_G_b[i].matrix()(r, c)));
      }
    }
  }
}

TEST(TrajectoryFiles, TumRoundTrip) {
  testing::TempDir dir;
  const Trajectory written = testing::Curve(25, 1311868164.363181);
  const std::string path = dir.File("poses.tum");
  ASSERT_TRUE(WriteTumTrajectory(path, written).ok());
  Trajectory read;
  ASSERT_TRUE(ReadTrajectory(path, TrajectoryFormat::kTum, {}, &read).ok());
  ASSERT_EQ(read.size(), written.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_TRUE(BitEqual(read.stamps_s[i], written.stamps_s[i]));
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(BitEqual(read.T_G_b[i].translation()[k], written.T_G_b[i].translation()[k]));
    }
    EXPECT_LT((read.T_G_b[i].linear() - written.T_G_b[i].linear()).norm(), 1e-15);
  }
  // A TUM file needs stamps.
  Trajectory unstamped = written;
  unstamped.stamps_s.clear();
  EXPECT_FALSE(WriteTumTrajectory(path, unstamped).ok());
  EXPECT_FALSE(WriteKittiTrajectory(dir.File("no/such/dir.kitti"), written).ok());
}

TEST(KittiReader, BadInput) {
  testing::TempDir dir;
  Trajectory trajectory;
  const std::string short_line = dir.Write("a.kitti", "1 0 0 0 0 1 0 0 0 0 1\n");
  Status status = ReadKittiTrajectory(short_line, &trajectory);
  EXPECT_NE(status.message().find(":1: expected 12 values, got 11"), std::string::npos)
      << status.message();
  const std::string not_rotation =
      dir.Write("b.kitti", "1 0 0 0 0 1 0 0 0 0 1 0\n2 0 0 0 0 1 0 0 0 0 1 0\n");
  status = ReadKittiTrajectory(not_rotation, &trajectory);
  EXPECT_NE(status.message().find(":2: the 3 x 3 block is not a rotation"), std::string::npos)
      << status.message();
  const std::string mirrored = dir.Write("c.kitti", "-1 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_FALSE(ReadKittiTrajectory(mirrored, &trajectory).ok());
  TrajectoryFormat format;
  EXPECT_TRUE(TrajectoryFormatFromString("kitti", &format));
  EXPECT_EQ(format, TrajectoryFormat::kKitti);
  EXPECT_TRUE(TrajectoryFormatFromString("euroc", &format));
  EXPECT_EQ(format, TrajectoryFormat::kEuroc);
  EXPECT_FALSE(TrajectoryFormatFromString("csv", &format));
}

TEST(Trajectory, PoseAtInterpolatesBetweenNeighboursWithinTheGap) {
  Trajectory t;
  t.stamps_s = {1.0, 2.0, 4.0};
  for (int k = 0; k < 3; ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(0.2 * k, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(k, 2.0 * k, 0.0);
    t.T_G_b.push_back(T);
  }
  Eigen::Isometry3d T;
  ASSERT_TRUE(t.PoseAt(1.25, 1.5, &T));
  EXPECT_NEAR((T.translation() - Eigen::Vector3d(0.25, 0.5, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(T.linear()).angle(), 0.05, 1e-12);
  ASSERT_TRUE(t.PoseAt(4.0, 2.5, &T));  // the last stamp itself
  EXPECT_NEAR((T.translation() - Eigen::Vector3d(2.0, 4.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_FALSE(t.PoseAt(3.0, 1.5, &T));  // the neighbours are 2 s apart
  EXPECT_FALSE(t.PoseAt(0.5, 10.0, &T));
  EXPECT_FALSE(t.PoseAt(4.5, 10.0, &T));
}

}  // namespace
}  // namespace swarmlio::eval
