// Finding where the beam enters the sample: the sub-pixel centroid of the brightest blob.
//
// Pixel convention (used by beam_point_px in capture and profile files too): pixel (i, j) covers
// [i, i + 1) x [j, j + 1) in pixel units, its centre is (i + 0.5, j + 0.5); x along image columns,
// y along rows (downwards).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "lucent/acquire/hdr_merge.h"

namespace lucent::acquire {

struct BeamDetectionOptions {
  /// The blob: pixels 8-connected to the brightest one and above this fraction of its luminance.
  double region_fraction = 0.5;
  /// "No beam" unless peak > background median + min_peak_snr * robust noise (1.4826 x MAD).
  double min_peak_snr = 10;
  /// A brightest pixel more than this times its brightest neighbour is an unresolved spike and is
  /// capped at that neighbour's luminance before the blob is taken (0: never).
  double spike_ratio = 2;
};

struct BeamPoint {
  std::array<double, 2> px{};         ///< (x, y) in pixels, centre convention above
  double peak = 0;                    ///< luminance of the brightest (or saturated) pixel
  double background = 0;              ///< median luminance of the image
  double noise = 0;                   ///< 1.4826 x median absolute deviation of the luminance
  std::int64_t region_pixels = 0;     ///< pixels in the blob
  std::int64_t saturated_pixels = 0;  ///< of which masked as saturated
  bool spike_capped = false;          ///< the brightest pixel was an unresolved spike (capped)
};

/// The entry point of the beam in `hdr`. Luminance is 0.2126 R + 0.7152 G + 0.0722 B; a pixel
/// masked as saturated in any channel counts as the brightest (weight = peak); black-masked
/// channels count as 0 and non-finite pixels are left out. The centroid weights each blob pixel by
/// its luminance minus the threshold (region_fraction x peak): pixels at the blob's edge weigh next
/// to nothing, so whether they fall just inside or just outside does not shift it (a plain
/// intensity weighting is biased by up to ~0.1 px when a symmetric spot sits off the pixel grid).
/// An unresolved spike (single scattering or specular light in one pixel, see spike_ratio) would
/// pin the centroid to that pixel's centre, up to half a pixel from the entry point: it is capped
/// first, so that the resolved light around it decides. Throws lucent::Error "<source>: no beam
/// found: ..." when the peak does not stand out of the background.
BeamPoint find_beam_point(const HdrResult& hdr, const std::string& source,
                          const BeamDetectionOptions& options = {});

/// A bench's system response (beam footprint (x) lens blur (x) glare (x) pixel), as its light on a
/// flat white target records it: radial rings of half a pixel about the spot's centroid (the
/// pixels above a tenth of the peak), normalised to unit integral, per mm^2, out to the nearest
/// image edge; a ring no brighter than 3 of its standard errors is 0 (the dark field's noise, not
/// light). No level is taken off: far from the spot it is the lens's veiling glare.
struct SystemResponse {
  std::vector<double> r_mm, value;
  double rms_mm = 0;  ///< rms radius of all the light about the centroid, mm
};

/// The response from an image's light, row-major width x height (NaN: left out), pixels of
/// pixel_mm on the target. Empty when there is no light (every pixel 0 or below).
SystemResponse system_response(const std::vector<double>& light, int width, int height,
                               double pixel_mm);

}  // namespace lucent::acquire
