// `lucent render`: a material on a mesh under lights or an environment map, rendered headless by
// any technique of the registry (technique.h), written as PNG (tone-mapped) or EXR (linear). Fills
// lucent::render's Scene and TechniqueOptions; validates everything before rendering so that bad
// input fails fast and leaves no output file.
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/core/json_file.h"
#include "lucent/render/frame_budget.h"
#include "lucent/render/fur_renderer.h"
#include "lucent/render/render_settings.h"
#include "lucent/render/scene.h"
#include "lucent/render/technique.h"
#include "lucent/render/tone_map.h"
#include "progress.h"
#include "scene_options.h"
#include "shader_cache.h"
#include "technique_flags.h"

namespace lucent::cli {
namespace {

struct RenderArguments {
  SceneArguments scene;
  std::vector<std::string> outputs;  ///< -o, a PNG, an EXR or one of each
  std::string output;                ///< the first of them (snapshots, messages)
  std::string budget = "60";         ///< --budget: seconds per image, or none
  render::FixedKnobs fixed;          ///< the maps' knobs given on the command line
  bool reference_samples_given = false, pathtrace_samples_given = false;  ///< (their passes too)
  std::string stats;
  std::vector<int> snapshots;
  bool json = false;
};

// OUT.exr -> OUT.f<t>.exr (the snapshot of frame t, always linear EXR).
std::string snapshot_path(const std::string& output, int frame) {
  const std::size_t dot = output.rfind('.');
  return output.substr(0, dot) + ".f" + std::to_string(frame) + ".exr";
}

// --budget: seconds per image (> 0), or none (infinity: the requested quality whatever it costs).
double parse_budget(const std::string& text) {
  if (text == "none") return std::numeric_limits<double>::infinity();
  char* end = nullptr;
  const double s = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !(s > 0) || !std::isfinite(s)) {
    throw Error("--budget: expected seconds per image (> 0) or none, got '" + text + "'");
  }
  return s;
}

std::string lower_extension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
  return extension;
}

// The outputs (-o, one PNG and one EXR at most), checked before any work: the right extensions,
// writable folders, not the same kind twice.
void check_outputs(RenderArguments& render_args) {
  if (render_args.outputs.empty()) throw Error("-o: give the output image (.png or .exr)");
  bool png = false, exr = false;
  for (const std::string& output : render_args.outputs) {
    if (!render::is_render_image_path(output)) {
      throw Error("-o: '" + output + "': output must be .png (tone-mapped) or .exr (linear)");
    }
    bool& seen = lower_extension(output) == ".png" ? png : exr;
    if (seen) throw Error("-o: '" + output + "': at most one .png and one .exr");
    seen = true;
    check_output_file(output, "", "-o");
  }
  render_args.output = render_args.outputs.front();
}

struct Written {
  float exposure = 1;
};

// Every output from one linear image: PNG with the exposure (auto: the image's own), EXR linear.
// Each path written goes into `written` (removed again if a later one fails).
Written write_outputs(const RenderArguments& render_args, const render::ImageRgb& image,
                      const render::Scene& scene, const std::string& technique,
                      std::vector<std::string>& written) {
  render::ToneMapOptions tone;
  tone.exposure = render_args.scene.auto_exposure ? render::auto_exposure(image)
                                                  : render_args.scene.options.settings.exposure;
  for (const std::string& path : render_args.outputs) {
    render::write_render_image(path, image, tone,
                               {{"lucent:units", "radiance, W mm^-2 sr^-1 per unit light"},
                                {"lucent:material", scene.material.name},
                                {"lucent:mesh", scene.mesh.name},
                                {"lucent:technique", technique}});
    if (std::find(written.begin(), written.end(), path) == written.end()) written.push_back(path);
  }
  return {tone.exposure};
}

// The stats' "budget" of a maps run: the levels run, the quality reached, the requested one's cost.
nlohmann::json maps_budget_doc(const render::BudgetedMapsOptions& budget,
                               const render::BudgetedMaps& result) {
  using render::quality_text;
  const render::RenderSettings& used = budget.ladder[std::size_t(result.level)];
  const render::RenderSettings& requested = budget.ladder.back();
  return {{"budget_s",
           std::isinf(budget.budget_s) ? nlohmann::json("none") : nlohmann::json(budget.budget_s)},
          {"levels", budget.ladder.size()},
          {"level", result.level},
          {"levels_run", result.levels_run},
          {"levels_given_up", result.levels_given_up},
          {"level_seconds", result.level_seconds},
          {"quality", quality_text(used)},
          {"requested", quality_text(requested)},
          {"requested_reached", result.level + 1 == int(budget.ladder.size())},
          {"requested_predicted_s", requested.frames * result.requested_frame_ms / 1000}};
}

