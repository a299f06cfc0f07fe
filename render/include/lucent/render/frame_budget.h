// Quality that fits a time budget: the radiance maps' knobs (K, W_s, W_l, N, T) chosen from what
// frames measurably cost on the machine that runs them. `lucent render` takes a budget per image:
// a first coarse image early, then the highest quality level whose predicted time fits what is
// left of the budget (the requested settings exactly when they fit, so that the refined image is
// the one the explicit settings give). `lucent view` takes a budget per frame: it climbs the same
// levels one after another as each converges, every frame split across display refreshes so that
// none takes longer than the budget.
//
// No clock and no OpenGL here: the callers measure (wall clock, glFinish) and say what a frame at
// a level took, so that tests drive the planner with a fake clock.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "lucent/render/render_settings.h"

namespace lucent::render {

/// The maps' knobs the user gave: kept at every level (explicit knobs win over the budget).
struct FixedKnobs {
  bool frames = false, directions = false, samples = false, radiance_map = false, light_map = false;
  bool all() const { return frames && directions && samples && radiance_map && light_map; }
};

/// The maps' quality levels for `requested`, coarsest first; the last is `requested` itself. Each
/// level scales the knobs not in `fixed` down from the requested values (K to 1/4, W_s to 1/8,
/// W_l to 1/4, N to 1/6 and T to 2 frames at level 0); levels that come out equal are merged.
/// One level when every knob is fixed.
std::vector<RenderSettings> maps_quality_ladder(const RenderSettings& requested,
                                                const FixedKnobs& fixed);

/// What a frame at some level cost, by pass (ms, wall clock after glFinish).
struct MeasuredFrame {
  RenderSettings settings;
  int pixels = 0;          ///< the image's width x height
  int lights = 1;          ///< light maps rendered (one per light)
  double radiance_ms = 0;  ///< the radiance-map pass (K layers, W_s^2 texels, N gathers each)
  double light_ms = 0;     ///< the light maps (L maps of W_l^2)
  double final_ms = 0;     ///< the final pass and the rest of the frame (K lookups per pixel)
};

/// ms = a + b x fitted to measured (x, ms) pairs (one point per amount of work, 16 at most, each a
/// running mean): least squares once two amounts of work 1.5x apart have been measured; before
/// that, and where the fit comes out negative, from the point with the largest ratio: above it
/// with `fixed_share` of its time taken as fixed (which over-predicts a larger x where the fixed
/// part is larger, the safe side of a budget; on llvmpipe the maps' coarse level's is 50-80%, the
/// default 0.5), below it in proportion.
class AffineCost {
 public:
  explicit AffineCost(double fixed_share = 0.5) : fixed_share_(fixed_share) {}
  void record(double x, double ms);
  double predict(double x) const;
  bool empty() const { return samples_.empty(); }

 private:
  static constexpr std::size_t kKept = 16;
  double fixed_share_;
  std::vector<std::pair<double, double>> samples_;
};

/// What a frame costs from what measured frames cost: the radiance map per layer against its
/// texels times gathers (W_s^2 N), the light maps per light against W_l^2, the final pass (and the
/// rest of the frame) against pixels times layers.
class FrameCostModel {
 public:
  void record(const MeasuredFrame& frame);
  bool measured() const { return frames_ > 0; }
  /// Predicted ms of one accumulated frame of `s` at `pixels` with `lights` light maps.
  double frame_ms(const RenderSettings& s, int pixels, int lights) const;

