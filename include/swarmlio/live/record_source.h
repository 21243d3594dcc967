// RecordSource: where a LiveDrone's input thread gets its sensor records
// (live_drone.h). Two implementations:
//   BagPlaybackSource  the drone's bag, each record released at its time on
//                      the playback mapping (swarmlio_live, the live tests);
//   PushSource         records pushed by a driver (the ROS node's subscriber
//                      callbacks), released in stamp order or IMU first
//                      (push_source.h).
// Records reach the estimator in the order Next() returns them; IMU samples
// and scans only (ground-truth records are passed on and ignored).
#pragma once

#include <cstdint>

#include "swarmlio/common/status.h"
#include "swarmlio/io/bag_reader.h"
#include "swarmlio/live/clock.h"

namespace swarmlio::live {

/// Where the sensor time line starts (SensorTimeMapping).
struct SourceStart {
  int64_t sensor_ns = 0;  // stamp of the first record
  int64_t clock_ns = 0;   // Clock::NowNs() that stamp corresponds to
};

class RecordSource {
 public:
  virtual ~RecordSource() = default;

  /// Blocks until the first record is known and returns where the sensor
  /// time line starts. *has_record = false: there is none (an empty log, or
  /// Interrupt()). Called once, before Next(), by LiveDrone::Run().
  virtual Status Start(SourceStart* start, bool* has_record) = 0;

  /// Blocks until the next record is due (playback on `mapping`, built from
  /// Start()) or released (push), and returns it. *has_record = false at the
  /// end of the input or after Interrupt(). Input thread only.
  virtual Status Next(const SensorTimeMapping& mapping, io::BagRecord* record,
                      bool* has_record) = 0;

  /// Wakes a blocked Start()/Next(), which then return *has_record = false;
  /// later calls too. Any thread.
  virtual void Interrupt() = 0;

  /// True when the source plays at LiveOptions::rate (a bag); false when
  /// records come at the sensors' own pace (rate must then be 1).
  virtual bool paced_by_rate() const = 0;

  /// The first record's stamp when known before Start() (a bag), else 0
  /// (recorded in the packet log header).
  virtual int64_t known_start_ns() const { return 0; }
};

}  // namespace swarmlio::live
