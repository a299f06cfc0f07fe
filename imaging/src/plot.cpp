#include "lucent/imaging/plot.h"

#include <plplot.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <numbers>
#include <sstream>

#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/core/xml_text.h"
#include "plot_layout.h"

namespace lucent::imaging {
namespace {

using namespace plot_detail;
namespace fs = std::filesystem;

// ---- PLplot: one lock, fatal errors as exceptions, one stream per figure ----

std::mutex& plplot_mutex() {
  static std::mutex m;
  return m;
}

std::string plplot_abort_message;  // guarded by plplot_mutex

// plexit would end the process; the library has unwind tables, so its handler may throw.
int throw_on_plexit(const char* message) {
  throw Error(std::string("PLplot: ") + (message && *message ? message : "fatal error"));
}
void keep_plabort(const char* message) {
  if (plplot_abort_message.empty()) plplot_abort_message = message ? message : "error";
}

bool have_device(const std::string& name) {
  std::array<const char*, 128> menu{}, names{};
  const char** menu_p = menu.data();
  const char** names_p = names.data();
  int n = int(names.size());
  plgDevs(&menu_p, &names_p, &n);
  for (int i = 0; i < std::min(n, int(names.size())); ++i)
    if (names[i] && name == names[i]) return true;
  return false;
}

class Stream {
 public:
  Stream(const std::string& device, const std::string& file, int width, int height) {
    plmkstrm(&id_);
    if (id_ < 0) throw Error("PLplot: no free stream");
    plsdev(device.c_str());
    plsfnam(file.c_str());
    plspage(0, 0, width, height, 0, 0);
    plscolbg(255, 255, 255);
    plscmap0n(16);
    plinit();
    pladv(0);
  }
  ~Stream() {
    plsstrm(id_);
    plend1();
  }
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;

 private:
  PLINT id_ = -1;
};

// Text widths in mm at the nominal character height, measured with the device's own fonts (a
// one-entry legend on a scratch stream whose page goes to /dev/null); estimated without one.
double legend_width(const std::string& text) {
  PLINT opt = PL_LEGEND_NONE, colour = 1;
  const char* strings[1] = {text.c_str()};
  PLFLT w = 0, h = 0;
  pllegend(&w, &h, 0, PL_POSITION_SUBPAGE | PL_POSITION_INSIDE | PL_POSITION_LEFT | PL_POSITION_TOP,
           0, 0, 0.1, 0, 0, 0, 0, 0, 1, &opt, 0, 1, 1, 0, &colour, strings, nullptr, nullptr,
           nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr);
  return w;
}

TextMeter measure(const std::vector<std::string>& texts, const std::string& device, double chr_mm,
                  int width, int height) {
  std::map<std::string, double> widths;
  if (std::ofstream("/dev/null")) {
    Stream scratch(device, "/dev/null", width, height);
    plschr(chr_mm, 1.0);
    plvpor(0, 1, 0, 1);
    plwind(0, 1, 0, 1);
    const double page_mm = width * kMmPerPoint, empty = legend_width("");
    for (const std::string& t : texts)
      if (!widths.count(t)) widths[t] = std::max(0.0, (legend_width(t) - empty) * page_mm);
  }
  return TextMeter(std::move(widths), chr_mm);
}

class Painter {
 public:
  Painter(double width_mm, double height_mm, double chr) : w_(width_mm), h_(height_mm), chr_(chr) {}
  void page() const {  // world = page mm
    plvpor(0, 1, 0, 1);
    plwind(0, w_, 0, h_);
  }
  void data(const Box& b, double x0, double x1, double y0, double y1) const {
    plvpor(b.x0 / w_, b.x1 / w_, b.y0 / h_, b.y1 / h_);
    plwind(x0, x1, y0, y1);
  }
  void colour(const Rgb& c) const {
    plscol0(15, c[0], c[1], c[2]);
    plcol0(15);
  }
  void text(double x, double y, double just, const std::string& s, double scale = 1,
            bool vertical = false) const {
    plschr(chr_, scale);
    plptex(x, y, vertical ? 0 : 1, vertical ? 1 : 0, just, s.c_str());
    plschr(chr_, 1);
  }
  void fill(const Box& b, const Rgb& c) const {
    PLFLT x[4] = {b.x0, b.x1, b.x1, b.x0}, y[4] = {b.y0, b.y0, b.y1, b.y1};
    colour(c);
    plfill(4, x, y);
  }
  // A filled marker centred at (x, y) mm (page frame).
  void marker(Marker kind, double x, double y) const {
    std::vector<PLFLT> px, py;
    const auto polygon = [&](int n, double r, double phase) {
      for (int k = 0; k < n; ++k) {
        const double a = phase + 2 * std::numbers::pi * k / n;
        px.push_back(x + r * std::cos(a)), py.push_back(y + r * std::sin(a));
      }
    };
    const double r = 0.27 * chr_, pi = std::numbers::pi;
    if (kind == Marker::kSquare)
      polygon(4, r * 1.2, pi / 4);
    else if (kind == Marker::kTriangle)
      polygon(3, r * 1.35, pi / 2);
    else if (kind == Marker::kDiamond)
      polygon(4, r * 1.3, 0);
    else
      polygon(12, r, 0);
    plfill(PLINT(px.size()), px.data(), py.data());
  }
  void line_style(bool dashed, double width) const {
    PLINT mark = 2500, space = 1500;  // micrometres
    if (dashed)
      plstyl(1, &mark, &space);
    else
      pllsty(1);
    plwidth(width);
  }
  double chr() const { return chr_; }

