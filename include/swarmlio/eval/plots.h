// PNG plots of evaluation results (rendered in-process with cairo; see
// docs/evaluation.md for the choice). Every function returns an error Status
// when the data cannot be plotted or the file cannot be written; none prints
// or aborts.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"
#include "swarmlio/eval/ape.h"

namespace swarmlio::eval {

struct PlotOptions {
  int width_px = 1200;  // 200 .. 8000
  int height_px = 900;  // 200 .. 8000
  std::string title;    // empty = a default title
};

/// One drone in a top view: positions (3 x n, metres) in one common frame,
/// e.g. the SE(3)-aligned estimate and the ground truth in W.
struct TopViewSeries {
  std::string name;
  Eigen::Matrix3Xd estimate_positions;
  Eigen::Matrix3Xd reference_positions;
};

/// x-y top view of every drone's estimate (solid) and ground truth (dashed, a
/// darker shade of the same colour) with equal axis scales and a legend.
/// Errors: no finite point, more than 64 drones, bad size, the file cannot be
/// written.
Status PlotTopView(const std::vector<TopViewSeries>& drones,
                   const PlotOptions& options,
                   const std::string& png_path);

/// One drone's error over time: time_s (any origin; the plot starts at the
/// earliest time of all series) and error, the same length.
struct ErrorSeries {
  std::string name;
  std::vector<double> time_s;
  std::vector<double> error;
};

/// Error over time, one line per drone, y axis from 0, labelled error_label
/// (e.g. "APE translation [m]").
Status PlotErrorOverTime(const std::vector<ErrorSeries>& drones,
                         const std::string& error_label,
                         const PlotOptions& options,
                         const std::string& png_path);

/// One series of a figure of means with intervals (e.g. one variant of a
/// sweep): for each category index i (the x axis, 0, 1, ...) a mean and an
/// interval [lo, hi]; a non-finite mean leaves the category out.
struct IntervalSeries {
  std::string name;
  std::vector<double> mean;
  std::vector<double> lo;
  std::vector<double> hi;
};

/// Means joined by a line per series with a vertical bar for each interval,
/// the series side by side within a category; y axis from 0, labelled
/// value_label; x_label names the categories (e.g. "run 0: indoor_3uav/uav1,
/// ..."). Errors: lengths differ, no finite mean, more than 64 series, bad
/// size, the file cannot be written.
Status PlotIntervals(const std::vector<IntervalSeries>& series,
                     const std::string& x_label,
                     const std::string& value_label,
                     const PlotOptions& options,
                     const std::string& png_path);

/// The aligned estimate and the associated reference positions of an APE.
TopViewSeries TopViewSeriesFromApe(const std::string& name, const ApeResult& ape);

/// The APE errors against the associated reference stamps (pose index when
/// the trajectories have no stamps).
ErrorSeries ErrorSeriesFromApe(const std::string& name, const ApeResult& ape);

}  // namespace swarmlio::eval
