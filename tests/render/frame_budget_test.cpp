// The frame budget (render/core/frame_budget.cpp): the maps' quality ladder, the cost model, the
// image budget's levels and the viewer's frame level, driven by a fake machine on a fake clock
// (each pass costs a fixed part plus a part that grows with its work, as measured on llvmpipe).
#include "lucent/render/frame_budget.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace lucent::render {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A machine: the radiance map costs per layer a fixed part plus a part per texel-gather, the final
// pass a fixed part plus per pixel-layer, each level's set-up and first frame (the compile) more.
struct FakeMachine {
  double layer_fixed_ms = 5, ms_per_million_gathers = 35;  // llvmpipe-like: ~28 M gathers/s
  double light_ms_per_light = 4;
  double final_fixed_ms = 80, final_ms_per_million_pixel_layers = 12;
  double setup_ms = 300, compile_ms = 500;

  double radiance_ms(const RenderSettings& s) const {
    const double gathers = double(s.radiance_map_size) * s.radiance_map_size * s.samples;
    return s.directions * (layer_fixed_ms + ms_per_million_gathers * gathers / 1e6);
  }
  double final_ms(const RenderSettings& s, int pixels) const {
    return final_fixed_ms + final_ms_per_million_pixel_layers * double(pixels) * s.directions / 1e6;
  }
  double frame_ms(const RenderSettings& s, int pixels, int lights) const {
    return radiance_ms(s) + lights * light_ms_per_light + final_ms(s, pixels);
  }
};

class FakeRunner final : public BudgetLevelRunner {
 public:
  FakeRunner(const FakeMachine& machine, double& clock_s, int pixels, int lights)
      : machine_(machine), clock_s_(clock_s), pixels_(pixels), lights_(lights) {}
  void start(const RenderSettings& settings) override {
    settings_ = settings;
    frame_ = 0;
    clock_s_ += machine_.setup_ms / 1000;
  }
  bool frame(MeasuredFrame& m) override {
    if (frame_ >= settings_.frames) return false;
    ++frame_;
    m.radiance_ms = machine_.radiance_ms(settings_) + (frame_ == 1 ? machine_.compile_ms : 0);
    m.light_ms = lights_ * machine_.light_ms_per_light;
    m.final_ms = machine_.final_ms(settings_, pixels_);
    clock_s_ += (m.radiance_ms + m.light_ms + m.final_ms) / 1000;
    return true;
  }
  void level_done(int level, bool refined_next) override {
    done.push_back({level, refined_next, clock_s_});
  }
  struct Done {
    int level;
    bool refined_next;
    double at_s;
  };
  std::vector<Done> done;

 private:
  const FakeMachine& machine_;
  double& clock_s_;
  int pixels_, lights_;
  RenderSettings settings_;
  int frame_ = 0;
};

double level_seconds(const FakeMachine& m, const RenderSettings& s, int pixels, int lights) {
  return (m.setup_ms + m.compile_ms + s.frames * m.frame_ms(s, pixels, lights)) / 1000;
}

TEST(QualityLadder, EndsAtTheRequestAndGrowsInWork) {
  const RenderSettings requested;  // the seed's: K 16, W_s 512, W_l 512, N 50, T 100
  const std::vector<RenderSettings> ladder = maps_quality_ladder(requested, {});
  ASSERT_GE(ladder.size(), 4u);
  EXPECT_EQ(quality_text(ladder.back()), quality_text(requested));
  for (std::size_t i = 1; i < ladder.size(); ++i) {
    const RenderSettings &a = ladder[i - 1], &b = ladder[i];
    EXPECT_LE(a.directions, b.directions);
    EXPECT_LE(a.radiance_map_size, b.radiance_map_size);
    EXPECT_LE(a.light_map_size, b.light_map_size);
    EXPECT_LE(a.samples, b.samples);
    EXPECT_LE(a.frames, b.frames);
    EXPECT_NO_THROW(a.validate());
  }
  // The first image is a thousandth of a requested frame's work or less, over two frames.
  const auto work = [](const RenderSettings& s) {
    return double(s.directions) * s.radiance_map_size * s.radiance_map_size * s.samples;
  };
  EXPECT_LE(work(ladder.front()), work(requested) / 1000);
  EXPECT_EQ(ladder.front().frames, 2);
}

