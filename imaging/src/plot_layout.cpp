#include "plot_layout.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "lucent/core/error.h"

namespace lucent::imaging::plot_detail {

// PLplot's escape character is '#': user text is drawn literally.
std::string escaped(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '#' ? std::string("##") : std::string(1, c);
  return out;
}

// Beyond 1e300 a range's span would overflow: such values are skipped like non-finite ones.
bool valid(double v, bool log) {
  return std::abs(v) < 1e300 && (!log || v > 0);
}
double to_axis(double v, bool log) {
  return log ? std::log10(v) : v;
}

std::string number_label(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}

namespace {

double nice_step(double span, int target) {
  const double raw = span / std::max(target, 1);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0})
    if (raw <= m * magnitude * (1 + 1e-9)) return m * magnitude;
  return 10 * magnitude;
}

}  // namespace

// Linear: multiples of a 1-2-2.5-5 step. Log: decades, the range widened to whole decades when
// fewer than two would be labelled, every k-th labelled when there are many.
Axis make_axis(double lo, double hi, bool log, int target) {
  Axis a;
  a.log = log;
  if (log && std::floor(hi + 1e-9) - std::ceil(lo - 1e-9) < 1) {
    lo = std::floor(lo + 1e-9), hi = std::max(std::ceil(hi - 1e-9), lo + 1);
  }
  a.lo = lo, a.hi = hi;
  if (log) {
    const int first = int(std::ceil(lo - 1e-9)), last = int(std::floor(hi + 1e-9));
    const int every = std::max(1, int(std::ceil((last - first + 1) / double(target))));
    // Two decades or fewer: 2 and 5 times each decade labelled too.
    const std::vector<double> mantissas =
        last - first < 2 ? std::vector<double>{1, 2, 5} : std::vector<double>{1};
    for (int e = first - 1; e <= last; ++e) {
      for (double m : mantissas) {
        const double t = e + std::log10(m);
        if (e % every != 0 || t < lo - 1e-9 || t > hi + 1e-9) continue;
        a.ticks.push_back(t);
        const std::string power = "10#u" + std::to_string(e) + "#d";
        a.labels.push_back(std::abs(e) <= 2 ? number_label(m * std::pow(10.0, e))
                           : m == 1         ? power
                                            : number_label(m) + "×" + power);
      }
    }
    return a;
  }
  a.step = nice_step(hi - lo, target);
  if (!(a.step > 0) || !std::isfinite(a.step)) return a;  // a span of +-1e308: no ticks
  for (double k = std::ceil(lo / a.step - 1e-9);
       k * a.step <= hi + 1e-9 * (hi - lo) && a.ticks.size() < 100; ++k) {
    const double t = std::abs(k) < 0.5 ? 0.0 : k * a.step;
    a.ticks.push_back(t);
    a.labels.push_back(number_label(t));
  }
  return a;
}


// The padded axis-space range of one panel's x or y, before ticks.
Range data_range(const PlotPanel& p, bool x_axis) {
  const bool log = x_axis ? p.log_x : p.log_y;
  Range r;
  for (const PlotSeries& s : p.series) {
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!valid(s.x[i], p.log_x) || !valid(s.y[i], p.log_y)) continue;
      const double v = x_axis ? s.x[i] : s.y[i];
      r.add(to_axis(v, log));
      const double e = !x_axis && i < s.y_error.size() ? s.y_error[i] : NAN;
      if (std::isfinite(e) && !log) r.add(v - e), r.add(v + e);
    }
  }
  for (const ReferenceLine& l : p.reference_lines)
    if (l.vertical == x_axis && valid(l.at, log)) r.add(to_axis(l.at, log));
  if (!(r.hi >= r.lo)) r = {0, 1};
  const double span = r.hi - r.lo;
  const double pad = span > 0 ? 0.04 * span : std::max(0.5, 0.1 * std::abs(r.lo));
  const std::optional<double>& lo = x_axis ? p.x_min : p.y_min;
  const std::optional<double>& hi = x_axis ? p.x_max : p.y_max;
  r.lo = lo && valid(*lo, log) ? to_axis(*lo, log) : r.lo - pad;
  r.hi = hi && valid(*hi, log) ? to_axis(*hi, log) : r.hi + pad;
  if (!(r.hi > r.lo)) r.hi = r.lo + 1;
  return r;
}