 private:
  double w_, h_, chr_;
};

const Rgb kBlack{0, 0, 0}, kGrid{228, 228, 228}, kReference{110, 110, 110}, kMissing{205, 205, 205};

std::string describe(const PlotSeries& s, std::size_t index) {
  return s.label.empty() ? "series " + std::to_string(index + 1) : "series '" + s.label + "'";
}

// The frame, grid and labelled ticks of a plot box (data frame set by the caller for the grid).
void draw_axes(const Painter& p, const Box& b, const Axis& x, const Axis& y, bool grid,
               bool y_labels) {
  const double c = p.chr();
  p.data(b, x.lo, x.hi, y.lo, y.hi);
  if (grid) {
    p.colour(kGrid);
    p.line_style(false, 0.6);
    for (double t : x.ticks) pljoin(t, y.lo, t, y.hi);
    for (double t : y.ticks) pljoin(x.lo, t, x.hi, t);
  }
  p.colour(kBlack);
  p.line_style(false, 0.8);
  plschr(c, 0.8);
  plbox(x.log ? "bcstl" : "bcst", x.step, 0, y.log ? "bcstl" : "bcst", y.step, 0);
  plschr(c, 1);
  p.page();
  for (std::size_t i = 0; i < x.ticks.size(); ++i)
    p.text(x.to(x.ticks[i], b.x0, b.x1), b.y0 - 1.1 * c, 0.5, x.labels[i]);
  for (std::size_t i = 0; y_labels && i < y.ticks.size(); ++i)
    p.text(b.x0 - 0.5 * c, y.to(y.ticks[i], b.y0, b.y1), 1.0, y.labels[i]);
}

void draw_series(const Painter& p, const PanelPlan& plan, const PlotPanel& panel,
                 const std::string& where, PanelLayout& out) {
  const Axis &x = plan.x, &y = plan.y;
  const Box& b = plan.plot;
  p.data(b, x.lo, x.hi, y.lo, y.hi);
  p.colour(kReference);
  for (const ReferenceLine& l : panel.reference_lines) {
    if (!valid(l.at, l.vertical ? x.log : y.log)) continue;
    p.line_style(l.dashed, 1.0);
    const double at = to_axis(l.at, l.vertical ? x.log : y.log);
    if (l.vertical)
      pljoin(at, y.lo, at, y.hi);
    else
      pljoin(x.lo, at, x.hi, at);
  }
  // Data first, then every line over it: a fit stays visible through dense markers.
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t k = 0; k < panel.series.size(); ++k) {
      const PlotSeries& s = panel.series[k];
      if (s.x.size() != s.y.size() || (!s.y_error.empty() && s.y_error.size() != s.y.size())) {
        throw Error(where + describe(s, k) + " has " + std::to_string(s.x.size()) + " x, " +
                    std::to_string(s.y.size()) + " y and " + std::to_string(s.y_error.size()) +
                    " error values (expected as many y as x, and errors for none or all)");
      }
      const auto ok = [&](std::size_t i) { return valid(s.x[i], x.log) && valid(s.y[i], y.log); };
      p.data(b, x.lo, x.hi, y.lo, y.hi);
      p.colour(s.rgb);
      if (pass == 1 && s.line) {
        p.line_style(s.dashed, 1.8);
        std::vector<PLFLT> px, py;
        for (std::size_t i = 0; i <= s.x.size(); ++i) {
          if (i < s.x.size() && ok(i)) {
            px.push_back(to_axis(s.x[i], x.log)), py.push_back(to_axis(s.y[i], y.log));
            continue;
          }
          if (px.size() > 1) plline(PLINT(px.size()), px.data(), py.data());
          px.clear(), py.clear();
        }
      }
      if (pass == 1 || !s.markers) continue;
      p.line_style(false, 0.8);
      for (std::size_t i = 0; i < s.y_error.size(); ++i) {
        const double e = s.y_error[i];
        if (!ok(i) || !(e > 0) || !std::isfinite(e)) continue;
        const double top = to_axis(s.y[i] + e, y.log), X = to_axis(s.x[i], x.log);
        const double bottom = y.log && s.y[i] - e <= 0 ? y.lo - 1 : to_axis(s.y[i] - e, y.log);
        pljoin(X, bottom, X, top);
      }
      p.page();
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        if (!ok(i)) continue;
        const double X = x.to(to_axis(s.x[i], x.log), b.x0, b.x1);
        const double Y = y.to(to_axis(s.y[i], y.log), b.y0, b.y1);
        if (X < b.x0 || X > b.x1 || Y < b.y0 || Y > b.y1) continue;
        p.marker(s.marker, X, Y);
        ++out.points_drawn;
      }
    }
  }
  p.line_style(false, 0.8);
}

