// From linear radiance to what a person looks at: exposure, Reinhard's curve per channel, sRGB
// encoding to 8 bits (PNG); or the linear values themselves (OpenEXR). Every technique writes its
// image through write_render_image so that they look alike; the GLSL tone map of the real-time
// pipeline is the twin of tone_curve() and srgb_encode().
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "lucent/imaging/image.h"

namespace lucent::render {

struct ToneMapOptions {
  float exposure = 1.0f;  ///< linear scale applied to the radiance before the curve
};

/// Reinhard's global operator per channel, x / (1 + x) for x >= 0 (Reinhard et al. 2002, eq. 3,
/// applied to each channel rather than to luminance): 1 maps to 0.5, never clips. Negative and NaN
/// inputs give 0.
float tone_curve(float x);

/// The sRGB transfer function (IEC 61966-2-1) on [0, 1]; values outside are clamped.
float srgb_encode(float linear);

/// Its inverse on [0, 1] (values outside clamped).
float srgb_decode(float encoded);

/// What a screen shows, as linear light in [0, 1]: a render after the exposure and the tone curve
/// (before the sRGB encoding), or a PNG's codes decoded. `lucent compare` holds a PNG against an
/// EXR, or two PNGs, in this space.
imaging::ImageRgb displayed(const imaging::ImageRgb& linear, const ToneMapOptions& options);
imaging::ImageRgb displayed(const imaging::RawImage& png);

/// exposure -> tone_curve -> srgb_encode -> 8-bit RGB (rounded).
imaging::RawImage tone_map(const imaging::ImageRgb& linear, const ToneMapOptions& options = {});

/// Writes an image by the name's extension, atomically: `.exr` linear float RGB as given (no
/// exposure, no tone curve; `attributes` go into the header); `.png` tone-mapped 8-bit sRGB.
/// Any other extension throws lucent::Error naming the file.
void write_render_image(const std::filesystem::path& path, const imaging::ImageRgb& linear,
                        const ToneMapOptions& options = {},
                        const std::map<std::string, std::string>& attributes = {});

/// `--exposure auto`: the scale that puts the 95th percentile of the object's luminance
/// (0.2126 R + 0.7152 G + 0.0722 B over pixels where mask != 0, or every non-black pixel when the
/// mask is empty) at 2, which the tone curve maps to 2/3: the bright side is bright and still
/// shaded (Reinhard never clips). 1 for an all-black image.
float auto_exposure(const imaging::ImageRgb& linear, const std::vector<std::uint8_t>& mask = {});

/// True for the extensions write_render_image accepts (.png, .exr; any case).
bool is_render_image_path(const std::filesystem::path& path);

}  // namespace lucent::render
