// `lucent view`'s layout and frame budget under a virtual X server: the panel beside the image
// (never over the object) at a small and a large window, with no line wider than the panel; the
// maps refined level by level to the requested settings and then idle (nothing rendered once
// converged); the edited material saved. The screenshots stay in the test's folder
// (view_layout_*.png) for a person to look at.
#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "lucent/materials/material.h"
#include "view_fixture.h"

namespace lucent::testing {
namespace {

// Small settings with T, W_s and W_l given: the frame budget climbs K and N (four levels) to the
// requested K 16, N 50 within seconds on llvmpipe.
const std::string kLevels =
    " --mesh sphere --maps-frames 3 --maps-radiance-map 64 --maps-light-map 64 "
    "--maps-disc-points 200 --light directional:1,0.3,0.5:1,1,1 --exposure 2";

struct Summary {
  long drawn = 0, rendered = 0;
  int level = 0, levels = 0;
  double widest = 0, panel = 0;
  std::string panel_state;
};

Summary summary(const std::string& out) {
  Summary s;
  std::smatch m;
  if (std::regex_search(out, m, std::regex(R"(view: (\d+) frames drawn, (\d+) rendered)"))) {
    s.drawn = std::stol(m[1]);
    s.rendered = std::stol(m[2]);
  }
  if (std::regex_search(out, m, std::regex(R"(quality level (\d+) of (\d+))"))) {
    s.level = std::stoi(m[1]);
    s.levels = std::stoi(m[2]);
  }
  if (std::regex_search(out, m,
                        std::regex(R"(view: panel (\w+), widest line (\d+) of (\d+) px)"))) {
    s.panel_state = m[1];
    s.widest = std::stod(m[2]);
    s.panel = std::stod(m[3]);
  }
  return s;
}

TEST_F(ViewCommand, ThePanelNeverCoversTheObjectNorClipsALine) {
  struct Case {
    const char* size;
    const char* screen;
    const char* state;  // the panel as it starts: folded in a small window, open in a large one
  };
  for (const Case c :
       {Case{"320x240", "640x480", "folded"}, Case{"1280x800", "1400x900", "open"}}) {
    SCOPED_TRACE(c.size);
    const CommandResult r = view(std::string("--material skin1 --size ") + c.size + kLevels +
                                     " --maps-directions 8 --maps-samples 8 --script 'settle; "
                                     "screenshot a.png; screenshot-panel b.png; quit'",
                                 "", c.screen);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Shot a = load_shot(dir_ / "a.png"), b = load_shot(dir_ / "b.png");
    const std::string keep = std::string("view_layout_") + c.size + ".png";
    fs::copy_file(dir_ / "b.png", keep, fs::copy_options::overwrite_existing);
    std::printf("%s: the window with its panel: %s\n", c.size, fs::absolute(keep).string().c_str());
    EXPECT_GT(a.lit, 2000) << "the object is on screen";
    EXPECT_GT(differing_pixels(a, b), 300) << "the panel is drawn";
    EXPECT_EQ(covered_object_pixels(a, b), 0) << "and covers none of the object";
    const Summary s = summary(r.out);
    EXPECT_EQ(s.panel_state, c.state) << r.out;
    // No line wider than the panel (2 px for rounding): a label cut at its edge ("CPU refe", "Esc
    // qui") would be wider.
    if (s.panel_state == "open") EXPECT_LE(s.widest, s.panel + 2) << r.out;
  }
}

TEST_F(ViewCommand, RefinesLevelByLevelToTheRequestedImageAndThenIdles) {
  const CommandResult r = view("--material potato --size 160x120" + kLevels +
                               " --hide-panel --script 'settle; screenshot a.png; sleep 2; "
                               "screenshot b.png; quit'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Summary s = summary(r.out);
  EXPECT_EQ(s.levels, 4) << r.out;        // K 4, 8, 12, 16 with N 9, 17, 25, 50
  EXPECT_EQ(s.level, s.levels) << r.out;  // the requested settings reached
  // Converged, the window kept answering the script (frames drawn) without rendering.
  EXPECT_GE(s.drawn - s.rendered, 20) << r.out;
  const Shot a = load_shot(dir_ / "a.png"), b = load_shot(dir_ / "b.png");
  EXPECT_EQ(differing_pixels(a, b), 0);
  // The same image as the requested settings given outright (no levels, no split frames).
  const fs::path refined = dir_ / "refined.png";
  fs::rename(dir_ / "a.png", refined);
  const CommandResult e = view("--material potato --size 160x120" + kLevels +
                               " --maps-directions 16 --maps-samples 50 --hide-panel "
                               "--script 'settle; screenshot a.png; quit'");
  ASSERT_EQ(e.exit_code, 0) << e.err;
  EXPECT_EQ(summary(e.out).levels, 1) << e.out;
  EXPECT_LE(differing_pixels(load_shot(refined), load_shot(dir_ / "a.png")), 5);
}

// A person's click (xdotool: an X event through the server, as a mouse's) on the panel's fold
// arrow while the maps refine at the seed's settings (a frame was 17 s, and clicks between frames
// were lost): the panel folds. The screenshots stay in the test's folder.
TEST_F(ViewCommand, AClickWhileTheMapsRefineIsAnswered) {
  if (std::system("command -v xdotool >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "xdotool not found (scripts/install-deps installs it)";
  }
  const std::string args =
      "--material marble --mesh bunny --size 640x480 --script 'sleep 6; "
      "screenshot-panel view_layout_clicked.png; quit'";
  // The arrow at the title bar's left end, the window at the screen's corner (no window manager).
  const CommandResult r = view(args, "", "640x480", "sleep 3\nxdotool mousemove 10 9 click 1");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Summary s = summary(r.out);
  EXPECT_EQ(s.panel_state, "folded") << r.out;
  EXPECT_LT(s.level, s.levels) << "the click came while the maps refined: " << r.out;
  ASSERT_TRUE(fs::exists(dir_ / "view_layout_clicked.png"));
  fs::copy_file(dir_ / "view_layout_clicked.png", "view_layout_clicked.png",
                fs::copy_options::overwrite_existing);
  std::printf("the window after the click: %s\n",
              fs::absolute("view_layout_clicked.png").string().c_str());
  // Without the click it stays open (the fold is the click's).
  const CommandResult still = view(args, "", "640x480", "sleep 3");
  ASSERT_EQ(still.exit_code, 0) << still.err;
  EXPECT_EQ(summary(still.out).panel_state, "open") << still.out;
}

TEST_F(ViewCommand, SavesTheMaterialAsAMaterialFile) {
  const CommandResult r = view("--material ketchup --size 160x120" + kLevels +
                               " --maps-directions 4 --maps-samples 4 --script 'wait 2; key e; "
                               "wait 2; save saved.json; quit'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("saved the material ketchup to saved.json"), std::string::npos) << r.out;
  const materials::Material saved = materials::load_material((dir_ / "saved.json").string());
  const materials::Material ketchup = materials::load_material("ketchup");
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(saved.sigma_a[std::size_t(c)], ketchup.sigma_a[std::size_t(c)], 1e-12);
    EXPECT_NEAR(saved.sigma_s_reduced[std::size_t(c)], ketchup.sigma_s_reduced[std::size_t(c)],
                1e-12);
  }
  const CommandResult bad = view("--material ketchup --script 'save saved.txt; quit'");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find("expected FILE.json"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace lucent::testing