namespace {

double nice_ceiling(double v) {
  const double magnitude = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0})
    if (v <= m * magnitude * (1 + 1e-9)) return m * magnitude;
  return 10 * magnitude;
}

}  // namespace

double colour_limit(const PlotPanel& p) {
  if (p.colour_limit && *p.colour_limit > 0 && std::isfinite(*p.colour_limit))
    return *p.colour_limit;
  std::vector<double> magnitudes;
  for (const PlotMap& m : p.maps)
    for (double v : m.values)
      if (std::isfinite(v)) magnitudes.push_back(std::abs(v));
  if (magnitudes.empty()) return 1;
  const std::size_t k = std::min(magnitudes.size() - 1, std::size_t(0.99 * magnitudes.size()));
  std::nth_element(magnitudes.begin(), magnitudes.begin() + k, magnitudes.end());
  return magnitudes[k] > 0 ? nice_ceiling(magnitudes[k]) : 1;
}

std::vector<std::string> words_of(const std::string& text) {
  std::vector<std::string> words;
  std::istringstream in(text);
  for (std::string w; in >> w;) words.push_back(escaped(w));
  return words;
}


namespace {

// Greedy word wrap at `width` mm.
FittedText wrap(const std::string& text, double width, double scale, const TextMeter& m) {
  FittedText f;
  f.scale = scale;
  const double space = m.width("a a", scale) - m.width("aa", scale);
  double current = 0;
  for (const std::string& w : words_of(text)) {
    const double ww = m.width(w, scale);
    if (!f.lines.empty() && current > 0 && current + space + ww <= width) {
      f.lines.back() += " " + w, current += space + ww;
    } else {
      f.lines.push_back(w), current = ww;
    }
    f.widest = std::max(f.widest, current);
  }
  return f;
}

}  // namespace

// Fits text into `width`: at most `max_lines` lines at full size, else smaller (to 0.7) with more
// lines, else shrunk until the widest word fits. Never clipped.
FittedText fit_text(const std::string& text, double width, int max_lines, const TextMeter& m) {
  width *= 0.97;  // word widths are summed: leave room for kerning
  for (double s = 1.0; s > 0.69; s -= 0.1) {
    FittedText f = wrap(text, width, s, m);
    if (int(f.lines.size()) <= max_lines && f.widest <= width) return f;
  }
  FittedText f = wrap(text, width, 0.7, m);
  if (f.widest > width) f = wrap(text, width, 0.7 * width / f.widest, m);
  return f;
}

// Axes, colour limits and legend entries of every panel; x shared when asked.
std::vector<PanelPlan> plan_axes(const PlotFigure& f, double height_mm, double chr) {
  std::vector<PanelPlan> plans(f.panels.size());
  double total_weight = 0;
  for (const PlotPanel& p : f.panels) total_weight += std::max(p.height_weight, 0.0);
  Range shared;
  for (const PlotPanel& p : f.panels) {
    if (p.maps.empty()) {
      const Range r = data_range(p, true);
      shared.add(r.lo), shared.add(r.hi);
    }
  }
  for (std::size_t i = 0; i < plans.size(); ++i) {
    const PlotPanel& p = f.panels[i];
    PanelPlan& plan = plans[i];
    const double share = total_weight > 0 ? std::max(p.height_weight, 0.0) / total_weight : 1;
    const int y_ticks = std::clamp(int(0.75 * height_mm * share / (2.5 * chr)), 3, 7);
    plan.map = !p.maps.empty();
    if (plan.map) {
      plan.limit = colour_limit(p);
      plan.x = make_axis(p.maps[0].x_min, p.maps[0].x_max, false, 5);
      plan.y = make_axis(p.maps[0].y_min, p.maps[0].y_max, false, 5);
      plan.colour = make_axis(-plan.limit, plan.limit, false, 4);
      continue;
    }
    const Range x = f.share_x ? shared : data_range(p, true), y = data_range(p, false);
    plan.x = make_axis(x.lo, x.hi, p.log_x, 7);
    plan.y = make_axis(y.lo, y.hi, p.log_y, y_ticks);
    for (const PlotSeries& s : p.series)
      if (!s.label.empty()) plan.legend.push_back(&s);
  }
  return plans;
}

