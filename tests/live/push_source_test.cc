// PushSource (the ROS node's input): whatever the interleaving of the IMU and
// LiDAR pushes, records come out in the bag reader's order (stamp, IMU
// first); the bounded wait releases a record whose other stream is silent
// and a record stamped before a released one is dropped as late; scans are
// dropped whole when too many wait, IMU pushes block instead. The IMU-first
// ordering releases IMU samples on arrival (those after a scan's end too,
// which the exact order holds for the next scan) and a scan once the IMU
// passed its stamp, and the odometry fed in that order (scans later than a
// scan period) equals the stamp order's bit for bit, the static start's map
// seeding included. End to end, in both orderings: a LiveDrone fed by a
// PushSource, its scans pushed late as a driver publishes them (later than a
// scan period), reproduces the offline replay of the same bag bit for bit.
#include "swarmlio/live/push_source.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <tuple>
#include <vector>

#include "swarmlio/io/bag_reader.h"
#include "swarmlio/live/live_drone.h"
#include "swarmlio/lio/odometry.h"
#include "swarmlio/live/steady_clock.h"
#include "swarmlio/net/simulated_network.h"
#include "swarmlio/replay/swarm_replay.h"
#include "test_utils/simulated_swarm.h"
#include "test_utils/temp_dir.h"

namespace swarmlio::live {
namespace {

/// Time that moves only when the test says so.
class ManualClock : public Clock {
 public:
  int64_t NowNs() const override { return now_ns_.load(); }
  void SleepForNs(int64_t duration_ns) const override {
    std::this_thread::sleep_for(std::chrono::nanoseconds(std::min<int64_t>(duration_ns, 1'000'000)));
  }
  void Advance(int64_t ns) { now_ns_ += ns; }

 private:
  std::atomic<int64_t> now_ns_{1'000'000'000};
};

ImuSample Imu(int64_t stamp_ns) {
  ImuSample imu;
  imu.stamp_ns = stamp_ns;
  return imu;
}

LidarScan Scan(int64_t stamp_ns) {
  LidarScan scan;
  scan.stamp_ns = stamp_ns;
  scan.points.resize(1);
  return scan;
}

// (stamp, 0 = IMU / 1 = scan) of every record until the end.
std::vector<std::tuple<int64_t, int>> Drain(PushSource* source) {
  std::vector<std::tuple<int64_t, int>> out;
  SourceStart start;
  bool has = false;
  if (!source->Start(&start, &has).ok() || !has) return out;
  const SensorTimeMapping mapping;
  io::BagRecord record;
  while (source->Next(mapping, &record, &has).ok() && has) {
    out.emplace_back(record.stamp_ns(), record.scan() != nullptr ? 1 : 0);
  }
  return out;
}

// A scan of one point at each of `offsets_s` after its stamp (the scan end
// is the stamp + the largest).
LidarScan ScanWithOffsets(int64_t stamp_ns, const std::vector<double>& offsets_s) {
  LidarScan scan;
  scan.stamp_ns = stamp_ns;
  for (const double offset_s : offsets_s) {
    LidarPoint p;
    p.offset_time_s = offset_s;
    scan.points.push_back(p);
  }
  return scan;
}

/// Drains a source on its own thread; the records released so far can be
/// read (and waited for) while the test pushes.
class Consumer {
 public:
  explicit Consumer(PushSource* source) : thread_([this, source] { Run(source); }) {}
  ~Consumer() {
    if (thread_.joinable()) thread_.join();
  }
  /// Waits (up to 10 s: only a stalled thread takes long) until `n` records
  /// came out; returns them.
  std::vector<std::tuple<int64_t, int>> WaitFor(size_t n) {
    for (int i = 0; i < 5000; ++i) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (released_.size() >= n) break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return Released();
  }
  std::vector<std::tuple<int64_t, int>> Released() {
    std::lock_guard<std::mutex> lock(mutex_);
    return released_;
  }
  void Join() { thread_.join(); }

