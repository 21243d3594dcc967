// lio::InputSynchronizer: scans wait for the IMU to cover their end, in
// arrival order; out-of-order IMU samples and scans are refused with the
// state unchanged; an overflowing queue drops its oldest scan; a replay
// (in-flight initialization) and a restart reset the scan order.
#include "swarmlio/lio/input_synchronizer.h"

#include <gtest/gtest.h>

#include <vector>

namespace swarmlio::lio {
namespace {

PendingScan Scan(int64_t start_ns, int64_t end_ns) {
  PendingScan p;
  p.scan.stamp_ns = start_ns;
  p.end_ns = end_ns;
  return p;
}

TEST(InputSynchronizer, AScanWaitsUntilTheImuCoversItsEnd) {
  InputSynchronizer sync(4);
  PendingScan out;
  EXPECT_FALSE(sync.PopReady(false, &out));  // nothing queued
  ASSERT_TRUE(sync.AddScan(Scan(0, 100)).ok());
  ASSERT_TRUE(sync.AddScan(Scan(100, 200)).ok());
  EXPECT_FALSE(sync.PopReady(false, &out));  // no IMU yet
  ASSERT_TRUE(sync.AddImuStamp(99, 99).ok());
  EXPECT_FALSE(sync.PopReady(false, &out));  // 99 < 100
  ASSERT_TRUE(sync.AddImuStamp(100, 100).ok());
  ASSERT_TRUE(sync.PopReady(false, &out));  // covered exactly at its end
  EXPECT_EQ(out.end_ns, 100);
  EXPECT_FALSE(sync.PopReady(false, &out));  // the second ends at 200
  ASSERT_TRUE(sync.PopReady(true, &out));    // the end of the log takes it anyway
  EXPECT_EQ(out.end_ns, 200);
  EXPECT_EQ(sync.num_queued(), 0u);
}

TEST(InputSynchronizer, RefusesImuSamplesNotAfterThePreviousOne) {
  InputSynchronizer sync(4);
  ASSERT_TRUE(sync.AddImuStamp(50, 60).ok());
  const Status same = sync.AddImuStamp(50, 60);
  EXPECT_EQ(same.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(same.message().find("at 60 ns"), std::string::npos) << same.message();  // the raw stamp
  EXPECT_EQ(sync.AddImuStamp(40, 50).code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(sync.newest_imu_ns(), 50);  // unchanged
  EXPECT_TRUE(sync.AddImuStamp(51, 61).ok());
}

TEST(InputSynchronizer, RefusesScansNotEndingAfterTheQueuedOrProcessedOne) {
  InputSynchronizer sync(4);
  ASSERT_TRUE(sync.AddScan(Scan(0, 100)).ok());
  EXPECT_EQ(sync.AddScan(Scan(10, 100)).code(), Status::Code::kInvalidArgument);  // same end
  EXPECT_EQ(sync.num_queued(), 1u);
  ASSERT_TRUE(sync.AddImuStamp(150, 150).ok());
  PendingScan out;
  ASSERT_TRUE(sync.PopReady(false, &out));
  // Nothing queued and nothing processed yet: any scan is accepted.
  ASSERT_TRUE(sync.AddScan(Scan(0, 90)).ok());
  ASSERT_TRUE(sync.PopReady(false, &out));
  sync.MarkProcessed(out.end_ns);
  EXPECT_EQ(sync.AddScan(Scan(50, 90)).code(), Status::Code::kInvalidArgument);
  EXPECT_TRUE(sync.AddScan(Scan(50, 91)).ok());
}

TEST(InputSynchronizer, AnOverflowingQueueDropsItsOldestScan) {
  InputSynchronizer sync(2);
  ASSERT_TRUE(sync.AddScan(Scan(0, 100)).ok());
  ASSERT_TRUE(sync.AddScan(Scan(100, 200)).ok());
  const Status dropped = sync.AddScan(Scan(200, 300));
  EXPECT_EQ(dropped.code(), Status::Code::kOutOfRange);
  EXPECT_NE(dropped.message().find("dropped the scan at 0 ns"), std::string::npos)
      << dropped.message();
  EXPECT_EQ(sync.num_queued(), 2u);
  PendingScan out;
  ASSERT_TRUE(sync.PopReady(true, &out));
  EXPECT_EQ(out.end_ns, 200);  // the oldest went
}

TEST(InputSynchronizer, ReplayAndRestartForgetTheScanOrder) {
  InputSynchronizer sync(8);
  ASSERT_TRUE(sync.AddImuStamp(1000, 1000).ok());
  ASSERT_TRUE(sync.AddScan(Scan(400, 500)).ok());
  PendingScan out;
  ASSERT_TRUE(sync.PopReady(false, &out));
  sync.MarkProcessed(500);
  // The in-flight initialization re-plays its scans from its start.
  sync.ReplayScans({Scan(0, 100), Scan(100, 200)});
  EXPECT_EQ(sync.num_queued(), 2u);
  ASSERT_TRUE(sync.PopReady(false, &out));
  EXPECT_EQ(out.end_ns, 100);
  EXPECT_EQ(sync.AddScan(Scan(0, 150)).code(), Status::Code::kInvalidArgument);  // before 200
  sync.ClearScans();
  EXPECT_EQ(sync.num_queued(), 0u);
  EXPECT_TRUE(sync.AddScan(Scan(0, 150)).ok());  // a restart accepts any
  EXPECT_EQ(sync.newest_imu_ns(), 1000);          // the IMU order stays
}

}  // namespace
}  // namespace swarmlio::lio
