// Reading and writing images: OpenEXR for linear HDR, PNG/TIFF (through OpenCV) for brackets and
// for what a person looks at. Every writer is atomic; every reader throws lucent::Error naming the
// file.
#pragma once

#include <filesystem>
#include <map>
#include <string>

#include "lucent/imaging/image.h"

namespace lucent::imaging {

/// Linear float RGB from an OpenEXR file (R, G, B channels; Y alone is read as grey).
ImageRgb read_exr(const std::filesystem::path& path);

/// Writes linear float RGB to OpenEXR (32-bit float channels R, G, B, ZIP compression), atomically.
/// `attributes` become string attributes in the header (units, provenance).
void write_exr(const std::filesystem::path& path, const ImageRgb& image,
               const std::map<std::string, std::string>& attributes = {});

/// A bracket from PNG or TIFF, 8 or 16 bits per channel, grey or RGB(A) (grey is copied to RGB),
/// or from a camera RAW file when the extension says so (read_camera_raw, camera_raw.h).
RawImage read_raw_image(const std::filesystem::path& path);

/// Writes an 8- or 16-bit RGB PNG (max_value 255 or 65535), atomically.
void write_png(const std::filesystem::path& path, const RawImage& image);

/// Linear float RGB from a Radiance RGBE (.hdr) file.
ImageRgb read_radiance_hdr(const std::filesystem::path& path);

/// Either reader by extension: .exr -> read_exr; anything else -> read_raw_image, linear in [0, 1]
/// ((v - black) / (max - black); negative below a RAW file's black level).
ImageRgb read_any_image(const std::filesystem::path& path);

}  // namespace lucent::imaging