// The maps within --budget: the coarse image first, written at once, then the refined levels.
render::ImageRgb render_maps_budgeted(RenderArguments& render_args, const render::Scene& scene,
                                      const render::TechniqueOptions& options,
                                      ProgressLine& progress, render::RenderStats& stats,
                                      nlohmann::json& budget_doc,
                                      std::vector<std::string>& written) {
  using namespace lucent::render;
  BudgetedMapsOptions budget;
  budget.ladder = maps_quality_ladder(options.settings, render_args.fixed);
  budget.budget_s = parse_budget(render_args.budget);
  const auto start = std::chrono::steady_clock::now();
  budget.on_image = [&](const ImageRgb& image, int level) {
    write_outputs(render_args, image, scene, "radiance maps", written);
    commit_pending_outputs();  // in place now, not when the run ends
    progress.finish();
    const double t =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "render: %s image in %s after %.1f s (%s)\n",
                 level == 0 ? "a first coarse" : "a refined", render_args.output.c_str(), t,
                 quality_text(budget.ladder[std::size_t(level)]).c_str());
    std::fflush(stderr);
  };
  budget.progress = [&](double fraction, double) {
    progress.update(std::uint64_t(std::lround(1000 * fraction)), 1000);
  };
  const BudgetedMaps result =
      render_radiance_maps_within_budget(scene, options.maps, budget, &stats);
  budget_doc = maps_budget_doc(budget, result);
  return result.image;
}

// Fur over a mesh within --budget: its skin is the maps', refined within what is left of the
// budget (the shells' own pass is one draw); no coarse image (it would have no coat).
render::ImageRgb render_fur_budgeted(RenderArguments& render_args, const render::Scene& scene,
                                     const render::TechniqueOptions& options,
                                     ProgressLine& progress, render::RenderStats& stats,
                                     nlohmann::json& budget_doc) {
  using namespace lucent::render;
  const double budget_s = parse_budget(render_args.budget);
  const auto start = std::chrono::steady_clock::now();
  BudgetedMapsOptions budget;
  budget.ladder = maps_quality_ladder(options.settings, render_args.fixed);
  budget.progress = [&](double fraction, double) {
    progress.update(std::uint64_t(std::lround(1000 * fraction)), 1000);
  };
  const SkinRenderer skin = [&](const Scene& skin_scene) {
    const double spent =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    budget.budget_s = std::max(0.1 * budget_s, budget_s - spent);
    const BudgetedMaps result =
        render_radiance_maps_within_budget(skin_scene, options.maps, budget, nullptr);
    budget_doc = maps_budget_doc(budget, result);
    budget_doc["of"] = "the skin under the fur (the radiance maps)";
    return result.image;
  };
  return render_fur(scene, options.fur, &stats, options.settings, skin);
}

// The reference or the path tracer within --budget: a coarse pass first, written at once, then
// passes as many samples as fit (render_still_within_budget).
render::ImageRgb render_cpu_budgeted(RenderArguments& render_args, render::TechniqueId id,
                                     const render::Scene& scene,
                                     const render::TechniqueOptions& options,
                                     ProgressLine& progress, render::RenderStats& stats,
                                     nlohmann::json& budget_doc,
                                     std::vector<std::string>& written) {
  using namespace lucent::render;
  const double budget_s = parse_budget(render_args.budget);
  const TechniqueInfo& technique = technique_info(id);
  const bool area =
      id == TechniqueId::kReference && options.reference.sampling == ReferenceSampling::kArea;
  const std::string unit = area ? "surface samples" : "samples per pixel";
  const auto start = std::chrono::steady_clock::now();
  const auto on_image = [&](const ImageRgb& image, int pass, int samples) {
    write_outputs(render_args, image, scene, technique.name, written);
    commit_pending_outputs();  // in place now, not when the run ends
    if (pass > 0) return;      // the last is reported with the run's summary
    progress.finish();
    const double t =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "render: a first coarse image in %s after %.1f s (%s)\n",
                 render_args.output.c_str(), t, (std::to_string(samples) + " " + unit).c_str());
    std::fflush(stderr);
  };
  const auto report = [&](double share) {
    progress.update(std::uint64_t(std::lround(1000 * share)), 1000);
  };
  TechniqueOptions o = options;
  o.reference.progress = o.pathtrace.progress = {};
  const BudgetedStill result =
      render_still_within_budget(id, scene, o, budget_s, on_image, report, &stats);
  budget_doc = {{"budget_s", budget_s},
                {"pass_samples", result.run.pass_samples},
                {"pass_seconds", result.run.pass_seconds},
                {"quality", std::to_string(result.run.samples) + " " + unit},
                {"requested", std::to_string(result.requested) + " " + unit},
                {"requested_reached", result.run.samples >= result.requested},
                {"requested_predicted_s", result.run.requested_predicted_s}};
  return result.image;
}