std::vector<std::string> texts_to_measure(const PlotFigure& f,
                                          const std::vector<PanelPlan>& plans) {
  std::vector<std::string> t{"", "aa", "a a"};
  const auto words = [&](const std::string& s) {
    for (const std::string& w : words_of(s)) t.push_back(w);
  };
  for (std::size_t i = 0; i < plans.size(); ++i) {
    const PlotPanel& p = f.panels[i];
    for (const Axis* a : {&plans[i].x, &plans[i].y, &plans[i].colour})
      t.insert(t.end(), a->labels.begin(), a->labels.end());
    words(p.title);
    for (const PlotMap& m : p.maps) {
      const Axis mx = make_axis(m.x_min, m.x_max, false, 5),
                 my = make_axis(m.y_min, m.y_max, false, 5);
      t.insert(t.end(), mx.labels.begin(), mx.labels.end());
      t.insert(t.end(), my.labels.begin(), my.labels.end());
    }
    for (const std::string* s : {&p.x_label, &p.y_label, &p.colour_label}) t.push_back(escaped(*s));
    for (const PlotSeries* s : plans[i].legend) t.push_back(escaped(s->label));
  }
  for (const std::string& line : f.footer) words(line);
  return t;
}

namespace {

// Page margin and legend row height, from the character height c (mm).
double page_margin(double c) {
  return 1.2 * c;
}
double legend_row(double c) {
  return 1.5 * c;
}

// The widest labels of all panels (mm), and whether any panel has a y or colour label.
struct LabelWidths {
  double y_ticks = 0, legend_text = 0, x_tick_half = 0, colour_ticks = 0;
  bool y_label = false, colour_label = false;
};

// Stage 1 of plan_figure: measures the labels that set the plot boxes' left and right edges.
LabelWidths measure_labels(const PlotFigure& f, const std::vector<PanelPlan>& plans,
                           const TextMeter& m) {
  LabelWidths w;
  for (std::size_t i = 0; i < plans.size(); ++i) {
    const PlotPanel& p = f.panels[i];
    for (const std::string& l : plans[i].y.labels) w.y_ticks = std::max(w.y_ticks, m.width(l));
    w.y_label = w.y_label || !p.y_label.empty();
    for (const PlotSeries* s : plans[i].legend)
      w.legend_text = std::max(w.legend_text, m.width(escaped(s->label)));
    if (!plans[i].x.labels.empty())
      w.x_tick_half = std::max(w.x_tick_half, 0.5 * m.width(plans[i].x.labels.back()));
    for (const std::string& l : plans[i].colour.labels)
      w.colour_ticks = std::max(w.colour_ticks, m.width(l));
    w.colour_label = w.colour_label || (plans[i].map && !p.colour_label.empty());
  }
  return w;
}

// The x edges every panel shares, mm.
struct Columns {
  double left = 0, right = 0, map_right = 0;
  double legend_box = 0;  // the legend's width
  bool legend_right = false;
};

// Stage 2 of plan_figure: the plot boxes' left and right edges, and whether the legend goes to
// the right of the plots or below them.
Columns plan_columns(const PlotFigure& f, const LabelWidths& widths, double legend_entry, double W,
                     double c) {
  const double margin = page_margin(c);
  Columns col;
  col.legend_box = legend_entry + 0.8 * c;
  col.left = margin + (widths.y_label ? 1.7 * c : 0) + widths.y_ticks + 0.6 * c;
  const double right_with_legend = W - (c + col.legend_box + margin);
  col.legend_right = f.legend == LegendPlace::kRight && col.legend_box > 0.8 * c &&
                     right_with_legend - col.left >= 0.45 * W;
  col.right =
      col.legend_right ? right_with_legend : W - std::max(margin, widths.x_tick_half + 0.3 * c);
  col.map_right =
      W - (2.4 * c + 0.5 * c + widths.colour_ticks + (widths.colour_label ? 1.9 * c : 0) + margin);
  if (!(col.right - col.left > 4 * c) || !(col.map_right - col.left > 4 * c))
    throw Error("the figure is too narrow for its labels");
  return col;
}

// Stage 3 of plan_figure: each panel's title and the heights above and below its plot box.
// Returns the page height those and the margins take, mm.
double plan_panel_surrounds(const PlotFigure& f, const Columns& col, double legend_entry, double W,
                            double c, const TextMeter& m, std::vector<PanelPlan>& plans) {
  const double margin = page_margin(c), row = legend_row(c);
  const double left = col.left, right = col.right;
  double fixed = 2 * margin + 0.8 * c * double(std::max<std::size_t>(plans.size(), 1) - 1);
  for (std::size_t i = 0; i < plans.size(); ++i) {
    const PlotPanel& p = f.panels[i];
    PanelPlan& plan = plans[i];
    plan.plot.x0 = left, plan.plot.x1 = plan.map ? col.map_right : right;
    if (!p.title.empty()) {
      plan.title = fit_text(p.title, (W - margin - left) / 1.15, 2, m);
      plan.title.scale *= 1.15, plan.title.widest *= 1.15;
      plan.top = double(plan.title.lines.size()) * 1.4 * plan.title.scale * c + 0.8 * c;
    } else {
      plan.top = 0.6 * c;
    }
    bool map_titles = false;
    for (const PlotMap& mp : p.maps) map_titles = map_titles || !mp.title.empty();
    if (map_titles) plan.top += 1.5 * c;
    plan.bottom = 1.7 * c + (p.x_label.empty() ? 0 : 1.6 * c);
    if (!col.legend_right && !plan.legend.empty()) {
      plan.legend_columns = std::max(1, int((right - left + 1.5 * c) / (legend_entry + 1.5 * c)));
      const int rows = int((plan.legend.size() + plan.legend_columns - 1) / plan.legend_columns);
      plan.bottom += 0.6 * c + rows * row + 0.4 * c;
    }
    fixed += plan.top + plan.bottom;
  }
  return fixed;
}

// Stage 4 of plan_figure: the footer's lines fitted to the page width. Returns its height, mm
// (0 without a footer).
double plan_footer(const PlotFigure& f, double W, double c, const TextMeter& m,
                   std::vector<FittedText>& footer) {
  const double margin = page_margin(c);
  double footer_height = 0;
  for (const std::string& line : f.footer) {
    footer.push_back(fit_text(line, (W - 2 * margin) / 0.9, 100, m));
    footer.back().scale *= 0.9, footer.back().widest *= 0.9;
    footer_height += double(footer.back().lines.size()) * 1.45 * footer.back().scale * c;
  }
  if (footer_height > 0) footer_height += 0.6 * c;
  return footer_height;
}

// Each panel's plot box height, mm, and the height maps gave up to the line panels.
struct PlotHeights {
  std::vector<double> heights;
  double line_weight = 0, spare = 0;
};

// Stage 5 of plan_figure: plot heights by weight; a row of maps keeps no more than its width
// allows, the rest goes to the other panels.
PlotHeights share_plot_heights(const PlotFigure& f, const std::vector<PanelPlan>& plans,
                               const Columns& col, double available, double c) {
  PlotHeights out;
  double total_weight = 0;
  for (const PlotPanel& p : f.panels) {
    total_weight += std::max(p.height_weight, 0.0);
    if (p.maps.empty()) out.line_weight += std::max(p.height_weight, 0.0);
  }
  std::vector<double>& heights = out.heights;
  heights.resize(plans.size());
  for (std::size_t i = 0; i < plans.size(); ++i) {
    const double w = std::max(f.panels[i].height_weight, 0.0);
    heights[i] = total_weight > 0 ? available * w / total_weight : available / plans.size();
    if (!plans[i].map) continue;
    double aspect = 0;
    for (const PlotMap& mp : f.panels[i].maps)
      aspect += std::abs((mp.x_max - mp.x_min) / (mp.y_max - mp.y_min));
    const double gaps = 1.2 * c * double(f.panels[i].maps.size() - 1);
    const double natural = aspect > 0 && std::isfinite(aspect)
                               ? (col.map_right - col.left - gaps) / aspect
                               : heights[i];
    if (natural < heights[i]) {
      if (out.line_weight > 0) out.spare += heights[i] - natural;
      heights[i] = natural;
    }
  }
  return out;
}

// Stage 6 of plan_figure: stacks the panels from the top of the page and places each one's plot,
// title, maps, colour bar and legend boxes.
void place_panels(const PlotFigure& f, const Columns& col, const PlotHeights& sizes,
                  double legend_entry, double H, double c, std::vector<PanelPlan>& plans) {
  const double margin = page_margin(c), row = legend_row(c);
  const double left = col.left;
  double y = H - margin;
  for (std::size_t i = 0; i < plans.size(); ++i) {
    const PlotPanel& p = f.panels[i];
    PanelPlan& plan = plans[i];
    double h = sizes.heights[i];
    if (!plan.map && sizes.line_weight > 0)
      h += sizes.spare * std::max(p.height_weight, 0.0) / sizes.line_weight;
    plan.plot.y1 = y - plan.top, plan.plot.y0 = plan.plot.y1 - h;
    if (!p.title.empty()) {
      plan.title_box = {left, left + plan.title.widest,
                        plan.plot.y1 + plan.top - 0.3 * c -
                            double(plan.title.lines.size()) * 1.4 * plan.title.scale * c,
                        plan.plot.y1 + plan.top - 0.3 * c};
    }
    if (plan.map) {
      double x = left;
      for (const PlotMap& mp : p.maps) {
        const double aspect = std::abs((mp.x_max - mp.x_min) / (mp.y_max - mp.y_min));
        const double w = std::isfinite(aspect) && aspect > 0 ? h * aspect : h;
        plan.maps.push_back({x, x + w, plan.plot.y0, plan.plot.y1});
        x += w + 1.2 * c;
      }
      if (!plan.maps.empty()) plan.plot.x1 = plan.maps.back().x1;
      plan.colour_bar = {plan.plot.x1 + 1.2 * c, plan.plot.x1 + 2.4 * c, plan.plot.y0,
                         plan.plot.y1};
    } else if (!plan.legend.empty()) {
      const int rows = int((plan.legend.size() + plan.legend_columns - 1) / plan.legend_columns);
      if (col.legend_right) {
        plan.legend_box = {plan.plot.x1 + c, plan.plot.x1 + c + col.legend_box, 0, plan.plot.y1};
      } else {
        const double top = plan.plot.y0 - 1.7 * c - (p.x_label.empty() ? 0 : 1.6 * c) - 0.6 * c;
        plan.legend_box = {left, left + plan.legend_columns * (legend_entry + 1.5 * c) - 0.7 * c, 0,
                           top};
      }
      plan.legend_box.y0 = plan.legend_box.y1 - rows * row - 0.4 * c;
    }
    y = plan.plot.y0 - plan.bottom - 0.8 * c;
  }
}

}  // namespace

