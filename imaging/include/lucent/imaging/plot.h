// Small line/scatter plots written as PNG, for what a person reads at a glance: fit profiles and
// residuals, benchmark trade curves. Rendering goes through OpenCV, which stays inside acquire.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace lucent::imaging {

struct PlotSeries {
  std::vector<double> x, y;
  std::vector<double> y_error;  ///< optional error bars (same length as y), drawn +- 1
  std::array<std::uint8_t, 3> rgb{0, 0, 0};
  bool markers = true;  ///< draw a point per sample
  bool line = false;    ///< join the samples
  std::string label;    ///< legend text (empty: no legend entry)
};

struct PlotPanel {
  std::string title;
  std::string x_label, y_label;
  bool log_x = false, log_y = false;
  std::optional<double> y_min, y_max;    ///< axis range (default: from the data)
  std::vector<double> horizontal_lines;  ///< reference lines (e.g. 0 for residuals)
  std::vector<PlotSeries> series;
  double height_weight = 1.0;  ///< share of the figure's height
};

/// Panels stacked top to bottom, sharing the width; `footer` lines printed under them. Atomic.
void write_plot_png(const std::filesystem::path& path, const std::vector<PlotPanel>& panels,
                    const std::vector<std::string>& footer = {}, int width = 1000,
                    int height = 800);

}  // namespace lucent::imaging
