// Camera RAW files (DNG, CR2, CR3, NEF, ARW, ... through LibRaw) as measurements: the sensor's own
// codes, linear, with no white balance, colour matrix, tone curve or demosaic interpolation.
//
// A Bayer sensor is read one RGB pixel per 2 x 2 colour-filter quad: red and blue from their
// photosites, green the mean of the two green ones (rounded to the nearest code; a quad is
// saturated when either green is). The image is half the sensor's width and height, so a capture's
// pixel_pitch_mm for RAW brackets is the pitch of a quad, twice the sensor's. The colours of a quad
// sit up to half a sensor pixel apart; no interpolation moves them (its bias at the beam centre
// would be worse than the offset). The black level (LibRaw's common, per-colour and 2 x 2 pattern
// parts) and the white level come from the file and are kept, not subtracted: linear light is
// (v - black) / (white - black), negative where read noise goes below the pedestal, so the faint
// tail stays unbiased. Pixels are in sensor orientation (the camera's rotation flag is ignored).
// Linear DNGs (three samples per pixel) are read pixel for pixel. X-Trans and other non-2 x 2
// mosaics, and black-level patterns larger than 2 x 2, are refused.
//
// LibRaw runs in a forked child process for every file: a RAW file is untrusted input, and LibRaw
// (Debian's 0.20) aborts on some crafted files. A crash or a hang (120 s) of the child becomes one
// error line naming the file; lucent itself never crashes on a RAW file.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "lucent/imaging/image.h"

namespace lucent::imaging {

/// True when the extension names a camera RAW format lucent reads through LibRaw (.dng, .cr2,
/// .cr3, .nef, .nrw, .arw, .srf, .sr2, .raf, .orf, .rw2, .pef, .srw, .3fr, .iiq, .erf, .kdc, .mos,
/// .mrw, .x3f; any case).
bool is_camera_raw_path(const std::filesystem::path& path);

/// Reads a camera RAW file (see the file comment). Throws lucent::Error naming the file for a file
/// LibRaw cannot read, a sensor layout lucent does not support, or an image over 16384^2 pixels.
RawImage read_camera_raw(const std::filesystem::path& path);

/// The same from bytes in memory (`name` is used in messages), LibRaw isolated in a child process.
RawImage decode_camera_raw(std::string_view bytes, const std::string& name);

/// The RAW decoder lucent runs, for provenance: "LibRaw 0.20.2".
std::string camera_raw_decoder_version();

/// A Bayer mosaic as a sensor records it: one code per photosite, row-major.
struct BayerMosaic {
  int width = 0, height = 0;  ///< photosites (both even)
  /// Colour (0 red, 1 green, 2 blue) of the photosites (0,0), (1,0), (0,1), (1,1): RGGB by default.
  std::array<int, 4> pattern{0, 1, 1, 2};
  std::vector<std::uint16_t> data;
  int black_level = 0;      ///< code of no light
  int white_level = 65535;  ///< code at saturation
  double exposure_s = 0;    ///< written when > 0
  double iso = 0;           ///< written when > 0
  std::string make = "lucent", model = "simulated camera";
};

/// Writes a mosaic as a minimal uncompressed DNG 1.4 (libtiff): CFA tags, BlackLevel, WhiteLevel,
/// an identity ColorMatrix1, ExposureTime and ISOSpeedRatings. Atomic. For tests and for `lucent
/// simulate --bracket-format dng`; cameras write the real thing.
void write_dng(const std::filesystem::path& path, const BayerMosaic& mosaic);

}  // namespace lucent::imaging
