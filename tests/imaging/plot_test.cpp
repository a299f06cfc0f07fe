// imaging/src/plot.cpp: formats by extension, atomic output, skipped values, maps, and the layout
// (legends outside the data, stacked panels on one x viewport, titles never clipped).
#include "lucent/imaging/plot.h"

#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include "lucent/core/error.h"

namespace lucent::imaging {
namespace {

namespace fs = std::filesystem;

fs::path scratch_root() {
  return fs::temp_directory_path() / ("lucent_plot_test_" + std::to_string(::getpid()));
}

// Removes this run's scratch folders at exit.
struct RemoveScratch {
  ~RemoveScratch() {
    std::error_code ec;
    fs::remove_all(scratch_root(), ec);
  }
} remove_scratch;

fs::path scratch(const std::string& name) {
  const fs::path dir = scratch_root() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

std::size_t files_in(const fs::path& dir) {
  return std::size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

// A profile with error bars and a fit, and a residual panel under it.
PlotFigure profile_figure(int points) {
  PlotPanel profile, residuals;
  profile.title = "profile of a test material";
  profile.x_label = "r (mm)";
  profile.y_label = "value (1/mm^2)";
  profile.log_y = true;
  profile.height_weight = 2;
  PlotSeries data, fit, res;
  data.label = "data R";
  data.rgb = {200, 30, 30};
  fit.label = "fit R";
  fit.markers = false, fit.line = true;
  for (int i = 0; i < points; ++i) {
    const double r = 0.2 + 0.3 * i, v = std::exp(-r) / (r + 0.5);
    data.x.push_back(r), data.y.push_back(v * (1 + 0.05 * std::sin(i))),
        data.y_error.push_back(0.05 * v);
    fit.x.push_back(r), fit.y.push_back(v);
    res.x.push_back(r), res.y.push_back(std::sin(i));
  }
  profile.series = {data, fit};
  residuals.title = "residuals (SE)";
  residuals.x_label = "r (mm)";
  residuals.reference_lines = {{0.0}, {2.0, false, true}, {-2.0, false, true}};
  residuals.series = {res};
  PlotFigure f;
  f.panels = {profile, residuals};
  f.share_x = true;
  f.footer = {"parameters: sigma_a = 0.01 /mm, sigma_s' = 1 /mm"};
  f.width = 640, f.height = 480;
  return f;
}

TEST(Plot, FormatFollowsTheExtensionInAnyCase) {
  EXPECT_EQ(plot_format("a/fit.svg"), PlotFormat::kSvg);
  EXPECT_EQ(plot_format("fit.PDF"), PlotFormat::kPdf);
  EXPECT_EQ(plot_format("fit.Png"), PlotFormat::kPng);
  for (const char* bad : {"fit.txt", "fit", "fit.png.tmp", "fit.jpeg"}) {
    try {
      plot_format(bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(".svg, .pdf or .png"), std::string::npos) << e.what();
    }
  }
}

TEST(Plot, SvgIsXmlWithItsWordsAndGrowsWithTheData) {
  const fs::path dir = scratch("svg");
  write_plot(dir / "few.svg", profile_figure(5));
  write_plot(dir / "many.svg", profile_figure(60));
  const std::string few = read_bytes(dir / "few.svg"), many = read_bytes(dir / "many.svg");
  EXPECT_EQ(few.rfind("<?xml", 0), 0u);
  EXPECT_NE(few.find("<svg"), std::string::npos);
  EXPECT_NE(few.find("</svg>"), std::string::npos);
  // cairo draws text as glyph outlines; the title and legend are kept as <title> and <desc>.
  EXPECT_NE(few.find("<title>profile of a test material</title>"), std::string::npos);
  EXPECT_NE(few.find("legend: data R"), std::string::npos);
  EXPECT_NE(few.find("legend: fit R"), std::string::npos);
  EXPECT_GT(count(many, "<path"), count(few, "<path") + 100);  // a marker is a path
}

TEST(Plot, PdfAndPngAreWhatTheyClaim) {
  const fs::path dir = scratch("pdf_png");
  PlotFigure f = profile_figure(20);
  write_plot(dir / "fit.pdf", f);
  EXPECT_EQ(read_bytes(dir / "fit.pdf").rfind("%PDF", 0), 0u);
  f.width = 700, f.height = 520;
  write_plot(dir / "fit.PNG", f);
  const std::string png = read_bytes(dir / "fit.PNG");
  ASSERT_GT(png.size(), 33u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(png.substr(12, 4), "IHDR");
  const auto be32 = [&](std::size_t at) {
    return (unsigned(std::uint8_t(png[at])) << 24) | (unsigned(std::uint8_t(png[at + 1])) << 16) |
           (unsigned(std::uint8_t(png[at + 2])) << 8) | unsigned(std::uint8_t(png[at + 3]));
  };
  EXPECT_EQ(be32(16), 700u);
  EXPECT_EQ(be32(20), 520u);
}

TEST(Plot, UnknownExtensionThrowsNamingThePathAndLeavesNoFile) {
  const fs::path dir = scratch("bad_extension");
  try {
    write_plot(dir / "fit.jpg", profile_figure(5));
    ADD_FAILURE() << "fit.jpg accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find((dir / "fit.jpg").string()), std::string::npos);
    EXPECT_NE(std::string(e.what()).find(".svg, .pdf or .png"), std::string::npos);
  }
  EXPECT_EQ(files_in(dir), 0u);
}

TEST(Plot, FailureMidwayLeavesNoPartialFileAndTheOldOneWhole) {
  const fs::path dir = scratch("midway");
  { std::ofstream(dir / "fit.png") << "old"; }
  PlotFigure f = profile_figure(10);
  f.panels[1].series[0].y.pop_back();  // the second panel is inconsistent: found while drawing
  EXPECT_THROW(write_plot(dir / "fit.png", f), Error);
  EXPECT_EQ(read_bytes(dir / "fit.png"), "old");
  EXPECT_EQ(files_in(dir), 1u);  // no temporary left
  f = profile_figure(10);
  f.panels.push_back(PlotPanel{});
  f.panels.back().maps.push_back(PlotMap{"bad", 3, 3, {1, 2}});  // 2 values for 3 x 3
  try {
    write_plot(dir / "new.svg", f);
    ADD_FAILURE() << "a 3 x 3 map of 2 values drawn";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("new.svg"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("3 x 3"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "new.svg"));
  EXPECT_EQ(files_in(dir), 1u);
}

TEST(Plot, NonFiniteAndNonPositiveValuesOnLogAxesAreSkipped) {
  const fs::path dir = scratch("skipped");
  PlotPanel p;
  p.log_x = p.log_y = true;
  PlotSeries s;
  s.x = {1, 2, NAN, 4, -1, 6, 0, 8, INFINITY};
  s.y = {1, -2, 3, NAN, 5, 0, 7, 1e-3, 9};
  s.y_error = {0.5, 1, 1, 1, 1, 1, 1, 2e-3, NAN};  // the last bar reaches below 0
  PlotSeries line = s;
  line.markers = false, line.line = true;
  p.series = {s, line, PlotSeries{}};  // and an empty one
  const PlotLayout layout = write_plot(dir / "log.png", {p});
  EXPECT_EQ(layout.panels.at(0).points_drawn, 2);  // (1, 1) and (8, 1e-3)
  // Nothing valid at all: still a plot.
  PlotPanel empty;
  empty.log_y = true;
  PlotSeries negative;
  negative.x = {1, 2}, negative.y = {-1, 0};
  empty.series = {negative};
  EXPECT_EQ(write_plot(dir / "empty.svg", {empty, PlotPanel{}}).panels.at(0).points_drawn, 0);
  EXPECT_TRUE(fs::exists(dir / "empty.svg"));
  // Extremes whose span would overflow are skipped too; a constant series still gets a range.
  PlotPanel extreme;
  extreme.series = {negative, negative};
  extreme.series[0].y = {-1.7e308, 1.7e308};
  extreme.series[1].x = {3, 3}, extreme.series[1].y = {5, 5};
  EXPECT_EQ(write_plot(dir / "extreme.pdf", {extreme}).panels.at(0).points_drawn, 2);
}

TEST(Plot, LegendSitsOutsideTheDataRightOrBelow) {
  const fs::path dir = scratch("legend");
  const PlotBox page{0, 1, 0, 1};
  for (LegendPlace place : {LegendPlace::kRight, LegendPlace::kBelow}) {
    PlotFigure f = profile_figure(30);
    f.legend = place;
    const PlotLayout layout = write_plot(dir / "legend.png", f);
    const PanelLayout& p = layout.panels.at(0);
    ASSERT_FALSE(p.legend.empty());
    EXPECT_FALSE(p.legend.overlaps(p.plot));
    EXPECT_TRUE(p.legend.inside(page));
    if (place == LegendPlace::kRight) {
      EXPECT_GE(p.legend.x0, p.plot.x1);
    } else {
      EXPECT_LE(p.legend.y1, p.plot.y0);
    }
    for (const PanelLayout& other : layout.panels) EXPECT_FALSE(p.legend.overlaps(other.plot));
    EXPECT_TRUE(layout.panels.at(1).legend.empty());  // no labels, no legend
  }
  // Labels too long for the right: the legend goes below.
  PlotFigure f = profile_figure(30);
  f.panels[0].series[0].label = std::string(60, 'w');
  const PanelLayout p = write_plot(dir / "long.png", f).panels.at(0);
  EXPECT_LE(p.legend.y1, p.plot.y0);
  EXPECT_FALSE(p.legend.overlaps(p.plot));
  EXPECT_GT(p.plot.x1 - p.plot.x0, 0.5);
}

TEST(Plot, StackedPanelsShareTheXViewportAndRange) {
  const fs::path dir = scratch("aligned");
  PlotFigure f = profile_figure(30);
  f.panels[1].series[0].x.back() = 40;  // the residuals reach further: the shared range follows
  f.panels[1].y_label = "a much longer y label than the profile's";
  const PlotLayout layout = write_plot(dir / "aligned.svg", f);
  const PanelLayout &top = layout.panels.at(0), &bottom = layout.panels.at(1);
  EXPECT_DOUBLE_EQ(top.plot.x0, bottom.plot.x0);
  EXPECT_DOUBLE_EQ(top.plot.x1, bottom.plot.x1);
  EXPECT_DOUBLE_EQ(top.x_min, bottom.x_min);
  EXPECT_DOUBLE_EQ(top.x_max, bottom.x_max);
  EXPECT_GE(top.x_max, 40);
  EXPECT_GT(top.plot.y0, bottom.plot.y1);  // stacked, not overlapping
  EXPECT_FALSE(layout.footer.overlaps(bottom.plot));
  EXPECT_LT(layout.footer.y1, bottom.plot.y0);
}

TEST(Plot, LongTitlesWrapOrShrinkAndStayOnThePage) {
  const fs::path dir = scratch("title");
  PlotFigure f = profile_figure(10);
  f.panels[0].title =
      "profile: data (points, +-1 SE) and tabulated fit (lines); excluded region in light "
      "colours; y: pi L / P (1/mm^2), one more clause to make it long enough for two lines";
  const PlotLayout layout = write_plot(dir / "title.png", f);
  const PanelLayout& p = layout.panels.at(0);
  EXPECT_TRUE(p.title_lines >= 2 || p.title_scale < 1);
  EXPECT_TRUE(p.title.inside(PlotBox{0, 1, 0, 1}));
  EXPECT_GE(p.title.y0, p.plot.y1);
  EXPECT_FALSE(p.title.overlaps(p.legend));
}

TEST(Plot, MapPanelHasItsColourBarBesideTheMaps) {
  const fs::path dir = scratch("map");
  PlotPanel maps;
  maps.title = "residual map";
  maps.x_label = "x (mm)", maps.y_label = "y (mm)", maps.colour_label = "(model - data) / SE";
  for (int c = 0; c < 3; ++c) {
    PlotMap m{"channel " + std::to_string(c), 40, 30, {}, -10, 10, -7.5, 7.5};
    for (int iy = 0; iy < m.ny; ++iy)
      for (int ix = 0; ix < m.nx; ++ix)
        m.values.push_back(ix == iy ? NAN : std::sin(0.3 * ix + c) * 5 * std::cos(0.2 * iy));
    maps.maps.push_back(m);
  }
  PlotFigure f = profile_figure(20);
  f.panels.push_back(maps);
  f.height = 800;
  for (const char* name : {"map.png", "map.svg", "map.pdf"}) {
    const PlotLayout layout = write_plot(dir / name, f);
    const PanelLayout& p = layout.panels.at(2);
    ASSERT_EQ(p.maps.size(), 3u);
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_TRUE(p.maps[k].inside(PlotBox{0, 1, 0, 1}));
      EXPECT_FALSE(p.maps[k].overlaps(p.colour_bar));
      if (k > 0) {
        EXPECT_FALSE(p.maps[k].overlaps(p.maps[k - 1]));
      }
    }
    EXPECT_GE(p.colour_bar.x0, p.maps.back().x1);
    EXPECT_TRUE(p.colour_bar.inside(PlotBox{0, 1, 0, 1}));
    // Equal scales: 20 mm by 15 mm on the page (points are square in every format).
    const double aspect =
        (p.maps[0].x1 - p.maps[0].x0) * f.width / ((p.maps[0].y1 - p.maps[0].y0) * f.height);
    EXPECT_NEAR(aspect, 20.0 / 15.0, 1e-6);
    EXPECT_GT(fs::file_size(dir / name), 1000u);
  }
  // A row of maps alone, wider than the page allows at full height: narrowed, still on the page.
  f.panels = {maps};
  f.height = 2000;
  const PanelLayout p = write_plot(dir / "maps_only.png", f).panels.at(0);
  EXPECT_TRUE(p.colour_bar.inside(PlotBox{0, 1, 0, 1}));
  EXPECT_TRUE(p.maps.back().inside(PlotBox{0, 1, 0, 1}));
}

TEST(Plot, TooSmallAFigureIsRefusedWithoutAFile) {
  const fs::path dir = scratch("small");
  PlotFigure f = profile_figure(5);
  f.width = 120, f.height = 100;
  for (int i = 0; i < 6; ++i) f.panels.push_back(f.panels[0]);
  EXPECT_THROW(write_plot(dir / "small.png", f), Error);
  f.width = 50;
  EXPECT_THROW(write_plot(dir / "tiny.png", f), Error);
  EXPECT_EQ(files_in(dir), 0u);
}

TEST(Plot, ConcurrentWritersEachGetAWholeFile) {
  const fs::path dir = scratch("threads");
  std::vector<std::thread> threads;
  for (int t = 0; t < 3; ++t) {
    threads.emplace_back([&, t] {
      for (int k = 0; k < 2; ++k)
        write_plot(dir / ("t" + std::to_string(t) + "_" + std::to_string(k) + ".svg"),
                   profile_figure(10 + t));
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(files_in(dir), 6u);
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_NE(read_bytes(entry.path()).find("</svg>"), std::string::npos) << entry.path();
}

}  // namespace
}  // namespace lucent::imaging