TEST(QualityLadder, ExplicitKnobsAreKeptAtEveryLevel) {
  RenderSettings requested;
  requested.directions = 6;
  requested.frames = 3;
  FixedKnobs fixed;
  fixed.directions = fixed.frames = true;
  for (const RenderSettings& s : maps_quality_ladder(requested, fixed)) {
    EXPECT_EQ(s.directions, 6);
    EXPECT_EQ(s.frames, 3);
  }
  fixed.samples = fixed.radiance_map = fixed.light_map = true;
  EXPECT_EQ(maps_quality_ladder(requested, fixed).size(), 1u);  // nothing left to scale
}

TEST(QualityLadder, ASmallRequestHasFewLevels) {
  RenderSettings requested;
  requested.directions = 1;
  requested.samples = 1;
  requested.radiance_map_size = 32;
  requested.light_map_size = 64;
  requested.frames = 2;
  EXPECT_EQ(maps_quality_ladder(requested, {}).size(), 1u);  // every level would be the request
}

TEST(AffineCost, OneAmountOfWorkPredictsThroughTheOriginAndTwoSeparateTheFixedPart) {
  AffineCost cost;
  cost.record(100, 50);
  EXPECT_DOUBLE_EQ(cost.predict(400), 25 + 100);  // half fixed: over-predicts 40 + 0.1 x (80)
  EXPECT_DOUBLE_EQ(cost.predict(50), 25);
  cost.record(400, 80);                      // ms = 40 + 0.1 x
  EXPECT_NEAR(cost.predict(1000), 140, 1e-9);
  EXPECT_NEAR(cost.predict(100), 50, 1e-9);
}

TEST(ImageBudget, NoBudgetRefinesToTheRequestedSettings) {
  const FakeMachine machine;
  double clock = 0;
  FakeRunner runner(machine, clock, 64 * 64, 1);
  const std::vector<RenderSettings> ladder = maps_quality_ladder(RenderSettings{}, {});
  const ImageBudgetRun run = run_image_budget(
      ladder, kInf, 64 * 64, 1, [&] { return clock; }, runner);
  EXPECT_EQ(run.level, int(ladder.size()) - 1);
  ASSERT_FALSE(runner.done.empty());
  EXPECT_EQ(runner.done.front().level, 0);  // the coarse image first ...
  EXPECT_TRUE(runner.done.front().refined_next);
  EXPECT_FALSE(runner.done.back().refined_next);  // ... the requested one last
}

TEST(ImageBudget, TheFirstImageComesEarlyAndTheRefinedOneFitsTheBudget) {
  const FakeMachine machine;
  const int pixels = 640 * 480, lights = 3;
  const std::vector<RenderSettings> ladder = maps_quality_ladder(RenderSettings{}, {});
  for (const double budget_s : {5.0, 20.0, 60.0, 300.0}) {
    SCOPED_TRACE(budget_s);
    double clock = 0;
    FakeRunner runner(machine, clock, pixels, lights);
    std::vector<double> shares;
    const ImageBudgetRun run = run_image_budget(
        ladder, budget_s, pixels, lights, [&] { return clock; }, runner,
        [&](double share, double) { shares.push_back(share); });
    // The first image within 2 s on this machine (the target on llvmpipe).
    EXPECT_LT(runner.done.front().at_s, 2.0);
    // Within the budget (the model over-predicts before it has two levels' frames, on this
    // machine, whose fixed part is over half the coarse level's).
    EXPECT_LE(clock, budget_s);
    // Not far below it: the best level that fits alone after the coarse one would have been
    // within the budget, and the one chosen is that one or one below it.
    int best = 0;
    for (int l = 1; l < int(ladder.size()); ++l)
      if (runner.done.front().at_s +
              level_seconds(machine, ladder[std::size_t(l)], pixels, lights) <=
          budget_s)
        best = l;
    EXPECT_GE(run.level, best - 1);
    // Progress between 0 and 1.
    for (double s : shares) {
      EXPECT_GE(s, 0.0);
      EXPECT_LE(s, 1.0);
    }
  }
}

