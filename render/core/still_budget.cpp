// The CPU techniques within an image budget (technique.h: render_still_within_budget): the
// reference's or the path tracer's samples in passes sized by run_sample_budget (frame_budget.h).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "lucent/render/technique.h"

namespace lucent::render {

BudgetedStill render_still_within_budget(
    TechniqueId id, const Scene& scene, const TechniqueOptions& options, double budget_s,
    const std::function<void(const ImageRgb& image, int pass, int samples)>& on_image,
    const std::function<void(double share)>& progress, RenderStats* stats) {
  if (id != TechniqueId::kReference && id != TechniqueId::kPathtrace) {
    throw std::logic_error("render_still_within_budget: the reference or the path tracer only");
  }
  const bool pathtrace = id == TechniqueId::kPathtrace;
  const bool area = !pathtrace && options.reference.sampling == ReferenceSampling::kArea;
  const long long per_pass = pathtrace ? options.pathtrace.pixel_samples
                             : area    ? options.reference.surface_samples
                                       : options.reference.pixel_samples;
  const long long passes = pathtrace ? options.pathtrace.passes : options.reference.passes;
  if (pathtrace) {
    options.pathtrace.validate();
  } else {
    options.reference.validate();
  }
  BudgetedStill out;
  out.requested = int(std::min<long long>(per_pass * passes, std::numeric_limits<int>::max()));

  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  const auto now_s = [start] {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  std::vector<double> sum;
  long long done = 0;
  RenderStats merged;
  const auto run_pass = [&](int n, int pass) {
    // The share done: of the samples asked for, or of the budget's time when that is larger.
    const auto share = [&, n](double fraction) {
      if (!progress) return;
      double s = (double(done) + fraction * n) / out.requested;
      if (std::isfinite(budget_s)) s = std::max(s, now_s() / budget_s);
      progress(std::clamp(s, 0.0, 1.0));
    };
    // Each pass its own samples: a seed of its own (the renderers hash it with the pixel).
    const std::uint64_t seed_step = 0x9E3779B97F4A7C15ull * std::uint64_t(pass);
    ImageRgb image;
    RenderStats pass_stats;
    if (pathtrace) {
      PathTraceOptions o = options.pathtrace;
      o.pixel_samples = n;
      o.passes = 1;
      o.seed += seed_step;
      o.progress = share;
      PathTraceImage r = render_pathtrace(scene, o);
      image = std::move(r.image);
      pass_stats = std::move(r.stats);
    } else {
      ReferenceOptions o = options.reference;
      (area ? o.surface_samples : o.pixel_samples) = n;
      o.passes = 1;
      o.seed += seed_step;
      o.progress = share;
      ReferenceImage r = render_reference(scene, options.settings.model, o);
      image = std::move(r.image);
      pass_stats = std::move(r.stats);
    }
    if (sum.empty()) sum.assign(image.data.size(), 0.0);
    for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += double(n) * image.data[i];
    done += n;
    out.image = ImageRgb(image.width, image.height);
    for (std::size_t i = 0; i < sum.size(); ++i) out.image.data[i] = float(sum[i] / double(done));
    // The statistics: the passes' phases summed, the last pass's details.
    for (const auto& [name, ms] : pass_stats.pass_ms) {
      auto it = std::find_if(merged.pass_ms.begin(), merged.pass_ms.end(),
                             [&](const auto& p) { return p.first == name; });
      if (it == merged.pass_ms.end()) {
        merged.pass_ms.emplace_back(name, ms);
      } else {
        it->second += ms;
      }
    }
    merged.technique = pass_stats.technique;
    merged.width = pass_stats.width;
    merged.height = pass_stats.height;
    merged.details = pass_stats.details;
    if (on_image) on_image(out.image, pass, int(done));
  };
  out.run = run_sample_budget(out.requested, budget_s, now_s, run_pass);
  if (stats) {
    merged.total_ms = 1000 * now_s();
    merged.details["budget_pass_samples"] = out.run.pass_samples;
    *stats = std::move(merged);
  }
  return out;
}

}  // namespace lucent::render
