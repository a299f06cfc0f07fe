// `lucent render --budget` (cli/render_command.cpp, render/core/frame_budget.cpp) end to end on
// this machine's OpenGL: the coarse first image, progress away from a terminal, PNG and EXR from
// one run, and the refined image equal to the one the explicit settings give.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_runner.h"

namespace lucent::testing {
namespace {

namespace fs = std::filesystem;

const std::string kScene =
    "render --material marble --mesh sphere --light directional:1,0.5,1:1,1,1 --view 30,20,4 ";

double relative_rmse(const fs::path& a, const fs::path& b) {
  const auto c =
      run_lucent("compare \"" + a.string() + "\" \"" + b.string() + "\" --json", "compare");
  EXPECT_EQ(c.exit_code, 0) << c.err;
  return c.exit_code == 0 ? nlohmann::json::parse(c.out).at("relative_rmse").get<double>() : -1;
}

// A budget far below the seed's settings on a CPU: the coarse image first, a line per tenth of
// progress on stderr (ctest's pipe is not a terminal), PNG and EXR both written, and the stats say
// which quality the budget bought against the requested one.
TEST(RenderBudget, CoarseFirstThenRefinedWithProgressAndBothImages) {
  const auto dir = scratch_dir("render-budget");
  const fs::path png = dir / "b.png", exr = dir / "b.exr", stats = dir / "b.json";
  // W_s and T given: the budget scales K, N and W_l under them (a level of a few seconds fits).
  const auto r = run_lucent(kScene +
                                "--size 48x48 --maps-radiance-map 128 --maps-frames 4 "
                                "--budget 8 -o \"" +
                                png.string() + "\" -o \"" + exr.string() + "\" --stats \"" +
                                stats.string() + "\"",
                            "budget");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(png));
  EXPECT_TRUE(fs::exists(exr));
  EXPECT_NE(r.err.find("render: a first coarse image in " + png.string()), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find('\r'), std::string::npos) << "no carriage returns off a terminal";
  // The progress lines: "render: 40%, 3 s left", rising.
  const std::regex line(R"(render: (\d+)%, [^\n]* left\n)");
  int last = -1, count = 0;
  for (auto it = std::sregex_iterator(r.err.begin(), r.err.end(), line);
       it != std::sregex_iterator(); ++it) {
    const int share = std::stoi((*it)[1]);
    EXPECT_GE(share, last);
    last = share;
    ++count;
  }
  EXPECT_GE(count, 1) << r.err;
  const auto doc = nlohmann::json::parse(std::ifstream(stats));
  const auto& budget = doc.at("budget");
  EXPECT_EQ(budget.at("budget_s").get<double>(), 8);
  EXPECT_EQ(budget.at("requested"), "K 16, W_s 128, W_l 512, N 50, T 4");
  EXPECT_FALSE(budget.at("requested_reached").get<bool>());  // minutes on a CPU, not 8 s
  EXPECT_GT(budget.at("requested_predicted_s").get<double>(), 8);
  ASSERT_GE(budget.at("levels_run").size(), 2u);
  EXPECT_EQ(budget.at("levels_run").at(0), 0);
  // The image's level: the last one run that was not given up (a level whose first measured
  // frame predicts it past the budget is).
  int image_level = 0;
  for (const auto& l : budget.at("levels_run")) {
    const auto& up = budget.at("levels_given_up");
    if (std::find(up.begin(), up.end(), l) == up.end()) image_level = l.get<int>();
  }
  EXPECT_EQ(budget.at("level").get<int>(), image_level);
  EXPECT_NE(r.out.find("within --budget 8 s; the requested K 16"), std::string::npos) << r.out;
  // The wall clock: the coarse image and the levels within the budget and a little (a level runs
  // to its end once begun; 2 s for start-up and writing).
  double total = 0;
  for (const auto& s : budget.at("level_seconds")) total += s.get<double>();
  EXPECT_LT(total, 8 + 2);
  // The PNG and the EXR are one image: compared as displayed (the EXR at the auto exposure the
  // PNG was written with), they differ by the PNG's 8-bit rounding alone.
  EXPECT_LT(relative_rmse(png, exr), 0.01);
  const fs::path again = dir / "again.png";
  const auto t =
      run_lucent("tonemap \"" + exr.string() + "\" -o \"" + again.string() + "\"", "tonemap");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  EXPECT_EQ(relative_rmse(again, png), 0);  // tonemap after the render = the render's PNG
  fs::remove_all(dir);
}

// Without a budget the refinement reaches the requested settings, and its image is the one the
// explicit settings give (the same renderer, the same frames).
TEST(RenderBudget, NoBudgetRefinesToTheExplicitSettingsImage) {
  const auto dir = scratch_dir("render-budget-none");
  const fs::path refined = dir / "refined.exr", explicit_ = dir / "explicit.exr";
  const std::string fixed =
      "--size 32x32 --maps-frames 3 --maps-radiance-map 64 "
      "--maps-light-map 64 --maps-samples 8 --maps-disc-points 200 ";
  const auto a = run_lucent(kScene + fixed + "--budget none --json -o \"" + refined.string() + "\"",
                            "refined");
  ASSERT_EQ(a.exit_code, 0) << a.err;
  const auto doc = nlohmann::json::parse(a.out);
  EXPECT_TRUE(doc.at("budget").at("requested_reached").get<bool>());
  EXPECT_GE(doc.at("budget").at("levels_run").size(), 2u);  // a coarse level came first
  const auto b = run_lucent(
      kScene + fixed + "--maps-directions 16 -o \"" + explicit_.string() + "\"", "explicit");
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_LT(relative_rmse(refined, explicit_), 1e-6);
  fs::remove_all(dir);
}

// The path tracer (and the reference: the same code) within a budget: a coarse pass of 1 of its
// 64 samples written at once, then passes of as many as fit; its samples given, it runs them whole.
TEST(RenderBudget, TheCpuTechniquesAddPassesWithinTheBudgetUnlessTheirSamplesAreGiven) {
  const auto dir = scratch_dir("render-budget-cpu");
  const fs::path png = dir / "p.png", stats = dir / "p.json";
  const auto r = run_lucent(kScene + "--technique pathtrace --size 32x32 --budget 3 -o \"" +
                                png.string() + "\" --stats \"" + stats.string() + "\"",
                            "pathtrace-budget");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("render: a first coarse image in " + png.string()), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("(1 samples per pixel)"), std::string::npos) << r.err;
  const auto budget = nlohmann::json::parse(std::ifstream(stats)).at("budget");
  const auto passes = budget.at("pass_samples").get<std::vector<int>>();
  ASSERT_FALSE(passes.empty());
  EXPECT_EQ(passes.front(), 1);
  int samples = 0;
  for (int n : passes) samples += n;
  EXPECT_LE(samples, 64);
  EXPECT_EQ(budget.at("quality"), std::to_string(samples) + " samples per pixel");
  EXPECT_EQ(budget.at("requested"), "64 samples per pixel");
  EXPECT_EQ(budget.at("requested_reached").get<bool>(), samples == 64);
  // No pass began after the budget ran out (how close the last one ended to it is the planner's
  // prediction, tested on a fake clock in frame_budget_test, not timed here).
  const auto pass_seconds = budget.at("pass_seconds").get<std::vector<double>>();
  ASSERT_EQ(pass_seconds.size(), passes.size());
  double started = 0;
  for (std::size_t i = 0; i + 1 < pass_seconds.size(); ++i) started += pass_seconds[i];
  EXPECT_LT(started, 3) << budget.dump();

