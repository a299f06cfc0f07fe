#include "lucent/imaging/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lucent/materials/atomic_file.h"
#include "lucent/materials/error.h"

namespace lucent::imaging {
namespace {

cv::Scalar bgr(const std::array<std::uint8_t, 3>& rgb) {
  return cv::Scalar(rgb[2], rgb[1], rgb[0]);
}

std::string tick_label(double v, bool log_axis) {
  char buffer[32];
  if (log_axis)
    std::snprintf(buffer, sizeof buffer, "1e%d", int(std::lround(std::log10(v))));
  else
    std::snprintf(buffer, sizeof buffer, "%.3g", v);
  return buffer;
}

// "Nice" linear ticks covering [lo, hi].
std::vector<double> linear_ticks(double lo, double hi) {
  const double span = hi - lo;
  if (!(span > 0)) return {lo};
  const double raw = span / 6;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = magnitude;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (raw <= m * magnitude) {
      step = m * magnitude;
      break;
    }
  }
  std::vector<double> ticks;
  for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * span; t += step) ticks.push_back(t);
  return ticks;
}

void draw_panel(cv::Mat& img, const PlotPanel& panel, cv::Rect area) {
  const int left = 90, right = 20, top = 30, bottom = 45;
  const cv::Rect plot(area.x + left, area.y + top, area.width - left - right,
                      area.height - top - bottom);
  // Data ranges (in axis space: log10 where the axis is logarithmic).
  const auto tx = [&](double v) { return panel.log_x ? std::log10(v) : v; };
  const auto ty = [&](double v) { return panel.log_y ? std::log10(v) : v; };
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const PlotSeries& s : panel.series) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (panel.log_x && !(s.x[i] > 0)) continue;
      if (panel.log_y && !(s.y[i] > 0)) continue;
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, tx(s.x[i]));
      x1 = std::max(x1, tx(s.x[i]));
      y0 = std::min(y0, ty(s.y[i]));
      y1 = std::max(y1, ty(s.y[i]));
    }
  }
  if (panel.y_min) y0 = ty(*panel.y_min);
  if (panel.y_max) y1 = ty(*panel.y_max);
  if (!std::isfinite(x0)) x0 = 0, x1 = 1;
  if (!std::isfinite(y0)) y0 = 0, y1 = 1;
  if (x1 <= x0) x1 = x0 + 1;
  if (y1 <= y0) y1 = y0 + 1;
  const double pad_y = 0.05 * (y1 - y0);
  y0 -= pad_y;
  y1 += pad_y;
  const auto px = [&](double v) { return plot.x + (tx(v) - x0) / (x1 - x0) * plot.width; };
  const auto py = [&](double v) {
    return plot.y + plot.height - (ty(v) - y0) / (y1 - y0) * plot.height;
  };

  cv::rectangle(img, plot, cv::Scalar(0, 0, 0), 1);
  const cv::Scalar grid(225, 225, 225), black(0, 0, 0);
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  // Ticks and grid.
  std::vector<double> xt, yt;
  if (panel.log_x)
    for (int e = int(std::ceil(x0)); e <= int(std::floor(x1)); ++e) xt.push_back(std::pow(10.0, e));
  else
    xt = linear_ticks(x0, x1);
  if (panel.log_y)
    for (int e = int(std::ceil(y0)); e <= int(std::floor(y1)); ++e) yt.push_back(std::pow(10.0, e));
  else
    yt = linear_ticks(y0, y1);
  for (double t : xt) {
    const int X = int(std::lround(px(t)));
    cv::line(img, {X, plot.y + 1}, {X, plot.y + plot.height - 1}, grid, 1);
    cv::putText(img, tick_label(t, panel.log_x), {X - 18, plot.y + plot.height + 18}, font, 0.45,
                black, 1, cv::LINE_AA);
  }
  for (double t : yt) {
    const int Y = int(std::lround(py(t)));
    cv::line(img, {plot.x + 1, Y}, {plot.x + plot.width - 1, Y}, grid, 1);
    cv::putText(img, tick_label(t, panel.log_y), {area.x + 8, Y + 5}, font, 0.45, black, 1,
                cv::LINE_AA);
  }
  for (double h : panel.horizontal_lines) {
    const int Y = int(std::lround(py(h)));
    cv::line(img, {plot.x, Y}, {plot.x + plot.width, Y}, cv::Scalar(120, 120, 120), 1, cv::LINE_AA);
  }
  cv::putText(img, panel.title, {plot.x, area.y + 20}, font, 0.55, black, 1, cv::LINE_AA);
  cv::putText(img, panel.x_label, {plot.x + plot.width / 2 - 40, plot.y + plot.height + 38}, font,
              0.5, black, 1, cv::LINE_AA);
  cv::putText(img, panel.y_label, {area.x + 8, plot.y - 8}, font, 0.45, black, 1, cv::LINE_AA);

  cv::Mat clip = img(plot);
  const auto local = [&](double x, double y) {
    return cv::Point(int(std::lround(px(x))) - plot.x, int(std::lround(py(y))) - plot.y);
  };
  int legend_row = 0;
  int legend_width = 0;
  for (const PlotSeries& s : panel.series) {
    int baseline = 0;
    if (!s.label.empty()) {
      legend_width =
          std::max(legend_width, cv::getTextSize(s.label, font, 0.45, 1, &baseline).width);
    }
  }
  for (const PlotSeries& s : panel.series) {
    const cv::Scalar colour = bgr(s.rgb);
    bool have_previous = false;
    cv::Point previous;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      const bool ok = std::isfinite(s.x[i]) && std::isfinite(s.y[i]) &&
                      (!panel.log_x || s.x[i] > 0) && (!panel.log_y || s.y[i] > 0);
      if (!ok) {
        have_previous = false;
        continue;
      }
      const cv::Point p = local(s.x[i], s.y[i]);
      if (!s.y_error.empty() && std::isfinite(s.y_error[i])) {
        const double lo =
            panel.log_y ? std::max(s.y[i] - s.y_error[i], s.y[i] * 1e-3) : s.y[i] - s.y_error[i];
        cv::line(clip, local(s.x[i], lo), local(s.x[i], s.y[i] + s.y_error[i]), colour, 1,
                 cv::LINE_AA);
      }
      if (s.markers) cv::circle(clip, p, 2, colour, cv::FILLED, cv::LINE_AA);
      if (s.line && have_previous) cv::line(clip, previous, p, colour, 2, cv::LINE_AA);
      previous = p;
      have_previous = true;
    }
    if (!s.label.empty()) {
      const cv::Point at(std::max(4, plot.width - legend_width - 40), 18 + 18 * legend_row++);
      cv::line(clip, at + cv::Point(0, -4), at + cv::Point(20, -4), colour, 2, cv::LINE_AA);
      cv::putText(clip, s.label, at + cv::Point(26, 0), font, 0.45, colour, 1, cv::LINE_AA);
    }
  }
}

}  // namespace

void write_plot_png(const std::filesystem::path& path, const std::vector<PlotPanel>& panels,
                    const std::vector<std::string>& footer, int width, int height) {
  cv::Mat img(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int footer_height = 8 + 20 * int(footer.size());
  double total_weight = 0;
  for (const PlotPanel& p : panels) total_weight += p.height_weight;
  int y = 0;
  for (const PlotPanel& p : panels) {
    const int h = int((height - footer_height) * p.height_weight / total_weight);
    draw_panel(img, p, cv::Rect(0, y, width, h));
    y += h;
  }
  for (std::size_t i = 0; i < footer.size(); ++i) {
    cv::putText(img, footer[i], {12, y + 18 + 20 * int(i)}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
                cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  AtomicOutputPath out(path);
  bool written = false;
  try {
    written = cv::imwrite(out.temporary().string(), img);
  } catch (const cv::Exception&) {
    written = false;  // e.g. an extension OpenCV has no writer for
  }
  if (!written) throw Error(path.string() + ": cannot write the plot (expected a .png file)");
  out.commit();
}

}  // namespace lucent::imaging
