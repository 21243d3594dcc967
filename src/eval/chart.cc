#include "src/eval/chart.h"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

namespace swarmlio::eval::internal {

namespace {

constexpr int kMinSizePx = 200;
constexpr int kMaxSizePx = 8000;
constexpr const char* kFont = "DejaVu Sans";
constexpr double kTitleFontPx = 22.0;
constexpr double kLabelFontPx = 18.0;
constexpr double kTickFontPx = 15.0;
constexpr double kLegendFontPx = 16.0;
constexpr double kLeftMarginPx = 110.0;
constexpr double kTopMarginPx = 60.0;
constexpr double kBottomMarginPx = 80.0;
constexpr double kRightMarginPx = 30.0;
constexpr double kLegendSamplePx = 34.0;
constexpr double kLegendRowPx = 26.0;
constexpr int kTargetTicks = 8;
constexpr double kDataPadFraction = 0.04;
constexpr double kHalfPi = 1.57079632679489661923;

struct Range {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  void Add(double v) {
    min = std::min(min, v);
    max = std::max(max, v);
  }
  double span() const { return max - min; }
  bool valid() const { return min <= max; }
  /// Widens by a fraction on each side; a zero span becomes +-0.5 (or 5 %).
  void Pad(double fraction, bool keep_min) {
    double pad = span() * fraction;
    if (!(pad > 0.0)) pad = std::max(0.5, 0.05 * std::max(std::abs(min), std::abs(max)));
    if (!keep_min) min -= pad;
    max += pad;
  }
};

struct CairoDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};

std::string FormatTick(double value, double step) {
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  if (std::abs(value) < step * 1e-9) value = 0.0;  // no "-0.0"
  char text[48];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

std::vector<double> TickValues(const Range& range, double step) {
  std::vector<double> ticks;
  const double first = std::ceil(range.min / step - 1e-9) * step;
  for (int k = 0; k < 1000; ++k) {
    const double t = first + k * step;
    if (t > range.max + step * 1e-9) break;
    ticks.push_back(t);
  }
  return ticks;
}

void SetFont(cairo_t* cr, double size_px, bool bold) {
  cairo_select_font_face(cr, kFont, CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size_px);
}

double TextWidth(cairo_t* cr, const std::string& text) {
  cairo_text_extents_t extents;
  cairo_text_extents(cr, text.c_str(), &extents);
  return extents.x_advance;
}

/// Draws text with its anchor at (x, y): h_align 0 left, 0.5 centre, 1 right;
/// y is the vertical centre of the text.
void DrawText(cairo_t* cr, const std::string& text, double x, double y, double h_align) {
  cairo_text_extents_t extents;
  cairo_text_extents(cr, text.c_str(), &extents);
  cairo_move_to(cr, x - h_align * extents.x_advance, y - (extents.y_bearing + extents.height / 2));
  cairo_show_text(cr, text.c_str());
}

void SetColor(cairo_t* cr, const Rgb& c) { cairo_set_source_rgb(cr, c.r, c.g, c.b); }

void SetLineStyle(cairo_t* cr, const ChartLine& line) {
  SetColor(cr, line.color);
  cairo_set_line_width(cr, line.width_px);
  if (line.dashed) {
    const double dashes[] = {9.0, 6.0};
    cairo_set_dash(cr, dashes, 2, 0.0);
  } else {
    cairo_set_dash(cr, nullptr, 0, 0.0);
  }
}

}  // namespace

Rgb PaletteColor(size_t index) {
  static constexpr unsigned kTab10[10] = {0x1f77b4, 0xff7f0e, 0x2ca02c, 0xd62728, 0x9467bd,
                                          0x8c564b, 0xe377c2, 0x7f7f7f, 0xbcbd22, 0x17becf};
  const unsigned rgb = kTab10[index % 10];
  return {((rgb >> 16) & 0xff) / 255.0, ((rgb >> 8) & 0xff) / 255.0, (rgb & 0xff) / 255.0};
}

double NiceTickStep(double range, int target) {
  if (!(range > 0.0) || !std::isfinite(range) || target < 1) return 1.0;
  const double raw = range / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double fraction = raw / magnitude;
  const double nice = fraction <= 1.0 ? 1.0 : fraction <= 2.0 ? 2.0 : fraction <= 5.0 ? 5.0 : 10.0;
  return nice * magnitude;
}

namespace {

// The ranges of the finite points (y including 0 with y_from_zero);
// InvalidArgument when a line's x and y differ in length or no point is finite.
Status DataRanges(const ChartSpec& spec, Range* x_range, Range* y_range) {
  for (const ChartLine& line : spec.lines) {
    if (line.x.size() != line.y.size()) {
      return Status::InvalidArgument("plot: line '" + line.label + "' has " +
                                     std::to_string(line.x.size()) + " x and " +
                                     std::to_string(line.y.size()) + " y values");
    }
    for (size_t i = 0; i < line.x.size(); ++i) {
      if (std::isfinite(line.x[i]) && std::isfinite(line.y[i])) {
        x_range->Add(line.x[i]);
        y_range->Add(line.y[i]);
      }
    }
  }
  if (!x_range->valid()) return Status::InvalidArgument("plot: no finite point to plot");
  if (spec.y_from_zero) y_range->Add(0.0);
  return Status::Ok();
}

// The plot area in pixels and the data ranges it shows.
struct PlotArea {
  double left = 0.0;
  double right = 0.0;
  double top = 0.0;
  double bottom = 0.0;
  double plot_w = 0.0;
  double plot_h = 0.0;
  Range x_range;
  Range y_range;

