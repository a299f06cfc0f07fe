// `lucent render`: a material on a mesh under lights or an environment map, rendered headless by
// any technique of the registry (technique.h), written as PNG (tone-mapped) or EXR (linear). Fills
// lucent::render's Scene and TechniqueOptions; validates everything before rendering so that bad
// input fails fast and leaves no output file.
#include <unistd.h>

#include <chrono>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/core/json_file.h"
#include "lucent/render/render_settings.h"
#include "lucent/render/scene.h"
#include "lucent/render/technique.h"
#include "lucent/render/tone_map.h"
#include "scene_options.h"

namespace lucent::cli {
namespace {

struct RenderArguments {
  SceneArguments scene;
  std::string output;
  std::string stats;
  std::vector<int> snapshots;
  bool json = false;
};

// OUT.exr -> OUT.f<t>.exr (the snapshot of frame t, always linear EXR).
std::string snapshot_path(const std::string& output, int frame) {
  const std::size_t dot = output.rfind('.');
  return output.substr(0, dot) + ".f" + std::to_string(frame) + ".exr";
}

void print_progress(double fraction) {
  std::fprintf(stderr, "\rrender: %3d%%", int(std::lround(100 * fraction)));
  std::fflush(stderr);
}

void run_render(RenderArguments& render_args) {
  using namespace lucent::render;
  SceneArguments& args = render_args.scene;
  if (render_args.output.empty()) throw Error("-o: give the output image (.png or .exr)");
  if (!is_render_image_path(render_args.output)) {
    throw Error("-o: '" + render_args.output +
                "': output must be .png (tone-mapped) or .exr (linear)");
  }
  // Where the outputs go is checked before any work (they are written together at the end).
  check_output_file(render_args.output, "", "-o");
  if (!render_args.stats.empty()) check_output_file(render_args.stats, ".json", "--stats");
  Scene scene = build_scene(args).scene;
  const auto start = std::chrono::steady_clock::now();

  const bool show_progress = ::isatty(STDERR_FILENO) != 0;
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
  bool progress_shown = false;  // the techniques that report progress end their line here
  if (show_progress) {
    options.reference.progress = [&progress_shown](double fraction) {
      progress_shown = true;
      print_progress(fraction);
    };
    options.pathtrace.progress = options.reference.progress;
  }
  RenderStats stats;
  const ImageRgb image = render_still(args.technique_id, scene, options, &stats);
  if (progress_shown) std::fprintf(stderr, "\n");

  ToneMapOptions tone;
  tone.exposure = args.auto_exposure ? auto_exposure(image) : options.settings.exposure;
  write_render_image(render_args.output, image, tone,
                     {{"lucent:units", "radiance, W mm^-2 sr^-1 per unit light"},
                      {"lucent:material", scene.material.name},
                      {"lucent:mesh", scene.mesh.name},
                      {"lucent:technique", technique.name}});
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::string extension = std::filesystem::path(render_args.output).extension().string();
  for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
  const bool png = extension == ".png";  // EXR is written linear, without the exposure
  nlohmann::json doc = stats.to_json();
  doc["scene"] = {{"material", scene.material.name},
                  {"model", materials::to_string(options.settings.model)},
                  {"mesh", scene.mesh.name},
                  {"triangles", scene.mesh.triangles.size()},
                  {"object_size_mm", args.object_size_mm},
                  {"lights", scene.lights.size()},
                  {"environment", args.env},
                  {"view", args.view}};
  if (const std::string settings = settings_text(args.technique_id, options); !settings.empty())
    doc["settings"] = settings;
  if (!render_args.stats.empty()) {
    check_finite_json(doc, render_args.stats);
    write_file_atomically(render_args.stats, doc.dump(2) + "\n");
  }
  if (render_args.json) {
    // The summary line as JSON, with the statistics (the same document as --stats).
    doc["output"] = render_args.output;
    doc["seconds"] = seconds;
    doc["exposure"] = png ? nlohmann::json(tone.exposure) : nlohmann::json(nullptr);
    doc["auto_exposure"] = png && args.auto_exposure;
    if (!render_args.stats.empty()) doc["stats_file"] = render_args.stats;
    check_finite_json(doc, "render --json");
    std::printf("%s\n", doc.dump(2).c_str());
  } else {
    std::printf(
        "render: wrote %s (%dx%d, %s, %s on %s, %s%s) in %.1f s\n", render_args.output.c_str(),
        scene.camera.width, scene.camera.height, technique.label.c_str(),
        materials::to_string(options.settings.model).c_str(), scene.mesh.name.c_str(),
        png ? "exposure " : "linear",
        png ? (std::to_string(tone.exposure) + (args.auto_exposure ? " (auto)" : "")).c_str() : "",
        seconds);
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
  add_scene_options(cmd, args->scene, "image size WxH in pixels");
  cmd->add_option("-o,--output", args->output,
                  "output image: .png (tone-mapped sRGB) or .exr (linear); written atomically")
      ->required();
  cmd->add_option("--snapshots", args->snapshots,
                  "maps: also write the linear image after these frames as OUT.f<t>.exr "
                  "(e.g. --snapshots 1,4,16)")
      ->delimiter(',');
  cmd->add_option("--stats", args->stats,
                  "write timings (per pass or phase, ms) and counts as JSON (lucent-render-stats)");
  cmd->add_flag("--json", args->json,
                 "print what was written as JSON on stdout (output, size, technique, model, mesh, "
                 "exposure, time and the --stats document) instead of the summary line");
  cmd->callback([args] { run_render(*args); });
}

}  // namespace lucent::cli