void run_render(RenderArguments& render_args) {
  using namespace lucent::render;
  SceneArguments& args = render_args.scene;
  check_outputs(render_args);
  // Where the outputs go is checked before any work (they are written together at the end).
  if (!render_args.stats.empty()) check_output_file(render_args.stats, ".json", "--stats");
  parse_budget(render_args.budget);
  Scene scene = build_scene(args).scene;
  use_shader_cache();
  const auto start = std::chrono::steady_clock::now();

  const TechniqueInfo& technique = technique_info(args.technique_id);
  if (!technique.frame_snapshots && !render_args.snapshots.empty()) {
    throw Error("--snapshots: frame snapshots are of the radiance maps (--technique maps)");
  }
  TechniqueOptions options = args.options;
  for (int t : render_args.snapshots) {
    if (t < 1 || t > options.settings.frames) {
      throw Error("--snapshots: frames must be 1.." + std::to_string(options.settings.frames) +
                  " (--maps-frames), got " + std::to_string(t));
    }
  }
  options.maps.snapshot_frames = render_args.snapshots;
  options.maps.on_snapshot = [&](int t, const ImageRgb& snapshot) {
    write_render_image(snapshot_path(render_args.output, t), snapshot, ToneMapOptions{});
  };
  // Progress of every technique: the share done (the frame-by-frame ones by frames, the CPU ones
  // by their passes), on a terminal one redrawn line, elsewhere a line per tenth.
  ProgressLine progress("render", "", false);
  const auto report = [&progress](double fraction) {
    progress.update(std::uint64_t(std::lround(1000 * fraction)), 1000);
  };
  options.reference.progress = report;
  options.pathtrace.progress = report;
  RenderStats stats;
  nlohmann::json budget_doc;
  const bool budgeted = args.technique_id == TechniqueId::kMaps && render_args.snapshots.empty();
  const bool finite_budget = std::isfinite(parse_budget(render_args.budget));
  // The CPU techniques within a finite budget unless their samples (or passes) were given.
  const bool cpu_budgeted =
      finite_budget &&
      ((args.technique_id == TechniqueId::kReference && !render_args.reference_samples_given) ||
       (args.technique_id == TechniqueId::kPathtrace && !render_args.pathtrace_samples_given));
  const bool fur_budgeted =
      args.technique_id == TechniqueId::kFur && scene.mesh.name != "tile" && finite_budget;
  std::vector<std::string>
      written;  // the coarse and refined images: removed if a later stage fails
  ImageRgb image;
  // The frame-by-frame techniques other than the maps: the time so far (their set-up, the
  // hierarchical links above all, has no share to report), on a terminal a ticker, elsewhere a
  // line after a second and every ten.
  std::unique_ptr<StageProgress> stages;
  if (!budgeted && !fur_budgeted && technique.gpu) {
    stages = std::make_unique<StageProgress>("render", false, true);
    stages->stage("rendering (" + technique.label + ")", 0);
  }
  Written out;
  try {
    image = budgeted       ? render_maps_budgeted(render_args, scene, options, progress, stats,
                                                  budget_doc, written)
            : cpu_budgeted ? render_cpu_budgeted(render_args, args.technique_id, scene, options,
                                                 progress, stats, budget_doc, written)
            : fur_budgeted
                ? render_fur_budgeted(render_args, scene, options, progress, stats, budget_doc)
                : render_still(args.technique_id, scene, options, &stats);
    progress.finish();
    stages.reset();
    out = write_outputs(render_args, image, scene, technique.name, written);
  } catch (...) {
    progress.finish();
    stages.reset();
    std::error_code ignored;
    for (const std::string& path : written) std::filesystem::remove(path, ignored);
    throw;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  bool png = false;
  for (const std::string& path : render_args.outputs) png = png || lower_extension(path) == ".png";
  nlohmann::json doc = stats.to_json();
  doc["scene"] = {{"material", scene.material.name},
                  {"model", materials::to_string(options.settings.model)},
                  {"mesh", scene.mesh.name},
                  {"triangles", scene.mesh.triangles.size()},
                  {"object_size_mm", args.object_size_mm},
                  {"lights", scene.lights.size()},
                  {"environment", args.env},
                  {"view", args.view}};
  if (!budget_doc.is_null()) doc["budget"] = budget_doc;
  if (const std::string settings = settings_text(args.technique_id, options); !settings.empty())
    doc["settings"] = settings;
  if (!render_args.stats.empty()) {
    check_finite_json(doc, render_args.stats);
    write_file_atomically(render_args.stats, doc.dump(2) + "\n");
  }
  std::string outputs;
  for (const std::string& path : render_args.outputs)
    outputs += (outputs.empty() ? "" : " and ") + path;
  if (render_args.json) {
    // The summary line as JSON, with the statistics (the same document as --stats).
    doc["output"] = render_args.output;
    doc["outputs"] = render_args.outputs;
    doc["seconds"] = seconds;
    doc["exposure"] = png ? nlohmann::json(out.exposure) : nlohmann::json(nullptr);
    doc["auto_exposure"] = png && args.auto_exposure;
    if (!render_args.stats.empty()) doc["stats_file"] = render_args.stats;
    check_finite_json(doc, "render --json");
    std::printf("%s\n", doc.dump(2).c_str());
  } else {
    std::printf(
        "render: wrote %s (%dx%d, %s, %s on %s, %s%s) in %.1f s\n", outputs.c_str(),
        scene.camera.width, scene.camera.height, technique.label.c_str(),
        materials::to_string(options.settings.model).c_str(), scene.mesh.name.c_str(),
        png ? "exposure " : "linear",
        png ? (std::to_string(out.exposure) + (args.auto_exposure ? " (auto)" : "")).c_str() : "",
        seconds);
    if (!budget_doc.is_null() && !budget_doc["requested_reached"].get<bool>()) {
      std::printf(
          "render: quality %s within --budget %s s; the requested %s would take about %s "
          "(--budget none, or give the knobs)\n",
          budget_doc["quality"].get<std::string>().c_str(), render_args.budget.c_str(),
          budget_doc["requested"].get<std::string>().c_str(),
          duration_text(budget_doc["requested_predicted_s"].get<double>()).c_str());
    }
  }
  if (!args.default_rig.empty()) {
    std::string rig;
    for (const auto& light : args.default_rig) rig += " --light " + light;
    warn("render: no --light or --env: the default rig (key, fill, rim):" + rig);
  }
}

}  // namespace

