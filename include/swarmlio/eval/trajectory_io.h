// Reading and writing trajectory files in the formats evo reads.
//
// TUM:   one pose a line, "stamp tx ty tz qx qy qz qw" (seconds, metres,
//        Hamilton quaternion, scalar last), whitespace separated; empty lines
//        and lines starting with '#' are skipped. The quaternion need not be
//        unit (it is normalised, as evo does) but must not be zero.
// KITTI: one pose a line, the 12 entries of the top 3 x 4 block of T_G_b in
//        row-major order; no stamps. The rotation block is kept as written
//        (evo does the same) after a check that it is a rotation.
// EuRoC: (read only) the ground-truth CSV of the EuRoC MAV dataset
//        (state_groundtruth_estimate0/data.csv), as evo's `euroc` format:
//        "#timestamp [ns], p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w,
//        q_RS_x, q_RS_y, q_RS_z, ..." with further columns ignored; lines
//        starting with '#' and empty lines are skipped. Stamp = ns / 1e9 (as
//        evo computes it), quaternion scalar first, normalised.
//
// Every error names the file and line ("path:line: reason").
#pragma once

#include <string>

#include "swarmlio/common/status.h"
#include "swarmlio/eval/trajectory.h"

namespace swarmlio::eval {

enum class TrajectoryFormat { kTum, kKitti, kEuroc };

/// Parses "tum", "kitti" or "euroc" (false for anything else).
bool TrajectoryFormatFromString(const std::string& text, TrajectoryFormat* format);

struct TrajectoryReadOptions {
  /// Stamps must increase strictly. With true, equal consecutive stamps are
  /// kept (evo keeps them; its association then takes the first); decreasing
  /// stamps are an error either way. The public TUM fr2_desk ground truth has
  /// one such duplicate.
  bool allow_duplicate_stamps = false;
};

struct TrajectoryReadStats {
  int pose_lines = 0;        // poses read
  int skipped_lines = 0;     // comments and empty lines
  int duplicate_stamps = 0;  // poses whose stamp equals the previous one
};

/// Reads a TUM file. `stats` may be null.
Status ReadTumTrajectory(const std::string& path,
                         const TrajectoryReadOptions& options,
                         Trajectory* trajectory,
                         TrajectoryReadStats* stats = nullptr);

/// Reads a EuRoC ground-truth CSV file (stamps follow the TUM rules of
/// `options`). `stats` may be null.
Status ReadEurocTrajectory(const std::string& path,
                           const TrajectoryReadOptions& options,
                           Trajectory* trajectory,
                           TrajectoryReadStats* stats = nullptr);

/// Reads a KITTI file. `stats` may be null.
Status ReadKittiTrajectory(const std::string& path,
                           Trajectory* trajectory,
                           TrajectoryReadStats* stats = nullptr);

/// Reads `path` in `format` (TUM and EuRoC use `options`).
Status ReadTrajectory(const std::string& path,
                      TrajectoryFormat format,
                      const TrajectoryReadOptions& options,
                      Trajectory* trajectory,
                      TrajectoryReadStats* stats = nullptr);

/// Writes a TUM file (needs stamps). Values are written with 17 significant
/// digits, so stamps and positions read back bit for bit.
Status WriteTumTrajectory(const std::string& path, const Trajectory& trajectory);

/// Writes a KITTI file (stamps are dropped). 17 significant digits: reading
/// it back gives the same matrices bit for bit.
Status WriteKittiTrajectory(const std::string& path, const Trajectory& trajectory);

}  // namespace swarmlio::eval
