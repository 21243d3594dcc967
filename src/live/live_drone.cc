// LiveDrone: the three threads of one live drone (live_drone.h, docs/online.md).
#include "swarmlio/live/live_drone.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>
#include <variant>
#include <vector>

#include "swarmlio/driver/drone_driver.h"
#include "swarmlio/io/bag_reader.h"
#include "swarmlio/live/bag_playback_source.h"
#include "swarmlio/live/bounded_queue.h"
#include "swarmlio/live/imu_rate_odometry.h"
#include "swarmlio/live/recording_transport.h"
#include "swarmlio/net/packet_codec.h"
#include "swarmlio/net/packet_log.h"

namespace swarmlio::live {
namespace {

// One bag record on its way to the estimator. A scan dropped at the input
// keeps only its stamp (memory stays bounded while the estimator is behind).
struct InputItem {
  int64_t stamp_ns = 0;
  bool dropped_scan = false;
  io::BagRecord record;
};

struct Outgoing {
  net::SwarmMessage message;  // sent stamped with the network thread's clock
};

LiveSink g_null_sink;

}  // namespace

// The estimator thread is the DroneDriver's; the Impl is its sink.
struct LiveDrone::Impl : driver::DriverSink {
  LiveSetup setup;
  LiveOptions options;
  LiveSink* sink = &g_null_sink;
  std::unique_ptr<RecordSource> owned_source;  // the bag playback when setup.source is null
  RecordSource* source = nullptr;
  std::unique_ptr<driver::DroneDriver> loop;  // the component in the drivers' one loop
  bool flushing = false;                      // the outputs come from the final flush
  std::unique_ptr<ImuRateOdometry> imu_rate;
  net::PacketCodec codec;
  std::unique_ptr<RecordingTransport> recording;
  std::unique_ptr<net::MessageChannel> channel;
  SensorTimeMapping mapping;  // set before the threads start, then read-only

  std::unique_ptr<BoundedQueue<InputItem>> input_queue;
  std::unique_ptr<BoundedQueue<net::ReceivedMessage>> messages;
  std::unique_ptr<BoundedQueue<Outgoing>> outbox;
  std::atomic<bool> stop{false};
  std::atomic<bool> estimator_done{false};
  std::atomic<int> scans_queued{0};

  // The sensor time up to which the network thread has polled.
  std::mutex watermark_mutex;
  std::condition_variable watermark_cv;
  int64_t watermark_ns = 0;
  bool network_done = false;

  // Each counter has one writer thread; all are read after the joins.
  LiveStats stats;
  Status input_error, network_error;
  bool ran = false;

