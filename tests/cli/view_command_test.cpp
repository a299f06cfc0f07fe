// End-to-end tests of `lucent view` under a virtual X server (xvfb-run): the window opens, a script
// drives it (orbit, light drag, key presses, settings, the deformer, the CPU reference, a material
// file edited while it runs) and screenshots show what it drew. Bad input fails with one line.
#include <gtest/gtest.h>

#include <string>

#include "view_fixture.h"

namespace lucent::testing {
namespace {

// Tiny settings: llvmpipe renders a 64-texel, 8-direction frame in ~0.1 s.
const std::string kTiny =
    " --mesh sphere --size 200x150 --maps-frames 8 --maps-directions 8 --maps-samples 8 "
    "--maps-disc-points 32"
    " --maps-radiance-map 64 --maps-light-map 64 --reference-samples-pixel 32 --reference-threads "
    "2";

TEST_F(ViewCommand, ScriptOrbitsMovesTheLightAndSavesScreenshots) {
  const CommandResult r =
      view("--material marble --light directional:1,0.3,0.5:1,1,1" + kTiny +
           " --script 'settle; key h; screenshot a.png; orbit 150 0; wait 2; screenshot b.png;"
           " light 150 0; settle; screenshot c.png; key h; wait 2; screenshot d.png;"
           " screenshot-panel e.png; key s; quit'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* name : {"a.png", "b.png", "c.png", "d.png", "e.png", "lucent_view_001.png"}) {
    ASSERT_TRUE(fs::exists(dir_ / name)) << name << "\n" << r.out << r.err;
  }
  const Shot a = load_shot(dir_ / "a.png"), b = load_shot(dir_ / "b.png"),
             c = load_shot(dir_ / "c.png"), d = load_shot(dir_ / "d.png"),
             e = load_shot(dir_ / "e.png");
  EXPECT_EQ(a.image.width, 200);
  EXPECT_EQ(a.image.height, 150);
  // The sphere at 3.4 radii nearly fills the 35-degree frame's height (a disc of ~73 px radius,
  // ~16,900 px; its unlit side may sink into the background); marble is light grey.
  EXPECT_GT(a.lit, 5000);
  EXPECT_LT(a.lit, 17500);
  EXPECT_GT(a.mean[0], 0.05);
  // Orbiting moves the lit side across the image, and does not restart the accumulation
  // (the maps are view independent); moving the light does.
  EXPECT_GT(differing_pixels(a, b), 300);
  EXPECT_GT(differing_pixels(b, c), 300);
  EXPECT_NE(r.out.find("2 restarts"), std::string::npos) << r.out;  // setup + light drag
  // H toggled the panel back on: at 200 x 150 it is folded to a title bar across the top, and the
  // image moves below it (c, without the panel, and d differ) so that it covers none of the
  // object; screenshots leave the panel out, screenshot-panel keeps it: where d shows the object
  // e (the same frame with the panel) has the same pixels.
  EXPECT_GT(differing_pixels(c, d), 300);
  EXPECT_GT(differing_pixels(d, e), 300);
  EXPECT_EQ(covered_object_pixels(d, e), 0);
  EXPECT_NE(r.out.find("accumulated 8 of 8"), std::string::npos) << r.out;
}

// The script's `set` takes the CLI's flag names (and the panel's short ones): T becomes 4, N 4.
TEST_F(ViewCommand, ScriptSetsKnobsByTheirFlagNames) {
  CommandResult r = view("--material marble --light directional:1,0.3,0.5:1,1,1" + kTiny +
                         " --script 'set maps-frames 4; set maps-samples 4; set N 6; set "
                         "maps-disc-selection nearest; settle; quit'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("accumulated 4 of 4"), std::string::npos) << r.out;
  r = view("--material marble --light directional:1,0.3,0.5:1,1,1" + kTiny +
           " --script 'set maps-bogus 4; quit'");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("set maps-bogus: expected maps-samples"), std::string::npos) << r.err;
}

TEST_F(ViewCommand, ReloadsAnEditedMaterialDeformsAndShowsTheReference) {
  fs::copy_file(fs::path(LUCENT_SOURCE_DIR) / "materials/library/marble.json",
                dir_ / "sample.json");
  // Edit the file while the window is open: once a.png exists, ketchup replaces marble.
  const std::string edit =
      "(for i in $(seq 600); do [ -f a.png ] && break; sleep 0.1; done; cp \"" +
      (fs::path(LUCENT_SOURCE_DIR) / "materials/library/ketchup.json").string() +
      "\" sample.json) & ";
  const CommandResult r =
      view("--material sample.json --light directional:0,0.3,1:1,1,1" + kTiny +
               " --script 'settle; key h; screenshot a.png; sleep 3; settle; screenshot b.png;"
               " set deform 0.1; wait 3; screenshot c.png; set deform 0; set technique reference; "
               "settle;"
               " screenshot d.png; quit'",
           edit);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("sample.json changed, reloading"), std::string::npos) << r.out;
  for (const char* name : {"a.png", "b.png", "c.png", "d.png"}) {
    ASSERT_TRUE(fs::exists(dir_ / name)) << name << "\n" << r.out << r.err;
  }
  const Shot a = load_shot(dir_ / "a.png"), b = load_shot(dir_ / "b.png"),
             c = load_shot(dir_ / "c.png"), d = load_shot(dir_ / "d.png");
  // Marble is a warm grey, ketchup red: the red-to-blue ratio grows by far once the edited file is
  // reloaded.
  const double warm = a.mean[0] / a.mean[2], red = b.mean[0] / b.mean[2];
  std::printf("red/blue: marble %.2f, ketchup %.2f (maps), %.2f (reference)\n", warm, red,
              d.mean[0] / d.mean[2]);
  EXPECT_LT(warm, 2.2);        // measured 1.85
  EXPECT_GT(red, 1.3 * warm);  // measured 2.92 = 1.6 x marble
  // The deformed sphere is another shape.
  EXPECT_GT(differing_pixels(b, c), 300);
  // The reference (a pass at half the window's resolution) shows a red sphere of the same size.
  EXPECT_GT(d.lit, b.lit / 2);
  EXPECT_LT(d.lit, b.lit * 2);
  EXPECT_GT(d.mean[0] / d.mean[2], 1.3 * warm);  // measured 3.05
}

// The sh technique in the window: every pass every frame, the scene's state carried into it (a
// deforming mesh changes the image), and the difference view against the cached reference after
// the best scale.
TEST_F(ViewCommand, ShowsTheShTechniqueDeformsItAndComparesItWithTheReference) {
  const CommandResult r =
      view("--material skin1 --light directional:1,0.2,0:3,3,3 --technique sh" + kTiny +
           " --script 'wait 2; screenshot a.png; set technique reference; settle; screenshot b.png;"
           " set technique sh; difference on; wait 31; screenshot c.png; difference off;"
           " set deform 0.1; wait 3; screenshot d.png; quit'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* name : {"a.png", "b.png", "c.png", "d.png"}) {
    ASSERT_TRUE(fs::exists(dir_ / name)) << name << "\n" << r.out << r.err;
  }
  const Shot a = load_shot(dir_ / "a.png"), b = load_shot(dir_ / "b.png"),
             c = load_shot(dir_ / "c.png"), d = load_shot(dir_ / "d.png");
  // sh shows the sphere where the reference does (the reference: half the window's resolution).
  EXPECT_GT(a.lit, b.lit / 2);
  EXPECT_LT(a.lit, b.lit * 2);
  EXPECT_GT(differing_pixels(a, c), 100);  // the difference view is another image
  EXPECT_GT(differing_pixels(a, d), 100);  // the deformed mesh reaches the sh renderer
  // The comparison is printed with its scale and correlation; side-lit skin1 correlates well
  // (ShRendererTest.CorrelatesWithTheReferenceSideLit measures 0.87 at 32 px).
  const std::size_t at = r.out.find("view: sh against the reference");
  ASSERT_NE(at, std::string::npos) << r.out;
  const std::size_t corr = r.out.find("correlation ", at);
  ASSERT_NE(corr, std::string::npos) << r.out;
  EXPECT_GT(std::stod(r.out.substr(corr + 12)), 0.6) << r.out.substr(at, 300);
}

// The hierarchical technique in the window, compared with the reference without a scale.
TEST_F(ViewCommand, ShowsTheHierarchicalTechniqueAgainstTheReference) {
  const CommandResult r =
      view("--material potato --light directional:1,0.2,0:3,3,3 --technique hierarchical" +
           kTiny + " --script 'wait 2; screenshot a.png; set technique reference;"
           " settle; set technique hierarchical; difference on; wait 31; quit'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::exists(dir_ / "a.png")) << r.out << r.err;
  EXPECT_GT(load_shot(dir_ / "a.png").lit, 1000);
  const std::size_t at = r.out.find("view: hierarchical against the reference");
  ASSERT_NE(at, std::string::npos) << r.out;
  const std::size_t rmse = r.out.find("relative RMSE ", at);
  ASSERT_NE(rmse, std::string::npos) << r.out;
  // The window's reference pass is noisy (32 probes per pixel): most of this is its noise.
  EXPECT_LT(std::stod(r.out.substr(rmse + 14)), 0.3) << r.out.substr(at, 200);
}

// The path tracer in the window (pass after pass on the worker) and the maps' difference view
// against it: the truth of the same view, without a scale.
TEST_F(ViewCommand, ShowsThePathTracerAndTheMapsAgainstIt) {
  const CommandResult r = view(
      "--material skin1 --light directional:1,0.2,0:3,3,3 --technique pathtrace "
      "--pathtrace-samples-pixel 2" +
      kTiny +
      " --script 'settle; screenshot a.png; set technique maps; difference on; settle; wait 31; "
      "quit'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::exists(dir_ / "a.png")) << r.out << r.err;
  EXPECT_GT(load_shot(dir_ / "a.png").lit, 100);
  const std::size_t at = r.out.find("against the pathtrace");
  ASSERT_NE(at, std::string::npos) << r.out;
  const std::size_t ratio = r.out.find("mean ratio R ", at);
  ASSERT_NE(ratio, std::string::npos) << r.out;
  // The maps miss single scattering and more: below the truth, but the same object.
  const double red = std::stod(r.out.substr(ratio + 13));
  EXPECT_GT(red, 0.3) << r.out.substr(at, 200);
  EXPECT_LT(red, 1.2) << r.out.substr(at, 200);
}

TEST_F(ViewCommand, BadInputFailsWithOneLine) {
  CommandResult r = view("--material no_such_material --light directional:0,0,1:1,1,1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("no_such_material"), std::string::npos) << r.err;
  r = view("--material marble --exposure nope");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--exposure"), std::string::npos) << r.err;
  r = view("--material marble --light directional:0,0,1:1,1,1 --size 0x10");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;
  r = view("--material marble --light directional:0,0,1:1,1,1" + kTiny +
           " --script 'orbit 1 2; fly away'");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--script: 'fly away'"), std::string::npos) << r.err;
  r = view("--material marble --light directional:0,0,1:1,1,1 --deform 2");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--deform"), std::string::npos) << r.err;
  // No X display at all: it says what to do.
  const std::string no_display =
      "env -u DISPLAY \"" LUCENT_BINARY "\" view --material marble --light directional:0,0,1:1,1,1";
  const int status =
      std::system((no_display + " >/dev/null 2>\"" + (dir_ / "e").string() + "\"").c_str());
  EXPECT_NE(status, 0);
  EXPECT_NE(read_text(dir_ / "e").find("xvfb-run"), std::string::npos) << read_text(dir_ / "e");
  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_NE(entry.path().extension(), ".png") << entry.path();  // nothing written
  }
}

}  // namespace
}  // namespace lucent::testing
