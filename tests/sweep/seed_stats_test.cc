#include "seed_stats.h"

#include <gtest/gtest.h>

namespace swarmlio::sweep {
namespace {

TEST(SeedStats, MeanStdRangeAndTInterval) {
  // 2, 4, 4, 4, 5, 5, 7, 9: mean 5, sample std sqrt(32 / 7).
  const SeedStats s = ComputeSeedStats({2, 4, 4, 4, 5, 5, 7, 9});
  EXPECT_EQ(s.n, 8);
  EXPECT_DOUBLE_EQ(s.mean, 5.0);
  EXPECT_NEAR(s.std, 2.1380899, 1e-6);
  EXPECT_EQ(s.min, 2.0);
  EXPECT_EQ(s.max, 9.0);
  // t(0.975, 7) = 2.365: 5 -+ 2.365 * 2.1380899 / sqrt(8) = 5 -+ 1.78777
  EXPECT_NEAR(s.ci95_lo, 3.21223, 1e-4);
  EXPECT_NEAR(s.ci95_hi, 6.78777, 1e-4);
}

TEST(SeedStats, FourSeedsAsInTheScenarioSweep) {
  const SeedStats s = ComputeSeedStats({0.0032, 0.0038, 0.0022, 0.0036});
  EXPECT_NEAR(s.mean, 0.0032, 1e-12);
  EXPECT_NEAR(s.std, 0.000712, 1e-6);
  EXPECT_NEAR(s.ci95_hi - s.mean, 3.182 * s.std / 2.0, 1e-12);
}

TEST(SeedStats, OneOrNoValue) {
  const SeedStats one = ComputeSeedStats({3.0});
  EXPECT_EQ(one.n, 1);
  EXPECT_EQ(one.std, 0.0);
  EXPECT_EQ(one.ci95_lo, 3.0);
  EXPECT_EQ(one.ci95_hi, 3.0);
  EXPECT_EQ(ComputeSeedStats({}).n, 0);
}

TEST(SeedStats, StudentQuantiles) {
  EXPECT_DOUBLE_EQ(StudentT975(1), 12.706);
  EXPECT_DOUBLE_EQ(StudentT975(3), 3.182);
  EXPECT_DOUBLE_EQ(StudentT975(30), 2.042);
  EXPECT_NEAR(StudentT975(60), 2.000, 0.002);
  EXPECT_NEAR(StudentT975(120), 1.980, 0.002);
  EXPECT_NEAR(StudentT975(100000), 1.960, 0.001);
}

}  // namespace
}  // namespace swarmlio::sweep