// Diverging, blue (negative) - white - red (positive): ColorBrewer RdBu.
void diverging_colours() {
  PLFLT pos[5] = {0, 0.25, 0.5, 0.75, 1};
  PLFLT r[5] = {0.02, 0.40, 0.97, 0.84, 0.40}, g[5] = {0.19, 0.65, 0.97, 0.38, 0.00};
  PLFLT b[5] = {0.38, 0.82, 0.97, 0.30, 0.12};
  plscmap1n(256);
  plscmap1l(1, 5, pos, r, g, b, nullptr);
}

void draw_image(const std::vector<double>& values, int nx, int ny, const Box& box, double x0,
                double x1, double y0, double y1, double limit, const Painter& p) {
  std::vector<PLFLT> column_major(std::size_t(nx) * ny);
  std::vector<const PLFLT*> columns(nx);
  for (int ix = 0; ix < nx; ++ix) {
    columns[ix] = column_major.data() + std::size_t(ix) * ny;
    for (int iy = 0; iy < ny; ++iy) {
      const double v = values[std::size_t(iy) * nx + ix];
      column_major[std::size_t(ix) * ny + iy] =
          std::isfinite(v) ? std::clamp(v, -limit, limit) : -3 * limit;  // outside: not drawn
    }
  }
  p.data(box, x0, x1, y0, y1);
  plimagefr(columns.data(), nx, ny, x0, x1, y0, y1, -limit, limit, -limit, limit, nullptr, nullptr);
}

void draw_maps(const Painter& p, const PanelPlan& plan, const PlotPanel& panel,
               const std::string& where, const TextMeter& m) {
  const double c = p.chr();
  diverging_colours();
  for (std::size_t k = 0; k < panel.maps.size(); ++k) {
    const PlotMap& map = panel.maps[k];
    if (map.nx < 1 || map.ny < 1 || map.values.size() != std::size_t(map.nx) * map.ny ||
        !(map.x_max > map.x_min) || !(map.y_max > map.y_min)) {
      throw Error(where + "map " + std::to_string(k + 1) + " has " +
                  std::to_string(map.values.size()) + " values for a " + std::to_string(map.nx) +
                  " x " + std::to_string(map.ny) +
                  " grid (expected nx * ny > 0, and x_max > "
                  "x_min, y_max > y_min)");
    }
    const Box& b = plan.maps[k];
    p.page();
    p.fill(b, kMissing);
    draw_image(map.values, map.nx, map.ny, b, map.x_min, map.x_max, map.y_min, map.y_max,
               plan.limit, p);
    Axis x = make_axis(map.x_min, map.x_max, false, 5),
         y = make_axis(map.y_min, map.y_max, false, 5);
    draw_axes(p, b, x, y, false, k == 0);
    if (!map.title.empty()) p.text(b.x0, b.y1 + 0.8 * c, 0, escaped(map.title));
    if (!panel.x_label.empty())
      p.text(0.5 * (b.x0 + b.x1), b.y0 - 2.6 * c, 0.5, escaped(panel.x_label));
  }
  // The colour bar: the same colour scale as an image of one column.
  const Box& bar = plan.colour_bar;
  std::vector<double> ramp(256);
  for (int i = 0; i < 256; ++i) ramp[i] = plan.limit * (2 * (i + 0.5) / 256 - 1);
  draw_image(ramp, 1, 256, bar, 0, 1, -plan.limit, plan.limit, plan.limit, p);
  p.colour(kBlack);
  plbox("bc", 0, 0, "bcst", plan.colour.step, 0);
  p.page();
  double widest = 0;
  for (std::size_t i = 0; i < plan.colour.ticks.size(); ++i) {
    p.text(bar.x1 + 0.5 * c, plan.colour.to(plan.colour.ticks[i], bar.y0, bar.y1), 0,
           plan.colour.labels[i]);
    widest = std::max(widest, m.width(plan.colour.labels[i]));
  }
  if (!panel.colour_label.empty()) {
    const std::string label = escaped(panel.colour_label);
    const double scale = std::min(1.0, bar.h() / std::max(m.width(label), 1e-9));
    p.text(bar.x1 + widest + 1.4 * c, 0.5 * (bar.y0 + bar.y1), 0.5, label, scale, true);
  }
}

