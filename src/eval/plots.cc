#include "swarmlio/eval/plots.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "src/eval/chart.h"

namespace swarmlio::eval {

namespace {

constexpr size_t kMaxDrones = 64;
constexpr double kReferenceShade = 0.6;

internal::ChartSpec BaseSpec(const PlotOptions& options, const std::string& default_title) {
  internal::ChartSpec spec;
  spec.width_px = options.width_px;
  spec.height_px = options.height_px;
  spec.title = options.title.empty() ? default_title : options.title;
  return spec;
}

internal::ChartLine XyLine(const Eigen::Matrix3Xd& positions) {
  internal::ChartLine line;
  line.x.reserve(static_cast<size_t>(positions.cols()));
  line.y.reserve(static_cast<size_t>(positions.cols()));
  for (Eigen::Index i = 0; i < positions.cols(); ++i) {
    line.x.push_back(positions(0, i));
    line.y.push_back(positions(1, i));
  }
  return line;
}

Status TooMany(size_t count) {
  return Status::InvalidArgument("plot: " + std::to_string(count) + " drones; at most " +
                                 std::to_string(kMaxDrones) + " fit in one figure");
}

}  // namespace

Status PlotTopView(const std::vector<TopViewSeries>& drones,
                   const PlotOptions& options,
                   const std::string& png_path) {
  if (drones.size() > kMaxDrones) return TooMany(drones.size());
  internal::ChartSpec spec =
      BaseSpec(options, "Top view: estimate (solid) vs ground truth (dashed)");
  spec.x_label = "x [m]";
  spec.y_label = "y [m]";
  spec.equal_axes = true;
  for (size_t k = 0; k < drones.size(); ++k) {
    const internal::Rgb color = internal::PaletteColor(k);
    internal::ChartLine reference = XyLine(drones[k].reference_positions);
    reference.label = drones[k].name + " ground truth";
    // The same hue, darker: tells the pair apart without a second colour.
    reference.color = {kReferenceShade * color.r, kReferenceShade * color.g,
                       kReferenceShade * color.b};
    reference.dashed = true;
    reference.width_px = 1.6;
    internal::ChartLine estimate = XyLine(drones[k].estimate_positions);
    estimate.label = drones[k].name + " estimate";
    estimate.color = color;
    spec.lines.push_back(std::move(estimate));
    spec.lines.push_back(std::move(reference));
  }
  return internal::RenderChartPng(spec, png_path);
}

Status PlotErrorOverTime(const std::vector<ErrorSeries>& drones,
                         const std::string& error_label,
                         const PlotOptions& options,
                         const std::string& png_path) {
  if (drones.size() > kMaxDrones) return TooMany(drones.size());
  double t0_s = std::numeric_limits<double>::infinity();
  for (const ErrorSeries& d : drones) {
    for (const double t : d.time_s) {
      if (std::isfinite(t)) t0_s = std::min(t0_s, t);
    }
  }
  internal::ChartSpec spec = BaseSpec(options, error_label + " over time");
  spec.x_label = "time since the first pose [s]";
  spec.y_label = error_label;
  spec.y_from_zero = true;
  for (size_t k = 0; k < drones.size(); ++k) {
    internal::ChartLine line;
    line.label = drones[k].name;
    line.color = internal::PaletteColor(k);
    line.width_px = 1.6;
    line.x = drones[k].time_s;
    for (double& t : line.x) t -= t0_s;
    line.y = drones[k].error;
    spec.lines.push_back(std::move(line));
  }
  return internal::RenderChartPng(spec, png_path);
}

Status PlotIntervals(const std::vector<IntervalSeries>& series,
                     const std::string& x_label,
                     const std::string& value_label,
                     const PlotOptions& options,
                     const std::string& png_path) {
  if (series.size() > kMaxDrones) return TooMany(series.size());
  internal::ChartSpec spec = BaseSpec(options, value_label + ": mean and interval");
  spec.x_label = x_label;
  spec.y_label = value_label;
  spec.y_from_zero = true;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double step = 0.6 / static_cast<double>(std::max<size_t>(series.size(), 1));
  for (size_t k = 0; k < series.size(); ++k) {
    const IntervalSeries& s = series[k];
    if (s.lo.size() != s.mean.size() || s.hi.size() != s.mean.size()) {
      return Status::InvalidArgument("plot: series " + s.name + ": mean, lo, hi differ in length");
    }
    const double offset = (static_cast<double>(k) - 0.5 * (series.size() - 1.0)) * step;
    internal::ChartLine means, bars;
    means.label = s.name;
    means.color = bars.color = internal::PaletteColor(k);
    bars.width_px = 3.0;
    for (size_t i = 0; i < s.mean.size(); ++i) {
      const double x = static_cast<double>(i) + offset;
      means.x.push_back(x);
      means.y.push_back(s.mean[i]);
      if (!std::isfinite(s.mean[i])) continue;
      bars.x.insert(bars.x.end(), {x, x, nan});
      bars.y.insert(bars.y.end(), {s.lo[i], s.hi[i], nan});
    }
    spec.lines.push_back(std::move(means));
    if (!bars.x.empty()) spec.lines.push_back(std::move(bars));
  }
  return internal::RenderChartPng(spec, png_path);
}

TopViewSeries TopViewSeriesFromApe(const std::string& name, const ApeResult& ape) {
  TopViewSeries series;
  series.name = name;
  series.estimate_positions = ape.aligned_estimate.Positions();
  series.reference_positions = ape.associated.reference.Positions();
  return series;
}

ErrorSeries ErrorSeriesFromApe(const std::string& name, const ApeResult& ape) {
  ErrorSeries series;
  series.name = name;
  series.error = ape.errors;
  const Trajectory& reference = ape.associated.reference;
  for (size_t i = 0; i < ape.errors.size(); ++i) {
    series.time_s.push_back(reference.has_stamps() ? reference.stamps_s[i]
                                                   : static_cast<double>(i));
  }
  return series;
}

}  // namespace swarmlio::eval
