#include "swarmlio/eval/error_statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace swarmlio::eval {
namespace {

TEST(ErrorStatistics, EvenCount) {
  ErrorStatistics s;
  ASSERT_TRUE(ComputeErrorStatistics({4.0, 1.0, 3.0, 2.0}, &s).ok());
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));  // population, not sample
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  EXPECT_DOUBLE_EQ(s.sse, 30.0);
}

TEST(ErrorStatistics, OddCountAndSingleValue) {
  ErrorStatistics s;
  ASSERT_TRUE(ComputeErrorStatistics({9.0, 1.0, 5.0}, &s).ok());
  EXPECT_DOUBLE_EQ(s.median, 5.0);
  ASSERT_TRUE(ComputeErrorStatistics({0.5}, &s).ok());
  EXPECT_DOUBLE_EQ(s.median, 0.5);
  EXPECT_DOUBLE_EQ(s.std, 0.0);
}

TEST(ErrorStatistics, Errors) {
  ErrorStatistics s;
  EXPECT_FALSE(ComputeErrorStatistics({}, &s).ok());
  EXPECT_FALSE(ComputeErrorStatistics({1.0, std::numeric_limits<double>::quiet_NaN()}, &s).ok());
  EXPECT_FALSE(ComputeErrorStatistics({std::numeric_limits<double>::infinity()}, &s).ok());
}

TEST(Percentile, InterpolatesBetweenOrderStatistics) {
  EXPECT_EQ(Percentile({}, 0.5), 0.0);
  EXPECT_EQ(Percentile({3.0, 1.0, 2.0, 4.0}, 0.5), 2.5);  // the median
  EXPECT_EQ(Percentile({3.0, 1.0, 2.0, 4.0}, 0.0), 1.0);
  EXPECT_EQ(Percentile({3.0, 1.0, 2.0, 4.0}, 1.0), 4.0);
  EXPECT_DOUBLE_EQ(Percentile({0.0, 10.0}, 0.95), 9.5);
}

}  // namespace
}  // namespace swarmlio::eval