TEST(ImageBudget, TheModelLearnsTheMachineFromTheLevelsItRan) {
  const FakeMachine machine;
  const int pixels = 640 * 480, lights = 1;
  const std::vector<RenderSettings> ladder = maps_quality_ladder(RenderSettings{}, {});
  double clock = 0;
  FakeRunner runner(machine, clock, pixels, lights);
  const ImageBudgetRun run = run_image_budget(
      ladder, 60, pixels, lights, [&] { return clock; }, runner);
  ASSERT_GE(run.levels_run.size(), 2u);
  // Two levels measured: the requested frame predicted within a factor 2 of the machine's (it is
  // extrapolated 4-40x beyond the work measured).
  const double truth = machine.frame_ms(ladder.back(), pixels, lights);
  EXPECT_GT(run.requested_frame_ms, 0.5 * truth);
  EXPECT_LT(run.requested_frame_ms, 2.0 * truth);
}

TEST(ImageBudget, TriesALevelTheFirstGuessRulesOutAndGivesUpOneThatWillNotFit) {
  // A machine whose coarse level is almost all fixed cost (16 environment lights' light maps and
  // a large final pass): from the coarse frames alone every refinement looks too dear.
  FakeMachine machine;
  machine.final_fixed_ms = 300;
  machine.light_ms_per_light = 20;
  const int pixels = 160 * 160, lights = 16;
  const std::vector<RenderSettings> ladder = maps_quality_ladder(RenderSettings{}, {});
  bool gave_up = false;
  for (const double budget_s : {20.0, 40.0, 90.0}) {
    SCOPED_TRACE(budget_s);
    double clock = 0;
    FakeRunner runner(machine, clock, pixels, lights);
    const ImageBudgetRun run = run_image_budget(
        ladder, budget_s, pixels, lights, [&] { return clock; }, runner);
    ASSERT_FALSE(runner.done.empty());
    EXPECT_EQ(run.level, runner.done.back().level);  // the image is the last level done
    // Refined beyond the coarse level wherever a level fits after it.
    const double after_coarse = budget_s - runner.done.front().at_s;
    if (level_seconds(machine, ladder[1], pixels, lights) < after_coarse) {
      EXPECT_GE(run.level, 1);
    }
    // Within the budget and one measured frame of a level given up (its set-up, the compile and
    // two frames at most).
    double slack = 0;
    for (const RenderSettings& s : ladder)
      slack = std::max(
          slack,
          (machine.setup_ms + machine.compile_ms + 2 * machine.frame_ms(s, pixels, lights)) / 1000);
    EXPECT_LE(clock, budget_s + slack);
    // Every level run was done or given up, never both.
    EXPECT_EQ(run.levels_run.size(), runner.done.size() + run.levels_given_up.size());
    for (int l : run.levels_given_up) {
      EXPECT_TRUE(std::none_of(runner.done.begin(), runner.done.end(),
                               [l](const FakeRunner::Done& d) { return d.level == l; }));
    }
    gave_up = gave_up || !run.levels_given_up.empty();
  }
  EXPECT_TRUE(gave_up) << "a level tried on this machine's first guess and given up";
}

TEST(FrameSplit, EachCallFitsTheBudgetAndAWholeFrameIsOneCall) {
  // A frame that fits is not split.
  FrameSplit split = plan_split(2, 16, 10, 50);
  EXPECT_EQ(split.bands, 1);
  EXPECT_EQ(split.units_per_call, 0);
  for (const double layer_ms : {5.0, 20.0, 90.0, 470.0, 3000.0}) {
    for (const double budget_ms : {30.0, 50.0, 100.0}) {
      SCOPED_TRACE(testing::Message() << layer_ms << " ms a layer, " << budget_ms << " ms budget");
      split = plan_split(layer_ms, 16, 20, budget_ms);
      ASSERT_GE(split.bands, 1);
      ASSERT_LE(split.bands, 64);
      EXPECT_EQ(split.bands & (split.bands - 1), 0);  // a power of two
      const double unit = layer_ms / split.bands;
      const int units = split.units_per_call == 0 ? 16 * split.bands : split.units_per_call;
      // Within the budget after the final pass (or half the budget when the final pass takes
      // more: the viewer lowers the resolution then), one unit where one is over it (a layer of
      // 3 s in 64 bands is 47 ms).
      const double room = std::max(budget_ms - 20, 0.5 * budget_ms);
      if (units > 1) {
        EXPECT_LE(units * unit, room + 1e-9);
      }
      if (split.bands < 64) {
        EXPECT_LE(unit, 0.5 * budget_ms);
      }
      // Not wastefully small: one more unit would not have fitted.
      if (split.units_per_call > 0 && units < 16 * split.bands && unit <= room) {
        EXPECT_GT((units + 1) * unit, room);
      }
    }
  }
}

