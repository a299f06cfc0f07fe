#include "lucent/acquire/beam.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "lucent/core/error.h"

namespace lucent::acquire {
namespace {

// Rec. 709 luminance weights (linear RGB).
constexpr double kLuminance[3] = {0.2126, 0.7152, 0.0722};

// 1.4826 x MAD estimates a Gaussian's sigma.
constexpr double kMadToSigma = 1.4826;

// Pixel kinds, stored as bytes (an enum class vector trips a false -Wfree-nonheap-object in g++
// 12).
constexpr std::uint8_t kMeasured = 0, kSaturated = 1, kExcluded = 2;

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}

// 8-connected pixels reachable from `seed` for which `inside(index)` holds and that are not yet
// `seen` (which they then become: one `seen` serves several regions without re-allocation).
template <typename Inside>
std::vector<std::size_t> connected_region(int width, int height, std::size_t seed, Inside inside,
                                          std::vector<std::uint8_t>& seen) {
  std::vector<std::size_t> region, stack{seed};
  seen[seed] = 1;
  while (!stack.empty()) {
    const std::size_t i = stack.back();
    stack.pop_back();
    region.push_back(i);
    const int x = int(i % width), y = int(i / width);
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int nx = x + dx, ny = y + dy;
        if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
        const std::size_t j = std::size_t(ny) * width + nx;
        if (seen[j] || !inside(j)) continue;
        seen[j] = 1;
        stack.push_back(j);
      }
    }
  }
  return region;
}

std::string number(double value) {
  std::ostringstream s;
  s.precision(4);
  s << value;
  return s.str();
}

}  // namespace

BeamPoint find_beam_point(const HdrResult& hdr, const std::string& source,
                          const BeamDetectionOptions& options) {
  const int width = hdr.width(), height = hdr.height();
  const std::size_t pixels = std::size_t(width) * height;
  std::vector<double> luminance(pixels, 0.0);
  std::vector<std::uint8_t> kind(pixels, kMeasured);
  std::vector<double> measured;
  measured.reserve(pixels);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const std::size_t i = std::size_t(y) * width + x;
      double value = 0;
      for (int c = 0; c < 3; ++c) {
        const PixelMask m = hdr.mask_at(x, y, c);
        if (m == PixelMask::kSaturated) kind[i] = kSaturated;
        if (m == PixelMask::kNonFinite && kind[i] == kMeasured) kind[i] = kExcluded;
        if (m == PixelMask::kValid) value += kLuminance[c] * hdr.radiance.at(x, y, c);
      }
      luminance[i] = value;
      if (kind[i] == kMeasured) measured.push_back(value);
    }
  }

  BeamPoint beam;
  beam.saturated_pixels = std::count(kind.begin(), kind.end(), kSaturated);
  if (measured.empty()) {
    throw Error(source + ": no beam found: no pixel has a measured value in all three channels");
  }
  beam.background = median(measured);
  std::vector<double> deviations(measured.size());
  for (std::size_t i = 0; i < measured.size(); ++i)
    deviations[i] = std::abs(measured[i] - beam.background);
  beam.noise = kMadToSigma * median(std::move(deviations));

  // The seed: the largest saturated blob when there is one (its pixels are the brightest of all),
  // else the brightest measured pixel.
  std::size_t seed = pixels;
  double peak = -HUGE_VAL;
  for (std::size_t i = 0; i < pixels; ++i) {
    if (kind[i] == kMeasured && luminance[i] > peak) peak = luminance[i], seed = i;
  }
  beam.peak = peak;
  if (beam.saturated_pixels == 0 && !std::isfinite(peak)) {
    throw Error(source + ": no beam found: no pixel holds a usable measurement (every one is "
                "masked: non-finite, negative or outside the brackets' range)");
  }
  if (beam.saturated_pixels > 0) {
    std::vector<std::uint8_t> labelled(pixels, 0);
    std::size_t largest = 0;
    for (std::size_t i = 0; i < pixels; ++i) {
      if (kind[i] != kSaturated || labelled[i]) continue;
      const auto blob = connected_region(
          width, height, i, [&](std::size_t j) { return kind[j] == kSaturated; }, labelled);
      if (blob.size() > largest) largest = blob.size(), seed = i;
    }
  } else if (!(peak > beam.background + options.min_peak_snr * beam.noise) || !(peak > 0)) {
    throw Error(source + ": no beam found: the brightest pixel (luminance " + number(peak) +
                ") does not stand out of the background (median " + number(beam.background) +
                ", noise " + number(beam.noise) + "; needs median + " +
                number(options.min_peak_snr) + " x noise); give beam_point_px in the capture file");
  }

  if (beam.saturated_pixels == 0 && options.spike_ratio > 0) {
    // An unresolved spike (single scattering or specular light landing in one pixel) says only
    // which pixel the beam enters; capped at its brightest neighbour, it leaves the centroid to the
    // resolved light around it, which is symmetric about the entry point at sub-pixel precision.
    const int sx = int(seed % width), sy = int(seed / width);
    double neighbour = 0;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = sx + dx, y = sy + dy;
        if ((dx == 0 && dy == 0) || x < 0 || y < 0 || x >= width || y >= height) continue;
        const std::size_t j = std::size_t(y) * width + x;
        if (kind[j] == kMeasured) neighbour = std::max(neighbour, luminance[j]);
      }
    }
    if (neighbour > 0 && peak > options.spike_ratio * neighbour) {
      luminance[seed] = peak = neighbour;
      beam.spike_capped = true;
    }
  }

  const double threshold = options.region_fraction * peak;
  std::vector<std::uint8_t> seen(pixels, 0);
  const auto region = connected_region(
      width, height, seed,
      [&](std::size_t j) {
        return kind[j] == kSaturated || (kind[j] == kMeasured && luminance[j] > threshold);
      },
      seen);
  double sum_w = 0, sum_x = 0, sum_y = 0;
  for (std::size_t i : region) {
    const double weight = (kind[i] == kSaturated ? peak : luminance[i]) - threshold;
    sum_w += weight;
    sum_x += weight * (double(i % width) + 0.5);
    sum_y += weight * (double(i / width) + 0.5);
  }
  beam.region_pixels = std::int64_t(region.size());
  if (sum_w > 0) {
    beam.px = {sum_x / sum_w, sum_y / sum_w};
  } else {  // a one-pixel blob exactly at the threshold
    beam.px = {double(seed % width) + 0.5, double(seed / width) + 0.5};
  }
  return beam;
}