  void InputLoop();
  void EstimatorLoop();
  void NetworkLoop();
  void WaitForNetwork(int64_t stamp_ns);
  void Deliver(int64_t stamp_ns, std::deque<net::ReceivedMessage>* pending);
  void OnOutputs(const std::vector<swarm::DroneOutput>& outputs) override;
  void OnMessages(std::vector<net::SwarmMessage>* messages) override;
  void Send(const Outgoing& out);
  double AccelerationFactor() const {
    const swarm::DroneEstimator& estimator = loop->estimator();
    return estimator.initialized() ? estimator.initialization().acceleration_to_m_s2 : 1.0;
  }
};

Status LiveDrone::Create(const LiveSetup& setup, const LiveOptions& options,
                         std::unique_ptr<LiveDrone>* drone) {
  const std::string& name = setup.drone.name;
  if (const std::string invalid = options.Validate(); !invalid.empty()) {
    return Status::InvalidArgument(name + ": live options: " + invalid);
  }
  if (setup.transport == nullptr || setup.clock == nullptr) {
    return Status::InvalidArgument(name + ": LiveSetup needs a transport and a clock");
  }
  if (setup.transport->self_id() != setup.drone_id) {
    return Status::InvalidArgument(name + ": transport id " +
                                   std::to_string(setup.transport->self_id()) +
                                   " differs from drone_id " + std::to_string(setup.drone_id));
  }
  std::unique_ptr<LiveDrone> d(new LiveDrone());
  d->impl_ = std::make_unique<Impl>();
  Impl& im = *d->impl_;
  im.setup = setup;
  im.options = options;
  if (setup.sink != nullptr) im.sink = setup.sink;
  Status status;
  if (setup.source != nullptr) {
    if (options.rate != 1.0 || options.start_offset_s != 0.0) {
      return Status::InvalidArgument(name + ": a pushed input runs at the sensors' pace: rate must "
                                     "be 1 and start_offset_s 0");
    }
    im.source = setup.source;
  } else {
    std::unique_ptr<BagPlaybackSource> bag;
    SWARMLIO_RETURN_IF_ERROR(
        BagPlaybackSource::Open(setup.drone, options.start_offset_s, setup.clock, &bag));
    im.owned_source = std::move(bag);
    im.source = im.owned_source.get();
  }
  SWARMLIO_RETURN_IF_ERROR(driver::DroneDriver::Create(setup.drone, setup.drone_id, &im, &im.loop));
  im.imu_rate = std::make_unique<ImuRateOdometry>(
      static_cast<int64_t>(std::llround(setup.drone.odometry.imu_time_offset_s * 1e9)));
  SWARMLIO_RETURN_IF_ERROR(net::PacketCodec::Create(setup.key, &im.codec));
  std::unique_ptr<net::PacketLogWriter> log;
  if (!setup.packet_log_path.empty()) {
    net::PacketLogHeader header;
    header.self_id = setup.drone_id;
    header.sensor_start_ns = im.source->known_start_ns();
    status = net::PacketLogWriter::Open(setup.packet_log_path, header, &log);
    if (!status.ok()) return status.WithContext(name);
  }
  im.recording = std::make_unique<RecordingTransport>(setup.transport, std::move(log));
  im.channel = std::make_unique<net::MessageChannel>(&im.codec, im.recording.get());
  im.input_queue =
      std::make_unique<BoundedQueue<InputItem>>(static_cast<size_t>(options.input_queue_records));
  im.messages = std::make_unique<BoundedQueue<net::ReceivedMessage>>(
      static_cast<size_t>(options.message_queue_capacity));
  im.outbox = std::make_unique<BoundedQueue<Outgoing>>(static_cast<size_t>(options.outbox_capacity));
  *drone = std::move(d);
  return Status::Ok();
}

LiveDrone::~LiveDrone() = default;

const LiveStats& LiveDrone::stats() const { return impl_->stats; }
const swarm::DroneEstimator& LiveDrone::estimator() const { return impl_->loop->estimator(); }
const SensorTimeMapping& LiveDrone::mapping() const { return impl_->mapping; }

void LiveDrone::Stop() {
  impl_->stop = true;
  impl_->source->Interrupt();
  impl_->input_queue->Close();
  {
    std::lock_guard<std::mutex> lock(impl_->watermark_mutex);
  }
  impl_->watermark_cv.notify_all();
}

Status LiveDrone::Run() {
  Impl& im = *impl_;
  if (im.ran) return Status::FailedPrecondition(im.setup.drone.name + ": Run() called twice");
  im.ran = true;
  SourceStart start;
  bool has_record = false;
  im.input_error = im.source->Start(&start, &has_record).WithContext(im.setup.drone.name);
  im.mapping.rate = im.options.rate;
  im.mapping.sensor_start_ns = start.sensor_ns;
  im.mapping.clock_start_ns = start.clock_ns;
  im.watermark_ns = im.mapping.sensor_start_ns - 1;
  im.stats.sensor_start_ns = im.mapping.sensor_start_ns;
  im.stats.clock_start_ns = im.mapping.clock_start_ns;
  std::thread network([&im] { im.NetworkLoop(); });
  std::thread estimator([&im] { im.EstimatorLoop(); });
  std::thread input([&im] { im.InputLoop(); });
  input.join();
  estimator.join();
  network.join();
  im.stats.clock_elapsed_ns = im.setup.clock->NowNs() - im.mapping.clock_start_ns;
  im.stats.channel = im.channel->stats();
  im.stats.datagrams_logged = im.recording->logged();
  im.stats.estimator_warnings = im.loop->warnings().count;
  im.stats.first_warning = im.loop->warnings().first;
  const Status log_status = im.recording->CloseLog();
  if (!im.input_error.ok()) return im.input_error;
  if (!im.network_error.ok()) return im.network_error.WithContext(im.setup.drone.name);
  return log_status;
}

void LiveDrone::Impl::InputLoop() {
  io::BagRecord record;
  bool has = input_error.ok();
  while (has && !stop) {
    const Status status = source->Next(mapping, &record, &has);
    if (!status.ok()) {
      input_error = status.WithContext(setup.drone.name);
      break;
    }
    if (!has || stop) break;
    const int64_t stamp_ns = record.stamp_ns();
    InputItem item;
    item.stamp_ns = stamp_ns;
    if (record.scan() != nullptr) {
      ++stats.scans_played;
      if (scans_queued.load() >= options.max_queued_scans) {
        item.dropped_scan = true;  // the points are not queued
        ++stats.scans_dropped_queue;
      } else {
        ++scans_queued;
        item.record = std::move(record);
      }
    } else {
      if (record.imu() != nullptr) ++stats.imu_samples;
      item.record = std::move(record);
    }
    ++stats.records_played;
    stats.sensor_end_ns = stamp_ns;
    if (input_queue->size() >= input_queue->capacity()) ++stats.input_stalls;
    if (!input_queue->Push(std::move(item))) break;  // closed by Stop()
  }
  input_queue->Close();
}

void LiveDrone::Impl::WaitForNetwork(int64_t stamp_ns) {
  std::unique_lock<std::mutex> lock(watermark_mutex);
  watermark_cv.wait(lock, [&] { return watermark_ns >= stamp_ns || network_done || stop; });
}

void LiveDrone::Impl::Deliver(int64_t stamp_ns, std::deque<net::ReceivedMessage>* pending) {
  while (std::optional<net::ReceivedMessage> m = messages->TryPop()) {
    pending->push_back(std::move(*m));
  }
  while (!pending->empty() && pending->front().arrival_ns <= stamp_ns) {
    loop->Add(std::move(pending->front()));
    ++stats.messages_delivered;
    pending->pop_front();
  }
}

void LiveDrone::Impl::OnOutputs(const std::vector<swarm::DroneOutput>& outputs) {
  const int64_t now_ns = setup.clock->NowNs();
  for (const swarm::DroneOutput& o : outputs) {
    ++stats.scans_processed;
    if (o.ego.held_by_initialization) ++stats.scans_held_by_initialization;
    imu_rate->ResetToScan(o.ego.state, o.ego.stamp_ns, AccelerationFactor());
    ScanLatency latency;
    latency.scan_end_clock_ns = mapping.ToClockNs(o.ego.stamp_ns);
    latency.output_clock_ns = now_ns;
    latency.at_flush = flushing;
    sink->OnScan(o, latency);
  }
}

void LiveDrone::Impl::OnMessages(std::vector<net::SwarmMessage>* out) {
  for (net::SwarmMessage& m : *out) {
    Outgoing o;
    o.message = std::move(m);
    if (!outbox->TryPush(std::move(o))) ++stats.outgoing_dropped_queue;
  }
}

void LiveDrone::Impl::EstimatorLoop() {
  std::deque<net::ReceivedMessage> pending;  // arrived after the current record
  const int64_t max_backlog_ns = static_cast<int64_t>(std::llround(options.max_scan_backlog_s * 1e9));
  while (std::optional<InputItem> item = input_queue->Pop()) {
    if (stop) break;
    const int64_t s = item->stamp_ns;
    WaitForNetwork(s);
    Deliver(s, &pending);
    if (item->dropped_scan) {
      sink->OnScanDropped(s, ScanDropReason::kQueueFull);
      continue;
    }
    io::BagRecord& r = item->record;
    if (const ImuSample* imu = r.imu()) {
      loop->Add(*imu);
      ImuRatePose pose;
      if (options.imu_rate_odometry && imu_rate->AddImu(*imu, AccelerationFactor(), &pose)) {
        if (stats.imu_poses++ == 0) stats.first_imu_pose_ns = pose.stamp_ns;
        stats.last_imu_pose_ns = pose.stamp_ns;
        sink->OnImuPose(pose);
      }
    } else if (LidarScan* scan = std::get_if<LidarScan>(&r.data)) {
      --scans_queued;
      const int64_t backlog_ns = mapping.ToSensorNs(setup.clock->NowNs()) - s;
      if (backlog_ns > max_backlog_ns) {
        ++stats.scans_dropped_backlog;
        sink->OnScanDropped(s, ScanDropReason::kBacklog);
        loop->SendMessages();
      } else {
        loop->Add(std::move(*scan));
      }
    } else {
      loop->SendMessages();  // a ground-truth pose: not for the component
    }
  }
  flushing = true;
  loop->Finish();
  loop->SendMessages();
  estimator_done = true;
}

void LiveDrone::Impl::Send(const Outgoing& out) {
  // Stamped with the time it really leaves (an EgoState's send delay is the
  // clock synchronisation's t1/t3); a teammate echoes it back, so a re-run of
  // the recording reproduces the exchanges without this drone's clock.
  const int64_t now_ns = mapping.ToSensorNs(setup.clock->NowNs());
  const Status sent = channel->Send(now_ns, net::kBroadcastId, out.message);
  if (sent.ok()) {
    ++stats.messages_sent;
  } else {
    ++stats.send_errors;
    if (network_error.ok()) network_error = sent;
  }
}

void LiveDrone::Impl::NetworkLoop() {
  std::vector<net::ReceivedMessage> inbox;
  const int64_t period_ns =
      std::max<int64_t>(1, std::llround(options.network_poll_period_ms * 1e6));
  while (true) {
    const bool last_round = estimator_done.load() || stop.load();
    while (std::optional<Outgoing> out = outbox->TryPop()) Send(*out);
    inbox.clear();
    const int64_t now_ns = mapping.ToSensorNs(setup.clock->NowNs());
    const Status polled = channel->Poll(now_ns, &inbox);
    if (!polled.ok() && network_error.ok()) network_error = polled;
    for (net::ReceivedMessage& m : inbox) {
      if (!messages->TryPush(std::move(m))) ++stats.messages_dropped_queue;
    }
    {
      std::lock_guard<std::mutex> lock(watermark_mutex);
      watermark_ns = std::max(watermark_ns, now_ns);
    }
    watermark_cv.notify_all();
    if (last_round) break;
    setup.clock->SleepForNs(period_ns);
  }
  {
    std::lock_guard<std::mutex> lock(watermark_mutex);
    network_done = true;
  }
  watermark_cv.notify_all();
}

}  // namespace swarmlio::live
