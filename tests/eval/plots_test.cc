#include "swarmlio/eval/plots.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "src/eval/chart.h"
#include "tests/eval/eval_test_util.h"

namespace swarmlio::eval {
namespace {

std::string ReadBytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::stringstream bytes;
  bytes << file.rdbuf();
  return bytes.str();
}

std::vector<TopViewSeries> ThreeDrones() {
  std::vector<TopViewSeries> drones;
  for (int k = 0; k < 3; ++k) {
    TopViewSeries d;
    d.name = "uav" + std::to_string(k);
    const int n = 200;
    d.reference_positions.resize(3, n);
    d.estimate_positions.resize(3, n);
    for (int i = 0; i < n; ++i) {
      const double a = 0.03 * i + 2.0 * k;
      d.reference_positions.col(i) = Eigen::Vector3d(4 * std::cos(a) + 3 * k, 3 * std::sin(a), 1);
      d.estimate_positions.col(i) =
          d.reference_positions.col(i) + Eigen::Vector3d(0.002 * i, -0.001 * i, 0);
    }
    drones.push_back(d);
  }
  return drones;
}

TEST(Plots, TopViewWritesADeterministicPng) {
  testing::TempDir dir;
  const std::string a = dir.File("a.png");
  const std::string b = dir.File("b.png");
  ASSERT_TRUE(PlotTopView(ThreeDrones(), {}, a).ok());
  ASSERT_TRUE(PlotTopView(ThreeDrones(), {}, b).ok());
  const std::string bytes = ReadBytes(a);
  ASSERT_GT(bytes.size(), 1000u);
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(bytes, ReadBytes(b));
}

TEST(Plots, ErrorOverTime) {
  testing::TempDir dir;
  std::vector<ErrorSeries> drones(2);
  for (int k = 0; k < 2; ++k) {
    drones[k].name = "uav" + std::to_string(k);
    for (int i = 0; i < 100; ++i) {
      drones[k].time_s.push_back(1000.0 + 0.1 * i + k);
      drones[k].error.push_back(0.01 * (k + 1) * (1.0 + std::sin(0.2 * i)));
    }
  }
  PlotOptions options;
  options.width_px = 800;
  options.height_px = 500;
  const std::string path = dir.File("errors.png");
  ASSERT_TRUE(PlotErrorOverTime(drones, "APE translation [m]", options, path).ok());
  EXPECT_GT(ReadBytes(path).size(), 1000u);
}

TEST(Plots, FailuresAreStatusesNotCrashes) {
  testing::TempDir dir;
  // The directory does not exist.
  const Status unwritable = PlotTopView(ThreeDrones(), {}, dir.File("no/such/dir/top.png"));
  EXPECT_EQ(unwritable.code(), Status::Code::kIoError);
  EXPECT_NE(unwritable.message().find("no/such/dir/top.png"), std::string::npos);
  // Nothing finite to plot.
  EXPECT_EQ(PlotTopView({}, {}, dir.File("empty.png")).code(), Status::Code::kInvalidArgument);
  ErrorSeries nan_only{"uav0", {0.0, 1.0}, {std::nan(""), std::nan("")}};
  EXPECT_FALSE(PlotErrorOverTime({nan_only}, "e", {}, dir.File("nan.png")).ok());
  // Mismatched lengths and bad sizes.
  ErrorSeries mismatched{"uav0", {0.0, 1.0}, {0.5}};
  EXPECT_FALSE(PlotErrorOverTime({mismatched}, "e", {}, dir.File("m.png")).ok());
  PlotOptions tiny;
  tiny.width_px = 10;
  EXPECT_FALSE(PlotTopView(ThreeDrones(), tiny, dir.File("tiny.png")).ok());
  // A single point and a constant series still plot.
  ErrorSeries flat{"uav0", {5.0}, {0.0}};
  EXPECT_TRUE(PlotErrorOverTime({flat}, "e", {}, dir.File("flat.png")).ok());
}

TEST(Plots, SeriesFromApe) {
  const Trajectory reference = testing::Curve(30);
  ApeOptions options;
  options.alignment = Alignment::kSe3;
  ApeResult ape;
  ASSERT_TRUE(ComputeApe(reference, reference, options, &ape).ok());
  const TopViewSeries top = TopViewSeriesFromApe("uav0", ape);
  EXPECT_EQ(top.estimate_positions.cols(), 30);
  EXPECT_EQ(top.reference_positions.cols(), 30);
  const ErrorSeries errors = ErrorSeriesFromApe("uav0", ape);
  ASSERT_EQ(errors.time_s.size(), 30u);
  EXPECT_EQ(errors.time_s[0], reference.stamps_s[0]);
}

TEST(Chart, NiceTickSteps) {
  EXPECT_DOUBLE_EQ(internal::NiceTickStep(10.0, 8), 2.0);
  EXPECT_DOUBLE_EQ(internal::NiceTickStep(1.0, 8), 0.2);
  EXPECT_DOUBLE_EQ(internal::NiceTickStep(0.037, 8), 0.005);
  EXPECT_DOUBLE_EQ(internal::NiceTickStep(700.0, 8), 100.0);
  EXPECT_DOUBLE_EQ(internal::NiceTickStep(0.0, 8), 1.0);
}

}  // namespace
}  // namespace swarmlio::eval