TEST(FrameSplit, ALargerLevelIsPredictedInProportionToItsWork) {
  RenderSettings small, large;
  small.radiance_map_size = 64;
  small.samples = 9;
  large.radiance_map_size = 256;
  large.samples = 25;
  EXPECT_NEAR(predict_layer_ms(10, small, large), 10 * 16 * 25 / 9.0, 1e-9);
}

TEST(AffineCost, AFixedShareOfZeroPredictsInProportion) {
  AffineCost cost(0.0);
  cost.record(1, 400);
  EXPECT_DOUBLE_EQ(cost.predict(30), 12000);
}

// The CPU techniques' samples: a machine whose pass of n samples takes fixed + per_sample n
// seconds, on a fake clock.
struct FakeSamplePasses {
  double fixed_s, per_sample_s;
  double clock_s = 0;
  std::vector<int> ran;
  SampleBudgetRun run(int requested, double budget_s) {
    return run_sample_budget(
        requested, budget_s, [this] { return clock_s; },
        [this](int n, int pass) {
          EXPECT_EQ(pass, int(ran.size()));
          ran.push_back(n);
          clock_s += fixed_s + per_sample_s * n;
        });
  }
};

TEST(SampleBudget, NoBudgetRunsEverySampleAfterACoarsePass) {
  FakeSamplePasses machine{0.2, 0.05};
  const SampleBudgetRun run = machine.run(1024, kInf);
  EXPECT_EQ(run.pass_samples, (std::vector<int>{16, 1008}));  // requested / 64 first
  EXPECT_EQ(run.samples, 1024);
  EXPECT_EQ(machine.ran, run.pass_samples);
  ASSERT_EQ(run.pass_seconds.size(), 2u);
  EXPECT_NEAR(run.pass_seconds[0], 0.2 + 0.05 * 16, 1e-12);
  FakeSamplePasses one{0.2, 0.05};
  EXPECT_EQ(one.run(10, kInf).pass_samples, (std::vector<int>{1, 9}));  // at least one sample
}

TEST(SampleBudget, PassesFillTheBudgetWithoutGoingOver) {
  // Little fixed time (the path tracer's) and much (a reference with a costly set-up): the passes
  // end within the budget, and use most of it.
  for (const double fixed_s : {0.0, 0.5, 3.0}) {
    SCOPED_TRACE(testing::Message() << "fixed " << fixed_s << " s a pass");
    FakeSamplePasses machine{fixed_s, 0.37};
    const SampleBudgetRun run = machine.run(64, 8.0 + fixed_s);
    EXPECT_LE(machine.clock_s, 8.0 + fixed_s);
    EXPECT_GT(machine.clock_s, 0.6 * (8.0 + fixed_s));
    EXPECT_LT(run.samples, 64);
    int sum = 0;
    for (int n : run.pass_samples) sum += n;
    EXPECT_EQ(sum, run.samples);
    // What all 64 would have taken, from the passes measured: the machine's own figure.
    if (run.pass_samples.size() >= 2)
      EXPECT_NEAR(run.requested_predicted_s, fixed_s + 0.37 * 64, 1e-6);
  }
}

TEST(SampleBudget, TheNextPassIsTheMostThatFitsOrNone) {
  AffineCost cost;
  cost.record(10, 1000);                                   // 100 ms a sample ...
  cost.record(40, 4000);                                   // ... and nothing fixed
  EXPECT_EQ(next_pass_samples(100, 100, cost, kInf), 0);   // all done
  EXPECT_EQ(next_pass_samples(100, 40, cost, kInf), 60);   // no budget: the rest
  EXPECT_EQ(next_pass_samples(100, 40, cost, 10000), 60);  // 6 s fit in 90% of 10 s
  EXPECT_EQ(next_pass_samples(100, 40, cost, 2000), 18);   // 1.8 s: 18 samples
  EXPECT_EQ(next_pass_samples(100, 40, cost, 100), 0);     // not even one
}

}  // namespace
}  // namespace lucent::render
