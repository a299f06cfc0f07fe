// `lucent compare`: how far a render is from a reference (relative RMSE, per-channel mean ratios)
// over the pixels where the reference shows the object.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/core/json_file.h"
#include "lucent/imaging/image_io.h"
#include "lucent/render/image_compare.h"
#include "lucent/render/tone_map.h"
#include "validators.h"

namespace lucent::cli {
namespace {

struct CompareArguments {
  std::string image, reference;
  std::string exposure = "auto";  ///< a PNG against an EXR: the EXR's exposure (or auto)
  bool json = false;
  std::string difference;
  float scale = 10;
  bool signed_difference = false;
  bool fit_scale = false;
};

bool is_png(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e == ".png";
}

// An EXR's linear render, refused with the pixel where it is not radiance.
render::ImageRgb read_linear(const std::string& path) {
  const render::ImageRgb im = imaging::read_exr(path);
  // Renders are radiance: finite and >= 0 (a NaN or negative pixel made a NaN or negative RMSE).
  for (std::size_t i = 0; i < im.data.size(); ++i)
    if (!std::isfinite(im.data[i]) || im.data[i] < 0) {
      const std::size_t p = i / 3;
      throw Error(path + ": pixel (" + std::to_string(p % std::size_t(im.width)) + ", " +
                  std::to_string(p / std::size_t(im.width)) + ") is " +
                  (std::isfinite(im.data[i]) ? "negative" : "not finite") +
                  ": expected a linear render (radiance >= 0)");
    }
  return im;
}

void check_extension(const std::string& path, const std::string& what) {
  std::string e = std::filesystem::path(path).extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (e != ".png" && e != ".exr") {
    throw Error(path + ": the " + what + " must be a render, .exr (linear) or .png (tone-mapped)");
  }
}

void run_compare(const CompareArguments& args) {
  if (!args.difference.empty()) check_output_file(args.difference, "", "--difference");
  check_extension(args.image, "image");
  check_extension(args.reference, "reference");
  std::optional<float> fixed_exposure;
  if (args.exposure != "auto") {
    char* end = nullptr;
    const float e = std::strtof(args.exposure.c_str(), &end);
    if (end == args.exposure.c_str() || *end != '\0' || !(e > 0) || !std::isfinite(e))
      throw Error("--exposure: expected a positive number or auto, got '" + args.exposure + "'");
    fixed_exposure = e;
  }
  // Two EXRs are compared as linear radiance; where either is a PNG (tone-mapped, 8 bits), both
  // as displayed (render::displayed): the EXR after the exposure (auto: its own, the rule
  // `render` writes PNGs with) and the tone curve, the PNG decoded from sRGB.
  const bool as_displayed = is_png(args.image) || is_png(args.reference);
  float exposure = 0;
  const auto read = [&](const std::string& path) {
    if (is_png(path)) return render::displayed(imaging::read_raw_image(path));
    render::ImageRgb linear = read_linear(path);
    if (!as_displayed) return linear;
    render::ToneMapOptions tone;
    tone.exposure = fixed_exposure ? *fixed_exposure : render::auto_exposure(linear);
    exposure = tone.exposure;
    return render::displayed(linear, tone);
  };
  const render::ImageRgb image = read(args.image);
  const render::ImageRgb reference = read(args.reference);
  if (image.width != reference.width || image.height != reference.height)
    throw Error(args.image + ": " + std::to_string(image.width) + " x " +
                std::to_string(image.height) + " pixels, the reference " + args.reference + " " +
                std::to_string(reference.width) + " x " + std::to_string(reference.height));
  bool lit = false;
  for (const float v : reference.data) lit = lit || v > 0;
  if (!lit) throw Error(args.reference + ": the reference is black: nothing to compare against");
  const render::ImageDifference d =
      render::compare_images(image, reference, render::nonzero_mask(reference));
  if (!args.difference.empty()) {
    // |image - reference| / the reference's mean, times --scale: a black image is no difference,
    // white (tone-mapped 1) is `1 / scale` of the mean.
    render::ImageRgb diff(image.width, image.height, 0.0f);
    const auto mask = render::nonzero_mask(reference);
    for (std::size_t p = 0; p < mask.size(); ++p) {
      if (!mask[p]) continue;
      if (args.signed_difference) {  // red: the image is brighter; blue: darker (mean of RGB)
        double delta = 0;
        for (int c = 0; c < 3; ++c)
          delta += image.data[3 * p + std::size_t(c)] - reference.data[3 * p + std::size_t(c)];
        delta /= 3 * d.reference_mean;
        diff.data[3 * p] = float(std::max(0.0, delta));
        diff.data[3 * p + 2] = float(std::max(0.0, -delta));
        continue;
      }
      for (int c = 0; c < 3; ++c) {
        const std::size_t i = 3 * p + std::size_t(c);
        diff.data[i] = float(std::abs(image.data[i] - reference.data[i]) / d.reference_mean);
      }
    }
    render::ToneMapOptions tone;
    tone.exposure = args.scale;
    render::write_render_image(args.difference, diff, tone);
  }
  std::optional<render::ScaledComparison> scaled;
  if (args.fit_scale) {
    scaled = render::compare_scaled(image, reference, render::nonzero_mask(reference));
  }
  if (args.json) {
    nlohmann::json doc = {{"format", "lucent-image-difference"},
                          {"version", 1},
                          {"image", args.image},
                          {"reference", args.reference},
                          {"pixels", d.pixels},
                          {"relative_rmse", d.relative_rmse},
                          {"mean_ratio", d.mean_ratio},
                          {"reference_mean", d.reference_mean},
                          {"space", as_displayed ? "displayed" : "linear"}};
    if (as_displayed && exposure > 0) doc["exposure"] = exposure;
    if (d.blocks > 0) {
      doc["blocks"] = d.blocks;
      doc["block_relative_rmse"] = d.block_relative_rmse;
    }
    if (scaled) {
      doc["scaled"] = {{"scale", scaled->scale},
                       {"channel_scale", scaled->channel_scale},
                       {"correlation", scaled->correlation},
                       {"relative_rmse", scaled->relative_rmse}};
    }
    check_finite_json(doc, "compare --json");
    std::printf("%s\n", doc.dump(2).c_str());
  } else {
    std::printf("compare: %s%s\n", d.to_string().c_str(),
                as_displayed ? (exposure > 0 ? ", as displayed (the EXR at exposure " +
                                                   std::to_string(exposure) + ")"
                                             : std::string(", as displayed"))
                                   .c_str()
                             : "");
    if (scaled) std::printf("compare (scaled): %s\n", scaled->to_string().c_str());
  }
}

}  // namespace

void register_compare_command(CLI::App& app) {
  auto args = std::make_shared<CompareArguments>();
  CLI::App* cmd = app.add_subcommand(
      "compare",
      "How far a render is from a reference render of the same size (EXR linear, PNG tone-mapped: "
      "two EXRs are compared as radiance; where either is a PNG both are compared as displayed, "
      "the EXR tone-mapped at --exposure): relative RMSE "
      "(RMSE over pixels and channels / the reference's mean), the same over 4x4 blocks of pixels "
      "(each block's mean; the blocks wholly on the object) and per-channel mean ratios, over the "
      "pixels where the reference is not black");
  cmd->add_option("image", args->image, "the render to judge (.exr or .png)")->required();
  cmd->add_option("reference", args->reference,
                  "the reference (.exr or .png), e.g. --technique reference")
      ->required();
  cmd->add_option("--exposure", args->exposure,
                  "an EXR held against a PNG: its exposure before the tone curve, or auto (the "
                  "rule render writes PNGs with)")
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "print a JSON summary (lucent-image-difference)");
  cmd->add_option(
      "--difference", args->difference,
      "also write |image - reference| / the reference's mean as an image (.png or .exr)");
  cmd->add_flag("--signed", args->signed_difference,
                "--difference: red where the image is brighter, blue where darker");
  cmd->add_option("--scale", args->scale, "--difference: multiplier before the tone curve")
      ->check(number_in(0, 1e9, "a multiplier", true))
      ->capture_default_str();
  cmd->add_flag("--fit-scale", args->fit_scale,
                "also the least-squares scale of the image to the reference, the relative RMSE "
                "after it, and the correlation (for renders right only up to a scale: --technique "
                "sh)");
  cmd->callback([args] { run_compare(*args); });
}

}  // namespace lucent::cli
