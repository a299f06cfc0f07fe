// `lucent tonemap`: a linear render (EXR) to what a person looks at (PNG), after the render: the
// exposure (a number, or auto: the rule `render` writes PNGs with) and the same tone curve and
// sRGB encoding (render/tone_map.h).
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "commands.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/imaging/image_io.h"
#include "lucent/render/tone_map.h"

namespace lucent::cli {
namespace {

struct TonemapArguments {
  std::string input, output, exposure = "auto";
};

void run_tonemap(const TonemapArguments& args) {
  check_output_file(args.output, ".png", "-o");
  std::string e = std::filesystem::path(args.input).extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (e != ".exr") throw Error(args.input + ": expected a linear render (.exr)");
  render::ToneMapOptions tone;
  const bool automatic = args.exposure == "auto";
  if (!automatic) {
    char* end = nullptr;
    tone.exposure = std::strtof(args.exposure.c_str(), &end);
    if (end == args.exposure.c_str() || *end != '\0' || !(tone.exposure > 0) ||
        !std::isfinite(tone.exposure))
      throw Error("--exposure: expected a positive number or auto, got '" + args.exposure + "'");
  }
  const imaging::ImageRgb image = imaging::read_exr(args.input);
  for (const float v : image.data)
    if (!std::isfinite(v)) throw Error(args.input + ": a pixel is not finite: expected radiance");
  if (automatic) tone.exposure = render::auto_exposure(image);
  render::write_render_image(args.output, image, tone);
  std::printf("tonemap: wrote %s (%dx%d, exposure %g%s)\n", args.output.c_str(), image.width,
              image.height, double(tone.exposure), automatic ? " (auto)" : "");
}

}  // namespace

void register_tonemap_command(CLI::App& app) {
  auto args = std::make_shared<TonemapArguments>();
  CLI::App* cmd = app.add_subcommand(
      "tonemap",
      "A linear render (EXR, e.g. from render -o x.exr) to a PNG as render writes them: exposure, "
      "Reinhard x/(1+x) per channel, sRGB");
  cmd->add_option("input", args->input, "the linear render (.exr)")->required();
  cmd->add_option("-o,--output", args->output, "the PNG to write (atomically)")->required();
  cmd->add_option("--exposure", args->exposure,
                  "linear scale before the tone curve, or auto (the object's 95th-percentile "
                  "luminance at 2)")
      ->capture_default_str();
  cmd->callback([args] { run_tonemap(*args); });
}

}  // namespace lucent::cli
