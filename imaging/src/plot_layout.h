// The layout of a figure, apart from drawing: axes and ticks, text fitting and the boxes of
// every panel, in mm on the page (y up). Private to lucent_plot; plot.cpp draws what this plans.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "lucent/imaging/plot.h"

namespace lucent::imaging::plot_detail {

using Rgb = std::array<std::uint8_t, 3>;

constexpr double kMmPerPoint = 25.4 / 72;  // the cairo devices draw at 72 units per inch

std::string escaped(const std::string& text);
bool valid(double v, bool log);
double to_axis(double v, bool log);
std::string number_label(double v);

// ---- axes: ranges and labelled ticks, in axis space (log10 of the value on a log axis) ----

struct Axis {
  double lo = 0, hi = 1, step = 0;  // step: linear major tick spacing
  bool log = false;
  std::vector<double> ticks;        // labelled ticks, axis space
  std::vector<std::string> labels;  // PLplot text
  double to(double v, double a0, double a1) const { return a0 + (v - lo) / (hi - lo) * (a1 - a0); }
};

Axis make_axis(double lo, double hi, bool log, int target);

struct Range {
  double lo = INFINITY, hi = -INFINITY;
  void add(double v) {
    if (valid(v, false)) lo = std::min(lo, v), hi = std::max(hi, v);
  }
};

// The padded axis-space range of one panel's x or y, before ticks.
Range data_range(const PlotPanel& p, bool x_axis);
// The colour scale's half-range of a panel of maps: given, else the 99th percentile of |value|.
double colour_limit(const PlotPanel& p);

// ---- text ----

// Text widths in mm at the nominal character height, as measured by the device (plot.cpp);
// estimated from the character count for text that was not measured.
class TextMeter {
 public:
  TextMeter(std::map<std::string, double> widths, double chr_mm)
      : chr_(chr_mm), widths_(std::move(widths)) {}
  double width(const std::string& text, double scale = 1) const {
    const auto it = widths_.find(text);
    return scale * (it != widths_.end() ? it->second : 0.75 * chr_ * double(text.size()));
  }

 private:
  double chr_;
  std::map<std::string, double> widths_;
};

std::vector<std::string> words_of(const std::string& text);

struct FittedText {
  std::vector<std::string> lines;
  double scale = 1;
  double widest = 0;  // mm, at `scale`
};

// Fits text into `width`: at most `max_lines` lines at full size, else smaller (to 0.7) with more
// lines, else shrunk until the widest word fits. Never clipped.
FittedText fit_text(const std::string& text, double width, int max_lines, const TextMeter& m);

// ---- layout (mm, y up) ----

struct Box {
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  double w() const { return x1 - x0; }
  double h() const { return y1 - y0; }
};

struct PanelPlan {
  bool map = false;
  Axis x, y, colour;
  double limit = 1;
  std::vector<const PlotSeries*> legend;
  FittedText title;
  int legend_columns = 1;
  Box plot, legend_box, colour_bar, title_box;
  std::vector<Box> maps;
  double top = 0, bottom = 0;  // heights above and below the plot box, mm
};

struct FigurePlan {
  std::vector<PanelPlan> panels;
  std::vector<FittedText> footer;
  Box footer_box;
  double legend_entry = 0;  // one legend entry's width, mm
  double y_label_x = 0;     // centre of the rotated y labels, mm
};

// Axes, colour limits and legend entries of every panel; x shared when asked.
std::vector<PanelPlan> plan_axes(const PlotFigure& f, double height_mm, double chr);
// Every text whose width the layout needs.
std::vector<std::string> texts_to_measure(const PlotFigure& f, const std::vector<PanelPlan>& plans);
// Boxes of every panel, legend, colour bar, title and the footer on a W x H mm page.
FigurePlan plan_figure(const PlotFigure& f, double W, double H, double c, const TextMeter& m,
                       std::vector<PanelPlan> plans);

}  // namespace lucent::imaging::plot_detail