void draw_legend(const Painter& p, const PanelPlan& plan, double entry) {
  const double c = p.chr();
  const Box& b = plan.legend_box;
  p.page();
  p.colour({190, 190, 190});
  p.line_style(false, 0.6);
  PLFLT bx[5] = {b.x0, b.x1, b.x1, b.x0, b.x0}, by[5] = {b.y0, b.y0, b.y1, b.y1, b.y0};
  plline(5, bx, by);
  for (std::size_t i = 0; i < plan.legend.size(); ++i) {
    const PlotSeries& s = *plan.legend[i];
    const double x = b.x0 + 0.4 * c + double(i % plan.legend_columns) * (entry + 1.5 * c);
    const double y = b.y1 - 0.2 * c - (double(i / plan.legend_columns) + 0.5) * 1.5 * c;
    p.colour(s.rgb);
    if (s.line) {
      p.line_style(s.dashed, 2.0);
      pljoin(x, y, x + 2.8 * c, y);
      p.line_style(false, 0.8);
    }
    if (s.markers) {
      if (!s.y_error.empty()) pljoin(x + 1.4 * c, y - 0.5 * c, x + 1.4 * c, y + 0.5 * c);
      p.marker(s.marker, x + 1.4 * c, y);
    }
    p.colour(kBlack);
    p.text(x + 3.4 * c, y, 0, escaped(s.label));
  }
}

PlotBox normalised(const Box& b, double W, double H) {
  return {b.x0 / W, b.x1 / W, b.y0 / H, b.y1 / H};
}

PlotLayout render(const PlotFigure& f, const std::string& device, const std::string& file) {
  const double W = f.width * kMmPerPoint, H = f.height * kMmPerPoint;
  const double c = std::clamp(std::min(W / 90, H / 55), 2.0, 6.0);  // nominal character height
  std::vector<PanelPlan> plans = plan_axes(f, H, c);
  const TextMeter meter = measure(texts_to_measure(f, plans), device, c, f.width, f.height);
  const FigurePlan fig = plan_figure(f, W, H, c, meter, std::move(plans));
  Stream stream(device, file, f.width, f.height);
  const Painter p(W, H, c);
  PlotLayout layout;
  for (std::size_t i = 0; i < fig.panels.size(); ++i) {
    const PlotPanel& panel = f.panels[i];
    const PanelPlan& plan = fig.panels[i];
    const std::string what = "panel " + std::to_string(i + 1) + ": ";
    PanelLayout& out = layout.panels.emplace_back();
    p.page();
    p.colour(kBlack);
    for (std::size_t k = 0; k < plan.title.lines.size(); ++k) {
      const double line = 1.4 * plan.title.scale * c;
      p.text(plan.plot.x0, plan.title_box.y1 - (double(k) + 0.5) * line, 0, plan.title.lines[k],
             plan.title.scale);
    }
    if (plan.map) {
      draw_maps(p, plan, panel, what, meter);
    } else {
      draw_series(p, plan, panel, what, out);
      draw_axes(p, plan.plot, plan.x, plan.y, true, true);
      if (!panel.x_label.empty())
        p.text(0.5 * (plan.plot.x0 + plan.plot.x1), plan.plot.y0 - 2.6 * c, 0.5,
               escaped(panel.x_label));
      if (!plan.legend.empty()) draw_legend(p, plan, fig.legend_entry);
    }
    p.page();
    p.colour(kBlack);
    const Box& first = plan.map && !plan.maps.empty() ? plan.maps[0] : plan.plot;
    if (!panel.y_label.empty()) {
      const std::string label = escaped(panel.y_label);
      const double scale = std::min(1.0, first.h() / std::max(meter.width(label), 1e-9));
      p.text(fig.y_label_x, 0.5 * (first.y0 + first.y1), 0.5, label, scale, true);
    }
    out.plot = normalised(plan.plot, W, H);
    for (const Box& b : plan.maps) out.maps.push_back(normalised(b, W, H));
    out.legend = normalised(plan.legend_box, W, H);
    out.colour_bar = normalised(plan.colour_bar, W, H);
    out.title = normalised(plan.title_box, W, H);
    out.title_lines = int(plan.title.lines.size());
    out.title_scale = plan.title.scale / 1.15;
    out.x_min = plan.x.lo, out.x_max = plan.x.hi;
  }
  double y = fig.footer_box.y1 - 0.3 * c;
  for (const FittedText& t : fig.footer) {
    for (const std::string& line : t.lines) {
      const double step = 1.45 * t.scale * c;
      p.text(fig.footer_box.x0, y - 0.5 * step, 0, line, t.scale);
      y -= step;
    }
  }
  layout.footer = normalised(fig.footer_box, W, H);
  return layout;
}

