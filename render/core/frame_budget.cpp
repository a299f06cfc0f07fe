// The maps' quality ladder and the budget planners (frame_budget.h).
#include "lucent/render/frame_budget.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <utility>

namespace lucent::render {
namespace {

// The coarse levels as fractions of the requested knobs (the last level is the request itself).
// Level 0 is the first image: about 1/1000 of the default's work per frame and 2 frames (the
// first compiles the programs).
struct LevelScale {
  double directions, radiance_map_divisor, light_map_divisor, samples;
  int frames;
};
constexpr LevelScale kLevels[] = {
    {0.25, 8, 4, 1.0 / 6, 2},
    {0.5, 4, 2, 1.0 / 3, 16},
    {0.75, 2, 2, 0.5, 16},
    {1.0, 2, 1, 1.0, 32},
};

bool same_knobs(const RenderSettings& a, const RenderSettings& b) {
  return a.frames == b.frames && a.directions == b.directions && a.samples == b.samples &&
         a.radiance_map_size == b.radiance_map_size && a.light_map_size == b.light_map_size;
}

// Per-layer work of the radiance-map pass: texels times gathers.
double layer_gathers(const RenderSettings& s) {
  return double(s.radiance_map_size) * s.radiance_map_size * s.samples;
}

}  // namespace

std::vector<RenderSettings> maps_quality_ladder(const RenderSettings& requested,
                                                const FixedKnobs& fixed) {
  std::vector<RenderSettings> ladder;
  for (const LevelScale& l : kLevels) {
    RenderSettings s = requested;
    if (!fixed.directions)
      s.directions = std::clamp(int(std::lround(requested.directions * l.directions)), 1,
                                requested.directions);
    if (!fixed.radiance_map)
      s.radiance_map_size =
          std::clamp(int(requested.radiance_map_size / l.radiance_map_divisor),
                     std::min(32, requested.radiance_map_size), requested.radiance_map_size);
    if (!fixed.light_map)
      s.light_map_size =
          std::clamp(int(requested.light_map_size / l.light_map_divisor),
                     std::min(64, requested.light_map_size), requested.light_map_size);
    if (!fixed.samples)
      s.samples = std::clamp(int(std::ceil(requested.samples * l.samples)), 1, requested.samples);
    if (!fixed.frames) s.frames = std::min(l.frames, requested.frames);
    if (ladder.empty() || !same_knobs(ladder.back(), s)) ladder.push_back(s);
  }
  if (!same_knobs(ladder.back(), requested)) ladder.push_back(requested);
  return ladder;
}

// Fits ms = a + b x to (x, ms) pairs; with a single x (or a fit that comes out negative) a
// conservative guess from the point with the largest ratio.
void AffineCost::record(double x, double ms) {
  if (!(x > 0) || !(ms >= 0) || !std::isfinite(ms)) return;
  // One point per amount of work (the level it was measured at), its ms a running mean in which
  // recent frames weigh most (the machine's load changes while the viewer runs); the points of
  // levels left behind are kept, so that the fixed part stays known.
  for (auto& [xi, yi] : samples_) {
    if (std::abs(xi - x) <= 0.01 * x) {
      yi = 0.7 * yi + 0.3 * ms;
      return;
    }
  }
  samples_.push_back({x, ms});
  if (samples_.size() > kKept) samples_.erase(samples_.begin());
}

double AffineCost::predict(double x) const {
  if (samples_.empty()) return 0;
  double sx = 0, sy = 0, sxx = 0, sxy = 0, max_ratio = 0, x_lo = 1e300, x_hi = 0;
  for (const auto& [xi, yi] : samples_) {
    sx += xi;
    sy += yi;
    sxx += xi * xi;
    sxy += xi * yi;
    max_ratio = std::max(max_ratio, yi / xi);
    x_lo = std::min(x_lo, xi);
    x_hi = std::max(x_hi, xi);
  }
  const double n = double(samples_.size());
  const double var = sxx / n - (sx / n) * (sx / n);
  // Two distinct amounts of work, a factor 1.5 apart at least, separate the fixed part from the
  // part that grows with the work.
  if (x_hi > 1.5 * x_lo && var > 0) {
    const double b = (sxy / n - (sx / n) * (sy / n)) / var;
    const double a = sy / n - b * sx / n;
    if (b >= 0 && a >= 0) return a + b * x;
    if (b > 0) return std::max(0.0, a + b * x);  // a < 0 within noise: still the measured slope
  }
  // One amount of work (or a fit that came out negative): above the point with the largest ratio,
  // fixed_share_ of its time taken as fixed and the rest as growing with the work; below it, in
  // proportion.
  double at = 0, ms = 0;
  for (const auto& [xi, yi] : samples_)
    if (yi / xi >= max_ratio) {
      at = xi;
      ms = yi;
    }
  return x <= at ? ms * x / at : ms * (fixed_share_ + (1 - fixed_share_) * x / at);
}

void FrameCostModel::record(const MeasuredFrame& f) {
  const RenderSettings& s = f.settings;
  radiance_.record(layer_gathers(s), f.radiance_ms / std::max(1, s.directions));
  // Light maps drawn once a level (point and directional lights) are part of its set-up: only
  // frames that drew them count them.
  if (f.light_ms > 0)
    light_.record(double(s.light_map_size) * s.light_map_size, f.light_ms / std::max(1, f.lights));
  final_.record(double(std::max(1, f.pixels)) * s.directions, f.final_ms);
  ++frames_;
}

double FrameCostModel::frame_ms(const RenderSettings& s, int pixels, int lights) const {
  return s.directions * radiance_.predict(layer_gathers(s)) +
         std::max(1, lights) * light_.predict(double(s.light_map_size) * s.light_map_size) +
         final_.predict(double(std::max(1, pixels)) * s.directions);
}

ImagePlan plan_image(const std::vector<RenderSettings>& ladder, const FrameCostModel& cost,
                     int pixels, int lights, double setup_s, double left_s) {
  ImagePlan plan;
  for (int level = int(ladder.size()) - 1; level >= 1; --level) {
    const RenderSettings& s = ladder[std::size_t(level)];
    const double predicted = setup_s + s.frames * cost.frame_ms(s, pixels, lights) / 1000;
    if (predicted <= left_s || std::isinf(left_s)) {
      plan.level = level;
      plan.predicted_s = predicted;
      return plan;
    }
  }
  return plan;
}

ImageBudgetRun run_image_budget(const std::vector<RenderSettings>& ladder, double budget_s,
                                int pixels, int lights, const std::function<double()>& now_s,
                                BudgetLevelRunner& runner,
                                const std::function<void(double, double)>& progress) {
  if (ladder.empty()) throw std::logic_error("run_image_budget: no levels");
  const double t0 = now_s();
  const auto elapsed = [&] { return now_s() - t0; };
  const bool bounded = !std::isinf(budget_s);
  FrameCostModel cost;
  ImageBudgetRun run;
  double setup_s = 0;
  // The plan in predicted seconds from t0, for the progress: the coarse level's first guess is
  // a second per frame until a frame has been measured.
  double planned_end_s = 0;
  int level = 0, done = -1;
  int ceiling = int(ladder.size());  // levels from here up are known not to fit
  for (;;) {
    const RenderSettings& s = ladder[std::size_t(level)];
    const double level_start = now_s();
    runner.start(s);
    setup_s = std::max(setup_s, now_s() - level_start);
    if (level == 0) planned_end_s = setup_s + s.frames;
    int frames = 0;
    bool abandoned = false;
    MeasuredFrame m;
    while (runner.frame(m)) {
      // A level's first frame compiles its programs (drivers compile at the first draw;
      // llvmpipe's JIT takes ~0.5 s): it says nothing of the frames after it.
      if (++frames > 1) {
        m.settings = s;
        m.pixels = pixels;
        m.lights = lights;
        cost.record(m);
        const double rest_s = (s.frames - frames) * cost.frame_ms(s, pixels, lights) / 1000;
        planned_end_s = elapsed() + rest_s;
        // Measured, a refinement that will not fit is given up (the last level's image stands):
        // the prediction that chose it had seen smaller work only.
        if (level > 0 && bounded && frames == 2 && elapsed() + rest_s > budget_s) {
          abandoned = true;
          break;
        }
      }
      if (progress) {
        progress(std::clamp(elapsed() / std::max(planned_end_s, 1e-9), 0.0, 1.0),
                 std::max(0.0, planned_end_s - elapsed()));
      }
      m = MeasuredFrame{};
    }
    run.level_seconds.push_back(now_s() - level_start);
    run.levels_run.push_back(level);
    if (abandoned) {
      ceiling = level;
      run.levels_given_up.push_back(level);
    } else {
      done = level;
    }
    // The next level: the highest below the ceiling predicted to fit; when none is, the next one
    // is tried if its prediction is within three times what is left (the model over-predicts
    // before it has seen two amounts of work; a try that will not fit is given up after a frame).
    int next = -1;
    if (done + 1 < ceiling) {
      const std::vector<RenderSettings> above(ladder.begin() + done, ladder.begin() + ceiling);
      const double left = bounded ? budget_s - elapsed() : budget_s;
      const ImagePlan plan = plan_image(above, cost, pixels, lights, setup_s, left);
      if (plan.level > 0) {
        next = done + plan.level;
        planned_end_s = elapsed() + plan.predicted_s;
      } else {
        const RenderSettings& n = ladder[std::size_t(done + 1)];
        const double predicted = setup_s + n.frames * cost.frame_ms(n, pixels, lights) / 1000;
        if (predicted <= 3 * left && setup_s + 2 * cost.frame_ms(n, pixels, lights) / 1000 < left) {
          next = done + 1;
          planned_end_s = elapsed() + predicted;
        }
      }
    }
    if (!abandoned) runner.level_done(level, next >= 0);
    if (next < 0) break;
    level = next;
  }
  run.level = done;
  run.requested_frame_ms = cost.frame_ms(ladder.back(), pixels, lights);
  return run;
}

FrameSplit plan_split(double layer_ms, int layers, double other_ms, double budget_ms) {
  FrameSplit split;
  if (!(layer_ms > 0) || !(budget_ms > 0) || layers < 1) return split;
  const double room = std::max(budget_ms - other_ms, 0.5 * budget_ms);
  if (layer_ms * layers <= room) return split;  // the whole frame fits
  while (split.bands < 64 && layer_ms / split.bands > 0.5 * budget_ms) split.bands *= 2;
  const double unit_ms = layer_ms / split.bands;
  const int total = layers * split.bands;
  split.units_per_call = std::clamp(int(room / unit_ms), 1, total);
  if (split.units_per_call == total) split.units_per_call = 0;
  return split;
}

double predict_layer_ms(double layer_ms, const RenderSettings& from, const RenderSettings& to) {
  return layer_ms * layer_gathers(to) / std::max(1.0, layer_gathers(from));
}

std::string quality_text(const RenderSettings& s) {
  char text[128];
  std::snprintf(text, sizeof text, "K %d, W_s %d, W_l %d, N %d, T %d", s.directions,
                s.radiance_map_size, s.light_map_size, s.samples, s.frames);
  return text;
}

int next_pass_samples(int requested, int done, const AffineCost& cost, double left_ms) {
  const int left = requested - done;
  if (left <= 0) return 0;
  if (std::isinf(left_ms) || cost.empty()) return left;
  const double room = 0.9 * left_ms;
  if (cost.predict(left) <= room) return left;
  if (cost.predict(1) > room) return 0;
  int lo = 1, hi = left;  // predict(lo) fits, predict(hi) does not
  while (hi - lo > 1) {
    const int mid = lo + (hi - lo) / 2;
    (cost.predict(mid) <= room ? lo : hi) = mid;
  }
  return lo;
}

SampleBudgetRun run_sample_budget(int requested, double budget_s,
                                  const std::function<double()>& now_s,
                                  const std::function<void(int samples, int pass)>& run_pass) {
  if (requested < 1) throw std::logic_error("run_sample_budget: at least one sample");
  SampleBudgetRun run;
  // Until two passes are measured, in proportion: the CPU renderers' fixed part is small (the
  // path tracer's 1-sample pass took 0.39 s, its 34-sample pass 12.5 s), and in proportion
  // over-predicts where there is one, the safe side.
  AffineCost cost(0.0);
  const double start = now_s();
  for (int n = std::max(1, requested / 64); n > 0;) {
    const double t0 = now_s();
    run_pass(n, int(run.pass_samples.size()));
    const double t1 = now_s();
    cost.record(n, 1000 * (t1 - t0));
    run.pass_samples.push_back(n);
    run.pass_seconds.push_back(t1 - t0);
    run.samples += n;
    const double left_ms = std::isinf(budget_s) ? budget_s : 1000 * (budget_s - (t1 - start));
    n = next_pass_samples(requested, run.samples, cost, left_ms);
  }
  run.requested_predicted_s = cost.predict(requested) / 1000;
  return run;
}

}  // namespace lucent::render
