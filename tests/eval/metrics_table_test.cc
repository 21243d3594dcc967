#include "swarmlio/eval/metrics_table.h"

#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <sstream>

#include "tests/eval/eval_test_util.h"

namespace swarmlio::eval {
namespace {

MetricsTable SmallTable() {
  MetricsTable table;
  EXPECT_TRUE(table.AddColumn({"drone", "drone", 0}).ok());
  EXPECT_TRUE(table.AddColumn({"ape_rmse_m", "APE rmse [m]", 3}).ok());
  EXPECT_TRUE(table.AddColumn({"update_ms", "", 1}).ok());
  EXPECT_TRUE(
      table.AddRow({{"drone", std::string("uav0")}, {"ape_rmse_m", 0.1}, {"update_ms", 2.25}})
          .ok());
  EXPECT_TRUE(table
                  .AddRow({{"drone", std::string("uav|1, \"b\"")},
                           {"ape_rmse_m", std::numeric_limits<double>::quiet_NaN()}})
                  .ok());
  return table;
}

TEST(MetricsTable, Markdown) {
  EXPECT_EQ(SmallTable().ToMarkdown(),
            "| drone       | APE rmse [m] | update_ms |\n"
            "| ----------- | -----------: | --------: |\n"
            "| uav0        |        0.100 |       2.2 |\n"
            "| uav\\|1, \"b\" |          n/a |       n/a |\n");
}

TEST(MetricsTable, Csv) {
  EXPECT_EQ(SmallTable().ToCsv(),
            "drone,ape_rmse_m,update_ms\n"
            "uav0,0.1,2.25\n"
            "\"uav|1, \"\"b\"\"\",,\n");
}

TEST(MetricsTable, Json) {
  EXPECT_EQ(SmallTable().ToJson(),
            "{\n"
            "  \"columns\": [\n"
            "    {\"key\": \"drone\", \"header\": \"drone\"},\n"
            "    {\"key\": \"ape_rmse_m\", \"header\": \"APE rmse [m]\"},\n"
            "    {\"key\": \"update_ms\", \"header\": \"update_ms\"}\n"
            "  ],\n"
            "  \"rows\": [\n"
            "    {\"drone\": \"uav0\", \"ape_rmse_m\": 0.1, \"update_ms\": 2.25},\n"
            "    {\"drone\": \"uav|1, \\\"b\\\"\", \"ape_rmse_m\": null, \"update_ms\": null}\n"
            "  ]\n"
            "}\n");
}

TEST(MetricsTable, NumbersRoundTripInCsv) {
  MetricsTable table;
  ASSERT_TRUE(table.AddColumn({"x", "x", 2}).ok());
  const double value = 0.1 + 0.2;  // 0.30000000000000004
  ASSERT_TRUE(table.AddRow({{"x", value}}).ok());
  EXPECT_EQ(table.ToCsv(), "x\n0.30000000000000004\n");
}

TEST(MetricsTable, Errors) {
  MetricsTable table;
  ASSERT_TRUE(table.AddColumn({"a", "A", 2}).ok());
  EXPECT_FALSE(table.AddColumn({"a", "again", 2}).ok());
  EXPECT_FALSE(table.AddColumn({"", "empty", 2}).ok());
  EXPECT_FALSE(table.AddColumn({"has space", "x", 2}).ok());
  EXPECT_FALSE(table.AddColumn({"b", "B", -1}).ok());
  EXPECT_FALSE(table.AddRow({{"nope", 1.0}}).ok());
  EXPECT_FALSE(table.AddRow({{"a", 1.0}, {"a", 2.0}}).ok());
  EXPECT_EQ(table.num_rows(), 0u);
}

TEST(MetricsTable, WritesAllThreeFiles) {
  testing::TempDir dir;
  const MetricsTable table = SmallTable();
  ASSERT_TRUE(table.WriteAll(dir.File("metrics")).ok());
  for (const auto& [suffix, format] :
       {std::pair{".md", TableFormat::kMarkdown}, std::pair{".csv", TableFormat::kCsv},
        std::pair{".json", TableFormat::kJson}}) {
    std::ifstream file(dir.File(std::string("metrics") + suffix));
    std::stringstream text;
    text << file.rdbuf();
    EXPECT_EQ(text.str(), table.Format(format)) << suffix;
  }
  const Status status = table.WriteAll(dir.File("missing/dir/metrics"));
  EXPECT_EQ(status.code(), Status::Code::kIoError);
}

}  // namespace
}  // namespace swarmlio::eval