// cairo's SVG draws text as glyph outlines: a <title> and <desc> keep the words searchable.
void add_svg_text(const fs::path& file, const PlotFigure& f) {
  std::ifstream in(file, std::ios::binary);
  std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  const std::size_t open = svg.find("<svg"), end = svg.find('>', open);
  if (open == std::string::npos || end == std::string::npos) return;
  std::string title, desc;
  for (const PlotPanel& p : f.panels) {
    if (title.empty()) title = p.title;
    desc += p.title + "\n";
    for (const PlotSeries& s : p.series)
      if (!s.label.empty()) desc += "legend: " + s.label + "\n";
    for (const PlotMap& m : p.maps)
      if (!m.title.empty()) desc += "map: " + m.title + "\n";
  }
  for (const std::string& line : f.footer) desc += line + "\n";
  svg.insert(end + 1,
             "\n<title>" + xml_escape(title) + "</title>\n<desc>" + xml_escape(desc) + "</desc>");
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << svg;
  out.flush();
  if (!out) throw Error("the SVG's title and description could not be written (disk full?)");
}

}  // namespace

PlotFormat plot_format(const fs::path& path) {
  std::string ext = path.extension().string();
  for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  if (ext == ".svg") return PlotFormat::kSvg;
  if (ext == ".pdf") return PlotFormat::kPdf;
  if (ext == ".png") return PlotFormat::kPng;
  throw Error(path.string() +
              ": cannot write a plot in this format (expected a file ending in "
              ".svg, .pdf or .png)");
}

PlotLayout write_plot(const fs::path& path, const PlotFigure& figure) {
  const PlotFormat format = plot_format(path);
  const std::string where = path.string() + ": cannot write the plot: ";
  if (figure.width < 100 || figure.height < 100 || figure.width > 20000 || figure.height > 20000) {
    throw Error(where + "size " + std::to_string(figure.width) + " x " +
                std::to_string(figure.height) + " (expected 100 to 20000 on each side)");
  }
  const std::string device = format == PlotFormat::kSvg   ? "svgcairo"
                             : format == PlotFormat::kPdf ? "pdfcairo"
                                                          : "pngcairo";
  std::lock_guard lock(plplot_mutex());
  static std::once_flag handlers;
  std::call_once(handlers, [] {
    plsexit(throw_on_plexit);
    plsabort(keep_plabort);
  });
  const std::string install = " (install Debian's plplot-driver-cairo)";
  bool found = false;
  try {
    found = have_device(device);
  } catch (const Error& e) {  // no driver at all
    throw Error(where + e.what() + install);
  }
  if (!found) throw Error(where + "PLplot has no " + device + " device" + install);
  AtomicOutputPath out(path);
  if (!std::ofstream(out.temporary()))
    throw Error(where + "cannot create " + out.temporary().string());
  plplot_abort_message.clear();
  PlotLayout layout;
  try {
    layout = render(figure, device, out.temporary().string());
  } catch (const Error& e) {
    throw Error(where + e.what());
  }
  if (!plplot_abort_message.empty()) throw Error(where + "PLplot: " + plplot_abort_message);
  if (format == PlotFormat::kSvg) {
    try {
      add_svg_text(out.temporary(), figure);
    } catch (const Error& e) {
      throw Error(where + e.what());
    }
  }
  std::error_code ec;
  if (!(fs::file_size(out.temporary(), ec) > 0) || ec)
    throw Error(where + "the device wrote nothing");
  out.commit();
  return layout;
}

PlotLayout write_plot(const fs::path& path, const std::vector<PlotPanel>& panels,
                      const std::vector<std::string>& footer, int width, int height) {
  PlotFigure f;
  f.panels = panels;
  f.footer = footer;
  f.width = width, f.height = height;
  return write_plot(path, f);
}

}  // namespace lucent::imaging
