// Figures a person reads or publishes: fit profiles with error bars and an aligned residual panel,
// 2D residual maps, benchmark trade curves. Drawn with PLplot's cairo devices (Debian's
// plplot-driver-cairo); the format follows the file's extension: .svg, .pdf or .png.
//
// Every axis, tick label and legend is placed by this file's own layout (text measured with the
// device's fonts), so that titles are never clipped (they wrap, then shrink), legends sit outside
// the data (right of the plot box or below it), and stacked panels share one x viewport.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace lucent::imaging {

enum class PlotFormat { kSvg, kPdf, kPng };

/// The format `path` asks for by its extension (case-insensitive .svg, .pdf or .png). Throws
/// lucent::Error naming the path and the accepted extensions otherwise.
PlotFormat plot_format(const std::filesystem::path& path);

enum class Marker { kCircle, kSquare, kTriangle, kDiamond };

struct PlotSeries {
  std::vector<double> x, y;
  std::vector<double> y_error;  ///< optional +-1 error bars: empty, or one per y (NaN: none)
  std::array<std::uint8_t, 3> rgb{0, 0, 0};
  bool markers = true;  ///< a marker per sample (data)
  bool line = false;    ///< join the samples (a model curve); broken where a sample is skipped
  Marker marker = Marker::kCircle;
  bool dashed = false;  ///< the line's style
  std::string label;    ///< legend text (empty: no entry); the entry shows the marker and/or line
};

struct ReferenceLine {
  double at = 0;
  bool vertical = false;  ///< x = at; otherwise y = at
  bool dashed = false;
};

/// A heat map of a grid of values (e.g. residuals in standard errors over the image plane).
struct PlotMap {
  std::string title;
  int nx = 0, ny = 0;
  /// nx * ny values, values[iy * nx + ix], iy = 0 at y_min; non-finite: no data (drawn grey).
  std::vector<double> values;
  double x_min = 0, x_max = 1, y_min = 0, y_max = 1;  ///< the grid's outer edges (axis units)
};

struct PlotPanel {
  std::string title;
  std::string x_label, y_label;
  bool log_x = false, log_y = false;  ///< non-positive values on a log axis are skipped
  std::optional<double> x_min, x_max, y_min, y_max;  ///< axis range (default: the data's)
  std::vector<ReferenceLine> reference_lines;        ///< always inside the default range
  std::vector<PlotSeries> series;
  /// A row of heat maps instead of series (x and y to the same scale, one diverging colour scale
  /// with symmetric limits, one colour bar). When not empty, `series` and the log flags are unused.
  std::vector<PlotMap> maps;
  std::string colour_label;            ///< the colour bar's label
  std::optional<double> colour_limit;  ///< limits -L..L (default: 99th percentile of |value|)
  double height_weight = 1.0;          ///< share of the figure's plot height
};

enum class LegendPlace { kRight, kBelow };

struct PlotFigure {
  /// Stacked top to bottom. Every non-map panel has the same left and right plot-box edges.
  std::vector<PlotPanel> panels;
  /// Non-map panels also share one x range (the union of theirs; they should agree on log_x).
  bool share_x = false;
  /// Legends go right of the plot box, or below it (also when the right would leave the data
  /// less than 45% of the width).
  LegendPlace legend = LegendPlace::kRight;
  std::vector<std::string> footer;  ///< text lines under the panels (wrapped to the width)
  int width = 1100, height = 900;   ///< PNG: pixels; SVG and PDF: points (1/72 inch)
};

/// A rectangle in normalised page coordinates (0..1, y up).
struct PlotBox {
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  bool empty() const { return !(x1 > x0 && y1 > y0); }
  /// Whether the two share an area (touching edges do not count).
  bool overlaps(const PlotBox& o) const {
    return !empty() && !o.empty() && x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1;
  }
  bool inside(const PlotBox& o) const {
    return x0 >= o.x0 && x1 <= o.x1 && y0 >= o.y0 && y1 <= o.y1;
  }
};

/// Where write_plot put each panel's parts.
struct PanelLayout {
  PlotBox plot;               ///< the data area (a row of maps: the box around all of them)
  std::vector<PlotBox> maps;  ///< each map's area
  PlotBox legend;             ///< empty without legend entries
  PlotBox colour_bar;         ///< maps only
  PlotBox title;              ///< empty without a title
  int title_lines = 0;
  double title_scale = 1;       ///< character height relative to the nominal (< 1: shrunk)
  double x_min = 0, x_max = 0;  ///< the x range drawn (log10 of it on a log axis)
  int points_drawn = 0;         ///< markers drawn (finite, and positive on log axes)
};

struct PlotLayout {
  std::vector<PanelLayout> panels;
  PlotBox footer;  ///< empty without footer lines
};

/// Draws `figure` into `path` (format by extension) atomically: a temporary beside it, renamed
/// when complete, so that a failure leaves no partial file and an existing target untouched.
/// Throws lucent::Error with one line naming the file (unknown extension, missing cairo driver,
/// inconsistent series or map sizes, a figure too small for its panels). Thread-safe (PLplot's
/// global state is held behind one lock).
PlotLayout write_plot(const std::filesystem::path& path, const PlotFigure& figure);

/// The same, for panels with the default layout.
PlotLayout write_plot(const std::filesystem::path& path, const std::vector<PlotPanel>& panels,
                      const std::vector<std::string>& footer = {}, int width = 1100,
                      int height = 900);

}  // namespace lucent::imaging