FigurePlan plan_figure(const PlotFigure& f, double W, double H, double c, const TextMeter& m,
                       std::vector<PanelPlan> plans) {
  FigurePlan fig;
  const double margin = page_margin(c);
  const LabelWidths widths = measure_labels(f, plans, m);
  fig.legend_entry = widths.legend_text > 0 ? 3.4 * c + widths.legend_text : 0;
  fig.y_label_x = margin + 0.5 * c;
  const Columns col = plan_columns(f, widths, fig.legend_entry, W, c);
  const double fixed = plan_panel_surrounds(f, col, fig.legend_entry, W, c, m, plans);
  const double footer_height = plan_footer(f, W, c, m, fig.footer);
  const double available = H - fixed - footer_height;
  if (!(available >= 2.5 * c * double(plans.size()))) {
    throw Error("the figure (" + number_label(W / kMmPerPoint) + " x " +
                number_label(H / kMmPerPoint) + ") is too small for its " +
                std::to_string(plans.size()) + " panels and " + std::to_string(f.footer.size()) +
                " footer lines");
  }
  const PlotHeights heights = share_plot_heights(f, plans, col, available, c);
  place_panels(f, col, heights, fig.legend_entry, H, c, plans);
  if (footer_height > 0) fig.footer_box = {margin, W - margin, margin, margin + footer_height};
  fig.panels = std::move(plans);
  return fig;
}

}  // namespace lucent::imaging::plot_detail
