// A minimal 2-D line chart rendered to PNG with cairo: nice-number ticks,
// grid, axis labels, title, solid or dashed polylines clipped to the plot
// area, and a legend to the right of it. Private to swarmlio_eval (no cairo
// type leaves chart.cc).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "swarmlio/common/status.h"

namespace swarmlio::eval::internal {

struct Rgb {
  double r = 0.0;
  double g = 0.0;
  double b = 0.0;
};

/// A categorical palette (matplotlib's tab10), cycled.
Rgb PaletteColor(size_t index);

struct ChartLine {
  std::string label;  // legend text; empty = not in the legend
  std::vector<double> x;
  std::vector<double> y;  // non-finite points break the line
  Rgb color;
  bool dashed = false;
  double width_px = 2.0;
};

struct ChartSpec {
  std::string title;
  std::string x_label;
  std::string y_label;
  int width_px = 1200;
  int height_px = 900;
  bool equal_axes = false;   // same metres per pixel on both axes
  bool y_from_zero = false;  // y axis starts at 0 (for errors)
  std::vector<ChartLine> lines;
};

/// Errors: a size outside [200, 8000], x and y of different lengths, no
/// finite point, a cairo failure (its message), the file cannot be written.
Status RenderChartPng(const ChartSpec& spec, const std::string& path);

/// Tick step for `range` with about `target` intervals: 1, 2 or 5 x 10^k.
double NiceTickStep(double range, int target);

}  // namespace swarmlio::eval::internal