SystemResponse system_response(const std::vector<double>& light, int w, int h,
                               double pixel_mm) {
  SystemResponse r;
  const auto at = [&](int x, int y) {
    const double s = light[std::size_t(y) * std::size_t(w) + std::size_t(x)];
    return std::isfinite(s) ? s : 0.0;
  };
  double peak = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) peak = std::max(peak, at(x, y));
  if (!(peak > 0)) return r;
  // The centroid of the spot (pixels above a tenth of the peak: the noise far out would pull it).
  double total = 0, cx = 0, cy = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double s = at(x, y);
      if (s > 0.1 * peak) total += s, cx += s * (x + 0.5), cy += s * (y + 0.5);
    }
  cx /= total, cy /= total;
  const double reach = std::min({cx, cy, w - cx, h - cy});
  const int rings = std::max(1, int(2 * reach));
  std::vector<double> sum(std::size_t(rings), 0.0), sum2(std::size_t(rings), 0.0),
      count(std::size_t(rings), 0.0), radius(std::size_t(rings), 0.0);
  double all = 0, second = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy), s = at(x, y);
      all += s, second += s * d * d;
      const int k = int(2 * d);
      if (k < rings) {
        const auto i = std::size_t(k);
        sum[i] += s, sum2[i] += s * s, count[i] += 1, radius[i] += d;
      }
    }
  if (!(all > 0)) return r;
  const double area = pixel_mm * pixel_mm;
  for (int k = 0; k < rings; ++k) {
    const double n = count[std::size_t(k)];
    if (n == 0) continue;
    const double mean = sum[std::size_t(k)] / n;
    // (A ring of one pixel, the centroid on a pixel's centre, has no spread to judge by: kept.)
    const double se =
        n > 1 ? std::sqrt(std::max(0.0, sum2[std::size_t(k)] / n - mean * mean) / (n - 1)) : 0.0;
    // At the mean distance of its pixels' centres: near the centre a ring's few pixels sit far from
    // its middle (the 4 pixels about a centroid on a pixel corner are at 0.71 px, in the ring
    // 0.5..1), and a spot of 2 pixels sigma read at the middles was fitted 8% off.
    r.r_mm.push_back(radius[std::size_t(k)] / n * pixel_mm);
    // The profile spans six decades: a floor of noise would be a veil over its tail.
    r.value.push_back(mean > 3 * se ? mean / (all * area) : 0.0);
  }
  r.rms_mm = std::sqrt(std::max(0.0, second / all)) * pixel_mm;
  return r;
}

}  // namespace lucent::acquire