void register_render_command(CLI::App& app) {
  auto args = std::make_shared<RenderArguments>();
  CLI::App* cmd = app.add_subcommand(
      "render",
      "Render a material on a mesh (headless). Output: PNG tone-mapped (exposure, Reinhard "
      "x/(1+x) per channel, sRGB) or EXR linear radiance (W mm^-2 sr^-1 per unit light). The mesh "
      "is centred and scaled so that its bounding-box diagonal is --object-size-mm.");
  args->scene.size = "256x256";
  add_scene_options(cmd, args->scene, "image size WxH in pixels (N: N x N)");
  cmd->add_option("-o,--output", args->outputs,
                  "output image: .png (tone-mapped sRGB) or .exr (linear), or one of each "
                  "(-o a.png -o a.exr); written atomically")
      ->required();
  cmd->add_option(
         "--budget", args->budget,
         "seconds per image (or none). A coarse first image is written at once, then the "
         "maps refine to the highest quality whose time, predicted from the frames measured, "
         "fits (the requested K, W_s, W_l, N, T when they fit; knobs given explicitly are "
         "kept at every level), the reference and the path tracer add passes of as many of "
         "their samples as fit (all of them unless given: their samples or passes given, "
         "they run whole); fur over a mesh renders its skin (the maps) within what is left; sh "
         "and hierarchical run whole")
      ->capture_default_str();
  cmd->add_option("--snapshots", args->snapshots,
                  "maps: also write the linear image after these frames as OUT.f<t>.exr "
                  "(e.g. --snapshots 1,4,16)")
      ->delimiter(',');
  cmd->add_option("--stats", args->stats,
                  "write timings (per pass or phase, ms) and counts as JSON (lucent-render-stats)");
  cmd->add_flag("--json", args->json,
                 "print what was written as JSON on stdout (output, size, technique, model, mesh, "
                 "exposure, time and the --stats document) instead of the summary line");
  cmd->callback([cmd, args] {
    args->fixed = given_maps_knobs(cmd);  // explicit knobs win over the budget
    args->reference_samples_given = given_reference_samples(cmd);
    args->pathtrace_samples_given = given_pathtrace_samples(cmd);
    run_render(*args);
  });
}

}  // namespace lucent::cli
