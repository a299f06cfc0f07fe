// `lucent acquire`: a capture file -> calibrated HDR, radial (and 2D) profiles, and a picture.
#include <iostream>
#include <memory>

#include "commands.h"
#include "lucent/acquire/acquire.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "progress.h"
#include "validators.h"

namespace lucent::cli {
namespace {

struct AcquireArguments {
  std::string capture;
  std::string output;
  acquire::AcquireOptions options;
  double radius_mm = 0;
  bool json = false, force = false, quiet = false;
};

}  // namespace

void register_acquire_command(CLI::App& app) {
  auto args = std::make_shared<AcquireArguments>();
  CLI::App* cmd = app.add_subcommand(
      "acquire",
      "Turn a capture (exposure brackets or an HDR image, see lucent-capture files) into a "
      "calibrated HDR image and the profile around the beam entry point. Writes OUTDIR/capture.exr "
      "(linear radiance; per unit beam power when calibrated), profile.json and profile.csv "
      "(radial "
      "bins: pi L / P per mm^2, or pi L relative without a white reference or beam_power; 2D "
      "samples too for oblique incidence) and acquire.png (tone-mapped, entry point, rings, "
      "masked pixels in magenta). The folder appears whole or not at all.");
  cmd->add_option("capture", args->capture, "capture file (JSON, \"format\": \"lucent-capture\")")
      ->required();
  cmd->add_option("-o,--output", args->output,
                  "output folder (created whole; an existing one is refused unless --force)")
      ->required();
  cmd->add_flag("--force", args->force,
                "replace an existing output folder whole (its other files are removed)");
  cmd->add_option("--bins", args->options.bins,
                  "number of radial bins from 0 to the radius (default 150); bins with too few "
                  "pixels are dropped")
      ->transform(whole_in(1, 1000000, "radial bins"));
  cmd->add_flag("--log-bins", args->options.log_bins,
                "log-spaced bins from half a pixel pitch to the radius (first bin [0, pitch/2))");
  auto* radius = cmd->add_option("--radius-mm", args->radius_mm,
                                 "outer radius of the bins and 2D samples, mm (default: distance "
                                 "from the entry point to the nearest image edge)")
                     ->check(number_in(0, 1e6, "mm", true));
  cmd->add_option(
         "--min-pixels", args->options.min_pixels_per_bin,
         "drop radial bins with fewer unmasked pixels than this in any channel (default 3)")
      ->transform(whole_in(2, 1000000000, "pixels per bin"));
  cmd->add_flag("--json", args->json, "print the summary as JSON on standard output");
  cmd->add_flag("-q,--quiet", args->quiet, "no progress on standard error");
  cmd->callback([args, radius] {
    set_replace_folders(args->force);
    if (radius->count() > 0) args->options.radius_mm = args->radius_mm;
    StageProgress progress("acquire", args->quiet);
    args->options.progress = [&](const std::string& stage, double done) {
      progress.stage(stage, done);
    };
    const acquire::AcquireSummary summary =
        acquire::run_acquire(args->capture, args->output, args->options);
    progress.finish();
    if (args->json) {
      std::cout << acquire::summary_to_json(summary).dump(2) << '\n';
    } else {
      std::cout << acquire::to_string(summary);
    }
  });
}

}  // namespace lucent::cli