  double ToPxX(double x) const { return left + (x - x_range.min) / x_range.span() * plot_w; }
  double ToPxY(double y) const { return bottom - (y - y_range.min) / y_range.span() * plot_h; }
};

// Layout: the legend sits right of the plot area. InvalidArgument when it
// leaves no room for the plot.
Status LayOut(cairo_t* cr, const ChartSpec& spec, PlotArea* area) {
  SetFont(cr, kLegendFontPx, false);
  double legend_width = 0.0;
  for (const ChartLine& line : spec.lines) {
    if (!line.label.empty()) {
      legend_width = std::max(legend_width, kLegendSamplePx + 10.0 + TextWidth(cr, line.label));
    }
  }
  const double left = kLeftMarginPx;
  const double right = spec.width_px - kRightMarginPx - (legend_width > 0 ? legend_width + 20 : 0);
  const double top = kTopMarginPx;
  const double bottom = spec.height_px - kBottomMarginPx;
  if (right - left < 50.0 || bottom - top < 50.0) {
    return Status::InvalidArgument(
        "plot: the legend leaves no room for the plot; use a wider image "
        "or shorter names");
  }
  area->left = left;
  area->right = right;
  area->top = top;
  area->bottom = bottom;
  area->plot_w = right - left;
  area->plot_h = bottom - top;
  return Status::Ok();
}

// The data ranges the area shows: padded, and with equal_axes widened to
// the same units per pixel on both axes.
void FitRanges(const ChartSpec& spec, Range x_range, Range y_range, PlotArea* area) {
  const double plot_w = area->plot_w;
  const double plot_h = area->plot_h;
  x_range.Pad(kDataPadFraction, false);
  y_range.Pad(kDataPadFraction, spec.y_from_zero);
  if (spec.equal_axes) {
    const double units_per_px = std::max(x_range.span() / plot_w, y_range.span() / plot_h);
    const double x_mid = 0.5 * (x_range.min + x_range.max);
    const double y_mid = 0.5 * (y_range.min + y_range.max);
    x_range = {x_mid - 0.5 * units_per_px * plot_w, x_mid + 0.5 * units_per_px * plot_w};
    y_range = {y_mid - 0.5 * units_per_px * plot_h, y_mid + 0.5 * units_per_px * plot_h};
  }
  area->x_range = x_range;
  area->y_range = y_range;
}

struct Ticks {
  double x_step = 0.0;
  double y_step = 0.0;
  std::vector<double> x;
  std::vector<double> y;
};

// About kTargetTicks intervals on x, as many per pixel on y.
Ticks MakeTicks(const PlotArea& area) {
  Ticks ticks;
  ticks.x_step = NiceTickStep(area.x_range.span(), kTargetTicks);
  ticks.y_step = NiceTickStep(
      area.y_range.span(), std::max(2, static_cast<int>(kTargetTicks * area.plot_h / area.plot_w)));
  ticks.x = TickValues(area.x_range, ticks.x_step);
  ticks.y = TickValues(area.y_range, ticks.y_step);
  return ticks;
}

void DrawGridAndFrame(cairo_t* cr, const PlotArea& area, const Ticks& ticks) {
  cairo_set_line_width(cr, 1.0);
  cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
  for (const double t : ticks.x) {
    const double px = std::round(area.ToPxX(t)) + 0.5;
    cairo_move_to(cr, px, area.top);
    cairo_line_to(cr, px, area.bottom);
  }
  for (const double t : ticks.y) {
    const double py = std::round(area.ToPxY(t)) + 0.5;
    cairo_move_to(cr, area.left, py);
    cairo_line_to(cr, area.right, py);
  }
  cairo_stroke(cr);
  cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
  cairo_rectangle(cr, std::round(area.left) + 0.5, std::round(area.top) + 0.5,
                  std::round(area.plot_w), std::round(area.plot_h));
  cairo_stroke(cr);
}

// Tick labels, axis labels, title.
void DrawLabels(cairo_t* cr, const ChartSpec& spec, const PlotArea& area, const Ticks& ticks) {
  const double left = area.left;
  const double top = area.top;
  const double bottom = area.bottom;
  SetFont(cr, kTickFontPx, false);
  for (const double t : ticks.x) {
    DrawText(cr, FormatTick(t, ticks.x_step), area.ToPxX(t), bottom + 16, 0.5);
  }
  for (const double t : ticks.y) {
    DrawText(cr, FormatTick(t, ticks.y_step), left - 8, area.ToPxY(t), 1.0);
  }
  SetFont(cr, kLabelFontPx, false);
  DrawText(cr, spec.x_label, left + area.plot_w / 2, bottom + 50, 0.5);
  cairo_save(cr);
  cairo_translate(cr, 24, top + area.plot_h / 2);
  cairo_rotate(cr, -kHalfPi);
  DrawText(cr, spec.y_label, 0, 0, 0.5);
  cairo_restore(cr);
  SetFont(cr, kTitleFontPx, true);
  DrawText(cr, spec.title, spec.width_px / 2.0, top / 2, 0.5);
}

// Lines, clipped to the plot area.
void DrawLines(cairo_t* cr, const ChartSpec& spec, const PlotArea& area) {
  cairo_save(cr);
  cairo_rectangle(cr, area.left, area.top, area.plot_w, area.plot_h);
  cairo_clip(cr);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  for (const ChartLine& line : spec.lines) {
    SetLineStyle(cr, line);
    bool pen_down = false;
    for (size_t i = 0; i < line.x.size(); ++i) {
      if (!std::isfinite(line.x[i]) || !std::isfinite(line.y[i])) {
        pen_down = false;
        continue;
      }
      const double px = area.ToPxX(line.x[i]);
      const double py = area.ToPxY(line.y[i]);
      if (pen_down) {
        cairo_line_to(cr, px, py);
      } else {
        cairo_move_to(cr, px, py);
        cairo_line_to(cr, px, py);  // a lone point still shows (round cap)
        pen_down = true;
      }
    }
    cairo_stroke(cr);
  }
  cairo_restore(cr);
}

// The legend, right of the plot area: a line sample and the label per
// labelled line.
void DrawLegend(cairo_t* cr, const ChartSpec& spec, const PlotArea& area) {
  SetFont(cr, kLegendFontPx, false);
  double legend_y = area.top + 14;
  for (const ChartLine& line : spec.lines) {
    if (line.label.empty()) continue;
    const double x0 = area.right + 20;
    SetLineStyle(cr, line);
    cairo_move_to(cr, x0, legend_y);
    cairo_line_to(cr, x0 + kLegendSamplePx, legend_y);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
    DrawText(cr, line.label, x0 + kLegendSamplePx + 10, legend_y, 0.0);
    legend_y += kLegendRowPx;
  }
}

}  // namespace

Status RenderChartPng(const ChartSpec& spec, const std::string& path) {
  if (spec.width_px < kMinSizePx || spec.width_px > kMaxSizePx || spec.height_px < kMinSizePx ||
      spec.height_px > kMaxSizePx) {
    return Status::InvalidArgument("plot: size " + std::to_string(spec.width_px) + " x " +
                                   std::to_string(spec.height_px) + " px is outside [200, 8000]");
  }
  Range x_range;
  Range y_range;
  SWARMLIO_RETURN_IF_ERROR(DataRanges(spec, &x_range, &y_range));

  const std::unique_ptr<cairo_surface_t, CairoDeleter> surface(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, spec.width_px, spec.height_px));
  if (cairo_surface_status(surface.get()) != CAIRO_STATUS_SUCCESS) {
    return Status::Internal(std::string("plot: cairo surface: ") +
                            cairo_status_to_string(cairo_surface_status(surface.get())));
  }
  const std::unique_ptr<cairo_t, CairoDeleter> context(cairo_create(surface.get()));
  cairo_t* cr = context.get();