  const auto given = run_lucent(kScene +
                                    "--technique pathtrace --size 16x16 --budget 3 "
                                    "--pathtrace-samples-pixel 2 -o \"" +
                                    png.string() + "\" --json",
                                "pathtrace-given");
  ASSERT_EQ(given.exit_code, 0) << given.err;
  EXPECT_FALSE(nlohmann::json::parse(given.out).contains("budget"));
  EXPECT_EQ(given.err.find("first coarse image"), std::string::npos) << given.err;
  fs::remove_all(dir);
}

// Fur over a mesh: the skin under the coat is the maps', within the budget (it took the seed's
// maps settings whole: 17 min on llvmpipe at 640 x 480 where the budget's took 31 s).
TEST(RenderBudget, FurOverAMeshRendersItsSkinWithinTheBudget) {
  const auto dir = scratch_dir("render-budget-fur");
  const fs::path png = dir / "f.png";
  const auto r = run_lucent(kScene +
                                "--technique fur --size 32x32 --maps-radiance-map 128 "
                                "--maps-frames 4 --budget 4 --json -o \"" +
                                png.string() + "\"",
                            "fur-budget");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(png));
  const auto budget = nlohmann::json::parse(r.out).at("budget");
  EXPECT_EQ(budget.at("of"), "the skin under the fur (the radiance maps)");
  EXPECT_EQ(budget.at("requested"), "K 16, W_s 128, W_l 512, N 50, T 4");
  EXPECT_GE(budget.at("levels_run").size(), 1u) << budget.dump();
  EXPECT_LE(budget.at("budget_s").get<double>(), 4);  // what was left of it for the skin
  fs::remove_all(dir);
}

TEST(RenderBudget, RefusesABadBudgetAndTwoImagesOfOneKind) {
  const auto dir = scratch_dir("render-budget-bad");
  for (const std::string& bad : {"0", "-1", "nan", "soon"}) {
    const auto r = run_lucent(
        kScene + "--budget " + bad + " -o \"" + (dir / "x.png").string() + "\"", "bad-budget");
    EXPECT_NE(r.exit_code, 0) << bad;
    EXPECT_NE(r.err.find("--budget: expected seconds per image (> 0) or none, got '" + bad + "'"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir / "x.png"));
  }
  const auto twice = run_lucent(
      kScene + "-o \"" + (dir / "a.png").string() + "\" -o \"" + (dir / "b.png").string() + "\"",
      "two-png");
  EXPECT_NE(twice.exit_code, 0);
  EXPECT_NE(twice.err.find("at most one .png and one .exr"), std::string::npos) << twice.err;
  EXPECT_TRUE(fs::is_empty(dir));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lucent::testing
