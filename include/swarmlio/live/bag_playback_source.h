// BagPlaybackSource: a drone's bag played in real time x rate (the input of
// swarmlio_live and the live tests; record_source.h). Each record is
// released when the clock reaches its stamp on the playback mapping; the
// sensor time line is the bag's header stamps.
#pragma once

#include <atomic>
#include <memory>

#include "swarmlio/io/bag_reader.h"
#include "swarmlio/live/record_source.h"
#include "swarmlio/driver/manifest.h"

namespace swarmlio::live {

class BagPlaybackSource : public RecordSource {
 public:
  /// Opens the drone's bag and reads its first record; start_offset_s > 0
  /// skips the log's first seconds (a late join, a restart mid-flight).
  /// Errors name the drone and the file.
  static Status Open(const driver::DroneInput& drone, double start_offset_s, const Clock* clock,
                     std::unique_ptr<BagPlaybackSource>* source);

  Status Start(SourceStart* start, bool* has_record) override;
  Status Next(const SensorTimeMapping& mapping, io::BagRecord* record, bool* has_record) override;
  void Interrupt() override { interrupted_ = true; }
  bool paced_by_rate() const override { return true; }
  int64_t known_start_ns() const override { return has_next_ ? next_.stamp_ns() : 0; }

 private:
  BagPlaybackSource() = default;

  const Clock* clock_ = nullptr;
  std::string name_;
  std::unique_ptr<io::BagReader> reader_;
  io::BagRecord next_;  // read ahead: the record Next() releases
  bool has_next_ = false;
  Status read_error_;
  std::atomic<bool> interrupted_{false};
};

}  // namespace swarmlio::live