  PlotArea area;
  SWARMLIO_RETURN_IF_ERROR(LayOut(cr, spec, &area));
  FitRanges(spec, x_range, y_range, &area);

  // Background, grid, frame.
  cairo_set_source_rgb(cr, 1.0, 1.0, 1.0);
  cairo_paint(cr);
  const Ticks ticks = MakeTicks(area);
  DrawGridAndFrame(cr, area, ticks);
  DrawLabels(cr, spec, area, ticks);
  DrawLines(cr, spec, area);
  DrawLegend(cr, spec, area);

  if (cairo_status(cr) != CAIRO_STATUS_SUCCESS) {
    return Status::Internal(std::string("plot: cairo: ") +
                            cairo_status_to_string(cairo_status(cr)));
  }
  cairo_surface_flush(surface.get());
  const cairo_status_t written = cairo_surface_write_to_png(surface.get(), path.c_str());
  if (written != CAIRO_STATUS_SUCCESS) {
    return Status::IoError(path + ": cannot write PNG (" + cairo_status_to_string(written) + ")");
  }
  return Status::Ok();
}

}  // namespace swarmlio::eval::internal

#if defined(__SANITIZE_ADDRESS__)
// cairo's text goes through fontconfig, whose one-time initialisation keeps
// about 1 KB that LeakSanitizer reports as leaked (the same 12 allocations
// whether one plot is drawn or a hundred). Suppressed here, where the
// dependency lives, so every executable that draws plots stays clean under
// the ASan stage of tools/swarmlio.sh.
extern "C" __attribute__((visibility("default"), used)) const char* __lsan_default_suppressions() {
  return "leak:libfontconfig.so\n";
}
#endif