 private:
  void Run(PushSource* source) {
    SourceStart start;
    bool has = false;
    if (!source->Start(&start, &has).ok() || !has) return;
    io::BagRecord record;
    while (source->Next(SensorTimeMapping(), &record, &has).ok() && has) {
      std::lock_guard<std::mutex> lock(mutex_);
      released_.emplace_back(record.stamp_ns(), record.scan() != nullptr ? 1 : 0);
    }
  }
  std::mutex mutex_;
  std::vector<std::tuple<int64_t, int>> released_;
  std::thread thread_;
};

// One scan [1.0 s, 1.1 s] and IMU samples every 5 ms from 0.995 s to 1.11 s,
// the scan pushed first (a driver stamping and publishing early). Returns
// what came out before Close() and after.
void PushScanThenImu(PushOrdering ordering, std::vector<std::tuple<int64_t, int>>* before_close,
                     std::vector<std::tuple<int64_t, int>>* all, size_t wait_for) {
  ManualClock clock;  // never advances: no record is released by the timeout
  PushSourceOptions options;
  options.ordering = ordering;
  std::unique_ptr<PushSource> source;
  ASSERT_TRUE(PushSource::Create(options, &clock, &source).ok());
  Consumer consumer(source.get());
  source->PushScan(ScanWithOffsets(1'000'000'000, {0.0, 0.05, 0.1}));
  for (int64_t t = 995'000'000; t <= 1'110'000'000; t += 5'000'000) source->PushImu(Imu(t));
  *before_close = consumer.WaitFor(wait_for);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));  // nothing more comes
  *before_close = consumer.Released();
  source->Close();
  consumer.Join();
  *all = consumer.Released();
  EXPECT_EQ(source->stats().released_by_timeout, 0);
}

TEST(PushSource, ImuFirstReleasesImuAfterTheScanEndAtOnce) {
  // 24 IMU samples (0.995 .. 1.11 s) and the scan; the exact order is the
  // same in both orderings here.
  std::vector<std::tuple<int64_t, int>> expected;
  for (int64_t t = 995'000'000; t <= 1'110'000'000; t += 5'000'000) expected.emplace_back(t, 0);
  expected.emplace_back(1'000'000'000, 1);
  std::sort(expected.begin(), expected.end());
  ASSERT_EQ(expected.size(), 25u);

  std::vector<std::tuple<int64_t, int>> before_close, all;
  // Stamp order: the samples after the scan end (1.105, 1.11 s) wait for the
  // next scan (here: the close), the scan's odometry with them.
  PushScanThenImu(PushOrdering::kStamp, &before_close, &all, 23);
  const std::vector<std::tuple<int64_t, int>> up_to_scan_end(expected.begin(), expected.end() - 2);
  EXPECT_EQ(before_close, up_to_scan_end);
  EXPECT_EQ(all, expected);
  // IMU first: everything goes at once, in the same order.
  PushScanThenImu(PushOrdering::kImuFirst, &before_close, &all, 25);
  EXPECT_EQ(before_close, expected);
  EXPECT_EQ(all, expected);
}

TEST(PushSource, ImuFirstScanWaitsForTheImuToPassItsStamp) {
  ManualClock clock;
  PushSourceOptions options;
  options.ordering = PushOrdering::kImuFirst;
  std::unique_ptr<PushSource> source;
  ASSERT_TRUE(PushSource::Create(options, &clock, &source).ok());
  Consumer consumer(source.get());
  // A scan published at its end, 0.1 s late: the IMU samples over it and
  // after it come out before it, on arrival.
  for (int64_t t = 1'000'000'000; t <= 1'100'000'000; t += 10'000'000) source->PushImu(Imu(t));
  EXPECT_EQ(consumer.WaitFor(11).size(), 11u);
  source->PushScan(ScanWithOffsets(1'000'000'000, {0.0, 0.1}));
  EXPECT_EQ(consumer.WaitFor(12).back(), std::make_tuple(int64_t{1'000'000'000}, 1));
  // A scan ahead of the IMU waits until an IMU sample reaches its stamp
  // (every sample up to it first, as in the bag order).
  source->PushScan(ScanWithOffsets(1'200'000'000, {0.0, 0.1}));
  source->PushImu(Imu(1'190'000'000));
  EXPECT_EQ(consumer.WaitFor(13).size(), 13u);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(consumer.Released().size(), 13u);  // the scan still waits
  source->PushImu(Imu(1'200'000'000));         // ties: the IMU sample first
  const auto released = consumer.WaitFor(15);
  ASSERT_EQ(released.size(), 15u);
  EXPECT_EQ(released[13], std::make_tuple(int64_t{1'200'000'000}, 0));
  EXPECT_EQ(released[14], std::make_tuple(int64_t{1'200'000'000}, 1));
  // Late against its own stream (a scan before released IMU samples is not,
  // above): an IMU sample before the last released one, a scan before the
  // last released scan.
  source->PushImu(Imu(1'150'000'000));
  source->PushScan(ScanWithOffsets(1'100'000'000, {0.0}));
  source->Close();
  consumer.Join();
  const PushSourceStats st = source->stats();
  EXPECT_EQ(st.imu_late, 1);
  EXPECT_EQ(st.scans_late, 1);  // 1.1 s < the released scan at 1.2 s
  EXPECT_EQ(st.released, 15);
  EXPECT_EQ(st.released_by_timeout, 0);
}

TEST(PushSource, OrderingOptionValidatedAndNamed) {
  EXPECT_STREQ(config::EnumToString(PushOrdering::kImuFirst), "imu_first");
  PushOrdering ordering = PushOrdering::kImuFirst;
  EXPECT_TRUE(config::EnumFromString("stamp", &ordering));
  EXPECT_EQ(ordering, PushOrdering::kStamp);
  EXPECT_FALSE(config::EnumFromString("arrival", &ordering));
  PushSourceOptions options;
  EXPECT_EQ(options.ordering, PushOrdering::kStamp);  // exact unless asked
  EXPECT_EQ(options.Validate(), "");
  options.max_wait_ms = -1.0;
  EXPECT_NE(options.Validate(), "");
}

TEST(PushSource, StampOrderWhateverTheInterleaving) {
  ManualClock clock;  // never advances: no record is released by the timeout
  PushSourceOptions options;
  options.max_buffered_scans = 1000;  // a consumer starved by the scheduler drops nothing
  std::unique_ptr<PushSource> source;
  ASSERT_TRUE(PushSource::Create(options, &clock, &source).ok());
  constexpr int kImu = 400;       // 2 s at 200 Hz
  constexpr int64_t kImuPeriodNs = 5'000'000;
  constexpr int64_t kScanPeriodNs = 100'000'000;
  constexpr int64_t kT0 = 7'000'000'000;
  std::atomic<int64_t> imu_pushed_until{0};
  std::vector<std::tuple<int64_t, int>> released;
  std::thread consumer([&] { released = Drain(source.get()); });
  std::thread imu([&] {
    for (int i = 0; i < kImu; ++i) {
      source->PushImu(Imu(kT0 + i * kImuPeriodNs));
      imu_pushed_until = kT0 + i * kImuPeriodNs;
      if (i % 7 == 0) std::this_thread::yield();
    }
  });
  std::thread lidar([&] {
    // A scan stamped at its start is published at its end: after the IMU
    // samples over it (and, racing, sometimes before a few of them).
    for (int64_t s = kT0; s < kT0 + kImu * kImuPeriodNs - kScanPeriodNs; s += kScanPeriodNs) {
      while (imu_pushed_until.load() < s + kScanPeriodNs - 3 * kImuPeriodNs) {
        std::this_thread::yield();
      }
      source->PushScan(Scan(s));
    }
  });
  imu.join();
  lidar.join();
  source->Close();
  consumer.join();

  std::vector<std::tuple<int64_t, int>> expected;
  for (int i = 0; i < kImu; ++i) expected.emplace_back(kT0 + i * kImuPeriodNs, 0);
  for (int64_t s = kT0; s < kT0 + kImu * kImuPeriodNs - kScanPeriodNs; s += kScanPeriodNs) {
    expected.emplace_back(s, 1);
  }
  std::sort(expected.begin(), expected.end());  // stamp, then IMU (0) before scan (1)
  EXPECT_EQ(released, expected);
  const PushSourceStats st = source->stats();
  EXPECT_EQ(st.released, static_cast<int64_t>(expected.size()));
  EXPECT_EQ(st.released_by_timeout, 0);
  EXPECT_EQ(st.imu_late + st.scans_late + st.scans_dropped_full, 0);
}

TEST(PushSource, BoundedWaitThenLateRecordsAreDropped) {
  ManualClock clock;
  PushSourceOptions options;
  options.max_wait_ms = 100.0;
  std::unique_ptr<PushSource> source;
  ASSERT_TRUE(PushSource::Create(options, &clock, &source).ok());
  std::atomic<int> released{0};
  std::thread consumer([&] {
    SourceStart start;
    bool has = false;
    if (!source->Start(&start, &has).ok() || !has) return;
    io::BagRecord record;
    while (source->Next(SensorTimeMapping(), &record, &has).ok() && has) ++released;
  });
  source->PushImu(Imu(2'000'000'000));  // the LiDAR stream is silent
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  EXPECT_EQ(released.load(), 0);  // waits for the LiDAR stream to pass its stamp
  clock.Advance(100'000'000);     // max_wait_ms later
  for (int i = 0; i < 500 && released.load() == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  EXPECT_EQ(released.load(), 1);
  source->PushScan(Scan(1'999'000'000));  // before the released IMU sample: late
  source->PushImu(Imu(1'998'000'000));
  source->Interrupt();
  consumer.join();
  const PushSourceStats st = source->stats();
  EXPECT_EQ(st.released_by_timeout, 1);
  EXPECT_EQ(st.scans_late, 1);
  EXPECT_EQ(st.imu_late, 1);
}

TEST(PushSource, ScansDroppedWholeImuNeverDropped) {
  ManualClock clock;
  PushSourceOptions options;
  options.max_buffered_scans = 2;
  options.max_buffered_records = 16;
  std::unique_ptr<PushSource> source;
  ASSERT_TRUE(PushSource::Create(options, &clock, &source).ok());
  for (int k = 0; k < 3; ++k) source->PushScan(Scan(1'000'000'000 + k));
  EXPECT_EQ(source->stats().scans_dropped_full, 1);
  constexpr int kImu = 40;  // more than the buffer holds: the pushes wait for the consumer
  std::thread imu([&] {
    for (int i = 0; i < kImu; ++i) source->PushImu(Imu(1'000'000'000 + 10 * i));
  });
  for (int i = 0; i < 5000 && source->stats().imu_push_waits == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_GT(source->stats().imu_push_waits, 0);  // blocked on the full buffer, not dropped
  std::vector<std::tuple<int64_t, int>> released;
  std::thread consumer([&] { released = Drain(source.get()); });
  imu.join();
  source->Close();
  consumer.join();
  int imu_out = 0, scans_out = 0;
  for (const auto& r : released) ++(std::get<1>(r) == 0 ? imu_out : scans_out);
  EXPECT_EQ(imu_out, kImu);
  EXPECT_EQ(scans_out, 2);
  EXPECT_TRUE(std::is_sorted(released.begin(), released.end()));
}

// The drone's odometry fed its bag directly (no threads): each scan given
// once the IMU has passed its stamp by `scan_delay_ns` (0: the bag's stamp
// order), as kImuFirst releases a scan published that late.
std::vector<lio::ScanOutput> RunOdometry(const driver::DroneInput& drone, int64_t scan_delay_ns,
                                         lio::OdometryCounters* counters) {
  std::vector<lio::ScanOutput> outputs;
  std::unique_ptr<lio::Odometry> odometry;
  std::unique_ptr<io::BagReader> reader;
  if (!lio::Odometry::Create(drone.odometry, drone.lidar, &odometry).ok() ||
      !io::BagReader::Open(drone.bag_path, drone.bag, &reader).ok()) {
    return outputs;
  }
  std::deque<LidarScan> held;
  io::BagRecord record;
  bool has = false;
  // Each input is processed as it comes, as the component does.
  const auto process = [&] { (void)odometry->ProcessReadyScans(/*flush=*/false, &outputs); };
  while (reader->Next(&record, &has).ok() && has) {
    if (const ImuSample* imu = record.imu()) {
      (void)odometry->AddImu(*imu);  // errors are counted; the comparison shows them
      process();
      while (!held.empty() && held.front().stamp_ns + scan_delay_ns <= imu->stamp_ns) {
        (void)odometry->AddScan(held.front());
        process();
        held.pop_front();
      }
    } else if (const LidarScan* scan = record.scan()) {
      held.push_back(*scan);
      if (scan_delay_ns == 0) {
        (void)odometry->AddScan(held.front());
        process();
        held.pop_front();
      }
    }
  }
  for (const LidarScan& scan : held) {
    (void)odometry->AddScan(scan);
    process();
  }
  (void)odometry->ProcessReadyScans(/*flush=*/true, &outputs);
  *counters = odometry->counters();
  return outputs;
}

TEST(PushSource, OdometryOfTheImuFirstOrderEqualsTheStampOrders) {
  // Scans 0.25 s late (the driver's 0.1 s and a slow transport; more than a
  // scan period): the static start's last window scans reach the odometry
  // after the IMU sample completing its initialization and must still seed
  // the map, as in stamp order (lio.md step 7). Deterministic, unlike the
  // LiveDrone test below, whose consumer may lag and re-sort the buffer.
  swarmlio::testing::TempDir dir;
  driver::SwarmManifest manifest;
  ASSERT_TRUE(swarmlio::testing::SimulateSwarm(
      std::string(SWARMLIO_SOURCE_DIR) + "/configs/scenarios/indoor_3uav.yaml", "order", 4.0,
      dir.path(), &manifest));
  lio::OdometryCounters stamp_counters, imu_first_counters;
  const std::vector<lio::ScanOutput> stamp = RunOdometry(manifest.drones[0], 0, &stamp_counters);
  const std::vector<lio::ScanOutput> imu_first =
      RunOdometry(manifest.drones[0], 250'000'000, &imu_first_counters);
  ASSERT_GT(stamp.size(), 20u);
  ASSERT_EQ(imu_first.size(), stamp.size());
  EXPECT_GT(stamp_counters.scans_seeding_map, 0);
  EXPECT_EQ(imu_first_counters.scans_seeding_map, stamp_counters.scans_seeding_map);
  double max_dp = 0.0;
  for (size_t i = 0; i < stamp.size(); ++i) {
    EXPECT_EQ(imu_first[i].stamp_ns, stamp[i].stamp_ns);
    max_dp = std::max(max_dp, (imu_first[i].state.p_b_in_G - stamp[i].state.p_b_in_G).norm());
  }
  EXPECT_EQ(max_dp, 0.0);  // bit for bit
}

/// Keeps the scan outputs (estimator thread; read after Run()).
class ScanSink : public LiveSink {
 public:
  void OnScan(const swarm::DroneOutput& output, const ScanLatency& /*latency*/) override {
    scans.push_back(replay::KeptOutput(output));
  }
  std::vector<swarm::DroneOutput> scans;
};

class PushSourceOrdering : public ::testing::TestWithParam<PushOrdering> {};

TEST_P(PushSourceOrdering, LiveDroneFedByPushesReproducesTheOfflineReplay) {
  swarmlio::testing::TempDir dir;
  driver::SwarmManifest manifest;
  ASSERT_TRUE(swarmlio::testing::SimulateSwarm(
      std::string(SWARMLIO_SOURCE_DIR) + "/configs/scenarios/indoor_3uav.yaml", "push", 6.0,
      dir.path(), &manifest));
  manifest.drones.resize(1);
  const driver::DroneInput& drone = manifest.drones[0];
  std::unique_ptr<replay::SwarmReplay> offline;
  Status s = replay::SwarmReplay::Create(manifest, &offline);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_TRUE(offline->Run(replay::ReplayOptions()).ok());
  const std::vector<swarm::DroneOutput>& reference = offline->drone(0).scans();
  ASSERT_GT(reference.size(), 30u);

  SteadyClock clock;
  PushSourceOptions push_options;
  push_options.ordering = GetParam();
  push_options.max_wait_ms = 60'000.0;  // a loaded machine never releases early
  push_options.max_buffered_scans = 1000;
  std::unique_ptr<PushSource> source;
  ASSERT_TRUE(PushSource::Create(push_options, &clock, &source).ok());
  std::unique_ptr<net::SimulatedNetwork> network;
  ASSERT_TRUE(net::SimulatedNetwork::Create(net::NetworkOptions(), {0, 1}, &network).ok());
  ScanSink sink;
  LiveSetup setup;
  setup.drone = drone;
  setup.drone_id = 0;
  setup.transport = network->Endpoint(0);
  setup.clock = &clock;
  setup.sink = &sink;
  setup.source = source.get();
  LiveOptions options;
  options.max_queued_scans = 1000;   // pushed faster than real time: nothing dropped
  options.max_scan_backlog_s = 60.0;
  std::unique_ptr<LiveDrone> live;
  s = LiveDrone::Create(setup, options, &live);
  ASSERT_TRUE(s.ok()) << s.message();
  Status run_status;
  std::thread runner([&] { run_status = live->Run(); });

  // The bag's records, each scan pushed only once the IMU has passed its
  // stamp by 0.25 s (a driver publishing at the scan end, 0.1 s, and a slow
  // transport), as fast as possible (so the consumer may lag and the buffer
  // re-sort some records: the order without a lag is the test above's).
  std::unique_ptr<io::BagReader> reader;
  ASSERT_TRUE(io::BagReader::Open(drone.bag_path, drone.bag, &reader).ok());
  std::vector<LidarScan> held;
  io::BagRecord record;
  bool has = false;
  int64_t pushed_scans = 0;
  while (reader->Next(&record, &has).ok() && has) {
    if (const ImuSample* imu = record.imu()) {
      source->PushImu(*imu);
      while (!held.empty() && held.front().stamp_ns + 250'000'000 <= imu->stamp_ns) {
        source->PushScan(std::move(held.front()));
        held.erase(held.begin());
        ++pushed_scans;
      }
    } else if (LidarScan* scan = std::get_if<LidarScan>(&record.data)) {
      held.push_back(std::move(*scan));
    }
  }
  for (LidarScan& scan : held) {
    source->PushScan(std::move(scan));
    ++pushed_scans;
  }
  source->Close();
  runner.join();
  ASSERT_TRUE(run_status.ok()) << run_status.message();
  const PushSourceStats st = source->stats();
  EXPECT_EQ(st.scans_pushed, pushed_scans);
  EXPECT_EQ(st.released_by_timeout + st.imu_late + st.scans_late + st.scans_dropped_full, 0);
  EXPECT_EQ(live->stats().scans_dropped_queue + live->stats().scans_dropped_backlog, 0);
  ASSERT_EQ(sink.scans.size(), reference.size());
  double max_dp = 0.0;
  for (size_t i = 0; i < reference.size(); ++i) {
    EXPECT_EQ(sink.scans[i].ego.stamp_ns, reference[i].ego.stamp_ns);
    max_dp = std::max(max_dp, (sink.scans[i].ego.state.p_b_in_G - reference[i].ego.state.p_b_in_G).norm());
  }
  EXPECT_LE(max_dp, 1e-9);
  std::printf("pushed live (%s order) vs offline replay: %zu scans, max position difference "
              "%.3g m\n",
              config::EnumToString(GetParam()), reference.size(), max_dp);
}

INSTANTIATE_TEST_SUITE_P(BothOrderings, PushSourceOrdering,
                         ::testing::Values(PushOrdering::kStamp, PushOrdering::kImuFirst),
                         [](const ::testing::TestParamInfo<PushOrdering>& param) {
                           return std::string(param.param == PushOrdering::kStamp ? "Stamp"
                                                                                  : "ImuFirst");
                         });

}  // namespace
}  // namespace swarmlio::live
