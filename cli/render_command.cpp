// `lucent render`: a material on a mesh under lights or an environment map, rendered headless with
// the real-time radiance-map technique or the CPU reference, written as PNG (tone-mapped) or EXR
// (linear). Fills lucent::render's Scene, RenderSettings and ReferenceOptions; validates everything
// before rendering so that bad input fails fast and leaves no output file.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "commands.h"
#include "lucent/materials/atomic_file.h"
#include "lucent/materials/error.h"
#include "lucent/render/radiance_maps.h"
#include "lucent/render/reference_renderer.h"
#include "lucent/render/render_settings.h"
#include "lucent/render/scene.h"
#include "lucent/render/tone_map.h"
#include "scene_options.h"

namespace lucent::cli {
namespace {

struct RenderArguments {
  SceneArguments scene;
  std::string output;
  std::string stats;
};

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
  Scene scene = build_scene(args).scene;

  const bool show_progress = ::isatty(STDERR_FILENO) != 0;
  ImageRgb image;
  RenderStats stats;
  if (args.technique == "reference") {
    if (show_progress) args.reference.progress = print_progress;
    ReferenceImage result = render_reference(scene, args.settings.model, args.reference);
    if (show_progress) std::fprintf(stderr, "\n");
    image = std::move(result.image);
    stats = std::move(result.stats);
  } else {
    image = render_radiance_maps(scene, args.settings, &stats);
  }

  ToneMapOptions tone;
  tone.exposure = args.settings.exposure;
  write_render_image(render_args.output, image, tone,
                     {{"lucent:units", "radiance, W mm^-2 sr^-1 per unit light"},
                      {"lucent:material", scene.material.name},
                      {"lucent:mesh", scene.mesh.name},
                      {"lucent:technique", args.technique}});
  if (!render_args.stats.empty()) {
    nlohmann::json doc = stats.to_json();
    doc["scene"] = {{"material", scene.material.name},
                    {"model", materials::to_string(args.settings.model)},
                    {"mesh", scene.mesh.name},
                    {"triangles", scene.mesh.triangles.size()},
                    {"object_size_mm", args.object_size_mm},
                    {"lights", scene.lights.size()},
                    {"environment", args.env},
                    {"view", args.view}};
    if (args.technique == "maps") doc["settings"] = args.settings.to_string();
    write_file_atomically(render_args.stats, doc.dump(2) + "\n");
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
  cmd->add_option("--stats", args->stats,
                  "write timings (per pass or phase, ms) and counts as JSON (lucent-render-stats)");
  cmd->callback([args] { run_render(*args); });
}

}  // namespace lucent::cli
