// The speed/accuracy map (`lucent bench tradeoff`, render/bench/tradeoff_*.cpp): its Pareto fronts
// and equal-error interpolation on rows made here, and a tiny sweep through every technique
// against the converged reference (skipped without headless OpenGL 4.5).
#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>

#include "lucent/core/error.h"
#include "lucent/render/gl_context.h"
#include "lucent/render/tradeoff_bench.h"

namespace lucent::render {
namespace {

namespace fs = std::filesystem;

TradeoffRow made(const std::string& technique, double image_ms, double frame_ms, double error) {
  TradeoffRow r;
  r.scene = "s", r.technique = technique, r.model = "dipole";
  r.setting = technique + " " + std::to_string(image_ms);
  r.image_ms = image_ms, r.frame_ms = frame_ms;
  r.relative_rmse = error, r.scaled_rmse = error / 2;
  return r;
}

TEST(TradeoffReport, ParetoFrontKeepsOnlyRowsNoOtherBeatsInTimeAndError) {
  const std::vector<TradeoffRow> rows = {made("maps", 100, 10, 0.3), made("maps", 200, 10, 0.4),
                                         made("maps", 300, 10, 0.1), made("maps", 50, 10, 0.5),
                                         made("hierarchical", 150, 1, 0.2)};
  const auto maps = pareto_front(rows, "maps", false);
  ASSERT_EQ(maps.size(), 3u);  // 200 ms / 0.4 is beaten by 100 ms / 0.3
  EXPECT_EQ(maps[0].image_ms, 50);
  EXPECT_EQ(maps[1].image_ms, 100);
  EXPECT_EQ(maps[2].image_ms, 300);
  const auto all = pareto_front(rows, "", false);
  ASSERT_EQ(all.size(), 4u);  // the hierarchical row sits between 100 and 300 ms
  EXPECT_EQ(all[2].technique, "hierarchical");
  // Against time per frame, the hierarchical row (1 ms) comes first; of the maps' equal-time
  // rows only the most accurate stays.
  const auto per_frame = pareto_front(rows, "", true);
  ASSERT_EQ(per_frame.size(), 2u);
  EXPECT_EQ(per_frame[0].technique, "hierarchical");
  EXPECT_EQ(per_frame[1].relative_rmse, 0.1);
  // sh is placed by its scaled error.
  TradeoffRow sh = made("sh", 10, 1, 0.9);
  EXPECT_DOUBLE_EQ(sh.error(), 0.45);
}

TEST(TradeoffReport, EqualErrorTimeIsInterpolatedLogLogAndNeverExtrapolated) {
  const std::vector<TradeoffRow> front = {made("maps", 10, 1, 0.4), made("maps", 1000, 1, 0.1)};
  // Half-way in log error (0.2 = sqrt(0.4 * 0.1)) is half-way in log time (100 ms).
  EXPECT_NEAR(maps_time_at_error(front, 0.2, false), 100, 1e-9);
  EXPECT_DOUBLE_EQ(maps_time_at_error(front, 0.4, false), 10);
  EXPECT_DOUBLE_EQ(maps_time_at_error(front, 0.1, false), 1000);
  EXPECT_LT(maps_time_at_error(front, 0.5, false), 0);   // worse than the fastest maps
  EXPECT_LT(maps_time_at_error(front, 0.05, false), 0);  // better than the maps' best
  EXPECT_LT(maps_time_at_error({}, 0.2, false), 0);
}

TEST(TradeoffReport, CsvQuotesFieldsWithCommasAndSummarySaysWhereNoRatioExists) {
  std::vector<TradeoffRow> rows = {made("maps", 10, 1, 0.4), made("maps", 1000, 1, 0.1),
                                   made("sh", 5, 1, 0.8), made("hierarchical", 20, 2, 0.01)};
  rows[0].setting = "light: K 8, frame 1";
  const std::string csv = tradeoff_csv(rows);
  EXPECT_NE(csv.find("\"light: K 8, frame 1\""), std::string::npos);
  std::istringstream lines(csv);
  std::string line;
  int n = 0;
  while (std::getline(lines, line)) ++n;
  EXPECT_EQ(n, 5);
  const std::string md = tradeoff_summary(rows, "test machine", "a converged reference", 8192);
  EXPECT_NE(md.find("none (right only up to a scale)"), std::string::npos);
  EXPECT_NE(md.find("the maps never reach it"), std::string::npos);  // 0.01 < the maps' 0.1
  EXPECT_NE(md.find("test machine"), std::string::npos);
}

TEST(TradeoffReport, BadScenesAreRefusedBeforeAnyWork) {
  TradeoffBenchOptions o;
  o.out_dir = fs::temp_directory_path() / "lucent_tradeoff_refused";
  for (const char* bad : {"sphere/marble", "sphere/marble/sunlight", "/marble/point"}) {
    o.scenes = {bad};
    std::ostringstream log;
    EXPECT_THROW(run_tradeoff_bench(o, log), Error) << bad;
  }
  o.scenes = {"sphere/nosuchmaterial/point"};
  std::ostringstream log;
  EXPECT_THROW(run_tradeoff_bench(o, log), Error);
  EXPECT_FALSE(fs::exists(o.out_dir / "tradeoff.csv"));
}

// A tiny sweep of one scene into a fresh folder named after `tag`.
TradeoffBenchOptions tiny_sweep(const std::string& tag, const std::string& scene, int size) {
  TradeoffBenchOptions o;
  o.out_dir = fs::temp_directory_path() / ("lucent_tradeoff_" + tag + std::to_string(::getpid()));
  fs::remove_all(o.out_dir);
  o.scenes = {scene};
  o.sweep = TradeoffSweep::kTiny;
  o.size = size;
  return o;
}

// The check: the CSV with every technique. One tiny scene (320 triangles, 32 px, a
// reference of 512 probes): ~6 s on llvmpipe.
TEST(TradeoffBench, TinySweepMeasuresEveryTechniqueAgainstTheReference) {
  setenv("MESA_SHADER_CACHE_DISABLE", "true", 0);
  std::string why_not;
  if (!GlContext::try_create_headless(&why_not)) GTEST_SKIP() << "no headless OpenGL: " << why_not;
  TradeoffBenchOptions o = tiny_sweep("", "sphere:2/marble/directional", 32);
  o.truth = TradeoffTruth::kReference;  // the bounds below are the pipelines' own error
  o.reference_samples = 512;
  std::ostringstream log;
  const std::vector<TradeoffRow> rows = run_tradeoff_bench(o, log);
  std::set<std::string> techniques;
  for (const TradeoffRow& r : rows) {
    techniques.insert(r.technique);
    EXPECT_TRUE(std::isfinite(r.error()) && r.error() > 0) << r.technique << " " << r.setting;
    EXPECT_GT(r.frame_ms, 0) << r.technique;
    EXPECT_GE(r.image_ms, r.frame_ms) << r.technique;
    EXPECT_GE(r.converge_ms, r.frame_ms) << r.technique;
    EXPECT_EQ(r.triangles, 320);
    // Measured at these settings: reference (64 probes) 0.045, maps (K 4, W 64, N 8, M 64)
    // 0.12, hierarchical (epsilon 0.2 / 1.6) 0.052, sh scaled 0.49 with correlation 0.72. The
    // bounds are what each must at least do to be the technique at all, with the yardstick's own
    // noise (~1.5% at 512 probes) well inside them: the reference's noise at 64 probes is
    // sqrt(512 / 64 + 1) times that, ~4.5%; the maps' tiny setting is coarse (20% bound); the
    // hierarchical technique must meet the 10% on a lit sphere.
    if (r.technique == "reference") {
      EXPECT_LT(r.relative_rmse, 0.08);
    } else if (r.technique == "maps") {
      EXPECT_LT(r.relative_rmse, 0.2);
    } else if (r.technique == "hierarchical") {
      EXPECT_LT(r.relative_rmse, 0.1);
    }
    if (r.technique == "sh") {
      EXPECT_GT(r.correlation, 0.5);  // the bound for sh (set for the bunny)
      EXPECT_LT(r.scaled_rmse, r.relative_rmse);
    }
  }
  EXPECT_EQ(techniques, (std::set<std::string>{"maps", "sh", "hierarchical", "reference"}));
  std::ifstream csv(o.out_dir / "tradeoff.csv");
  std::string line;
  int lines = 0;
  while (std::getline(csv, line)) ++lines;
  EXPECT_EQ(lines, int(rows.size()) + 1);
  for (const char* f : {"tradeoff.png", "tradeoff.svg", "tradeoff_summary.md"}) {
    EXPECT_GT(fs::file_size(o.out_dir / f), 1000u) << f;
  }
  fs::remove_all(o.out_dir);
}

}  // namespace
// Against the path-traced truth (the default): a 20 mm skin1 sphere (paths stay short), every
// technique measured, the summary naming the truth. The maps and the reference carry their
// model's error now: the dipole is 1.3-1.6 times too bright in green and blue here, and the shape's
// factor (materials/geometry_factor.h: the osculating sphere, +10-30% within a few mean free paths
// on a convex 20 mm sphere, as Monte Carlo has it) adds to it: measured 0.38-0.51 (the tiny maps'
// first frame the most; the oblique skew, materials/angular.h, takes 5-15% back); bounded at 0.6.
// Red, where the dipole is nearly right on a plane, is held to 0.9-1.25: measured 1.15-1.19 with
// the factor and the skew (the tabulated model's reference is 0.97-1.02 on a 30 mm skin1: the rest
// is the dipole's own excess in red); without its single scattering a technique loses a quarter of
// it (notebooks_data/bench/previews_vs_truth.sh).
TEST(TradeoffBench, TinySweepAgainstThePathTracedTruth) {
  setenv("MESA_SHADER_CACHE_DISABLE", "true", 0);
  std::string why_not;
  if (!GlContext::try_create_headless(&why_not)) GTEST_SKIP() << "no headless OpenGL: " << why_not;
  TradeoffBenchOptions o = tiny_sweep("pt_", "sphere:2/skin1/directional/20", 24);
  o.truth_samples = 256;
  std::ostringstream log;
  const std::vector<TradeoffRow> rows = run_tradeoff_bench(o, log);
  std::set<std::string> techniques;
  for (const TradeoffRow& r : rows) {
    techniques.insert(r.technique);
    EXPECT_TRUE(std::isfinite(r.error()) && r.error() > 0) << r.technique << " " << r.setting;
    std::printf("%s %s %s: error %.3f, means %.3f %.3f %.3f\n", r.technique.c_str(),
                r.model.c_str(), r.setting.c_str(), r.error(), r.mean_ratio[0], r.mean_ratio[1],
                r.mean_ratio[2]);
    if (r.technique == "reference" || r.technique == "maps") {
      EXPECT_LT(r.relative_rmse, 0.6) << r.technique;
      EXPECT_GT(r.mean_ratio[0], 0.9) << r.technique;
      EXPECT_LT(r.mean_ratio[0], 1.25) << r.technique;
    }
  }
  EXPECT_EQ(techniques.size(), 4u);
  std::ifstream summary(o.out_dir / "tradeoff_summary.md");
  const std::string text((std::istreambuf_iterator<char>(summary)),
                         std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("path-traced truth"), std::string::npos);
  fs::remove_all(o.out_dir);
}

}  // namespace lucent::render