 private:
  AffineCost radiance_, light_, final_;
  int frames_ = 0;
};

/// The image budget's plan for `lucent render`: which level to refine to after the coarse one.
struct ImagePlan {
  int level = 0;           ///< index into the ladder (its last is the requested settings)
  double predicted_s = 0;  ///< the refinement's predicted time (setup and every frame)
};

/// The highest level whose setup (`setup_s`, measured on the coarse level) and T frames fit in
/// `left_s`; level 0 (nothing to refine) when none above it does. `left_s` may be infinite (no
/// budget): then the last level.
ImagePlan plan_image(const std::vector<RenderSettings>& ladder, const FrameCostModel& cost,
                     int pixels, int lights, double setup_s, double left_s);

/// What the image budget drives: one level's set-up and its frames (render_radiance_maps_within_
/// budget runs the radiance maps; tests run a fake machine on a fake clock).
class BudgetLevelRunner {
 public:
  virtual ~BudgetLevelRunner() = default;
  /// Sets a level up (a renderer of `settings`); a level started and not done is given up.
  virtual void start(const RenderSettings& settings) = 0;
  /// One frame; false when the level had converged (no frame accumulated). Fills what it cost.
  virtual bool frame(MeasuredFrame& measured) = 0;
  /// The level's frames are done: its image is the result unless a higher level is done later;
  /// `refined_next`: a higher level is tried next (this image is a preview until then).
  virtual void level_done(int level, bool refined_next) = 0;
};

struct ImageBudgetRun {
  int level = 0;                      ///< the last level done (the image's)
  std::vector<int> levels_run;        ///< in order, those given up included
  std::vector<int> levels_given_up;   ///< the levels whose first measured frame said no
  std::vector<double> level_seconds;  ///< each one's set-up and frames, s
  double requested_frame_ms = 0;      ///< the cost model's prediction of a requested frame
};

/// The image budget: level 0, then while a higher level is predicted to fit what is left of
/// `budget_s` (infinity: up to the last), the highest such; when none is predicted to, the next
/// one is tried if predicted within three times what is left, and any level whose first measured
/// frame says its frames will not fit is given up (the model learns from it). A level's first
/// frame compiles its programs and is not measured. `now_s`: the clock (s); `progress(share,
/// seconds left)` after every frame.
ImageBudgetRun run_image_budget(const std::vector<RenderSettings>& ladder, double budget_s,
                                int pixels, int lights, const std::function<double()>& now_s,
                                BudgetLevelRunner& runner,
                                const std::function<void(double, double)>& progress = {});

/// How `lucent view` splits a maps frame across display refreshes (RadianceMapRenderer::set_split)
/// so that each refresh's work stays within `budget_ms`: each layer in bands (a power of two, at
/// most 64) of at most half the budget, and as many layer-bands a call as fit after `other_ms`
/// (the light map and the final pass of a call that ends a frame). The whole frame in one call
/// (units 0) when it fits. `layer_ms`: one layer's radiance-map pass, measured or predicted.
struct FrameSplit {
  int bands = 1;
  int units_per_call = 0;  ///< 0: the whole frame
};
FrameSplit plan_split(double layer_ms, int layers, double other_ms, double budget_ms);

/// A layer's radiance-map time at `to` predicted from one measured at `from`: in proportion to the
/// texels times gathers (W_s^2 N), which over-predicts a larger level (its fixed part is smaller).
double predict_layer_ms(double layer_ms, const RenderSettings& from, const RenderSettings& to);

/// "K 16, W_s 512, W_l 512, N 50, T 100": a level in the flags' letters, for summaries.
std::string quality_text(const RenderSettings& s);

// The CPU techniques' budget (`lucent render --technique reference|pathtrace`): their samples in
// passes whose images are averaged weighted by their samples, so that any split of the requested
// samples gives the same expected image with the same noise as one pass of them all.

/// The samples of the next pass: none when `done` >= `requested`; all that are left where
/// `left_ms` is infinite or `cost` (ms against samples, fitted to the passes so far) predicts them
/// to fit in 90% of it; else the most that are predicted to (none when not even one is).
int next_pass_samples(int requested, int done, const AffineCost& cost, double left_ms);

struct SampleBudgetRun {
  std::vector<int> pass_samples;     ///< in order; their sum is the samples done
  std::vector<double> pass_seconds;  ///< each pass's wall clock
  int samples = 0;                   ///< done, of the requested
  double requested_predicted_s = 0;  ///< what all the requested would have taken, predicted
};

/// A first coarse pass of requested / 64 samples (at least 1: an image early), then passes of
/// next_pass_samples() until none is left or fits `budget_s` (infinity: all). `run_pass(samples,
/// pass)` renders one; `now_s` is the clock (s), a fake one in tests.
SampleBudgetRun run_sample_budget(int requested, double budget_s,
                                  const std::function<double()>& now_s,
                                  const std::function<void(int samples, int pass)>& run_pass);

}  // namespace lucent::render
