#include "lucent/acquire/camera.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "lucent/core/error.h"

namespace lucent::acquire {
namespace {

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

}  // namespace

double srgb_encode(double v) {
  v = std::clamp(v, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

double srgb_decode(double v) {
  v = std::clamp(v, 0.0, 1.0);
  return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

namespace {

std::string number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}

}  // namespace

void validate_camera_options(const CameraOptions& o) {
  if (o.exposures_s.empty()) throw Error("--exposures: expected at least one exposure time");
  for (std::size_t k = 0; k < o.exposures_s.size(); ++k) {
    const double t = o.exposures_s[k];
    if (!(t > 0 && t <= 1e6)) {
      throw Error("--exposures: each exposure must be a time in (0, 1e6] s, got " + number(t));
    }
    if (k > 0 && !(t > o.exposures_s[k - 1])) {
      throw Error("--exposures: exposure times must increase strictly");
    }
  }
  if (o.bits != 8 && o.bits != 16) throw Error("--bits: expected 8 or 16");
  if (o.response == Response::kCalibrate) {
    throw Error("--response: a simulated camera is 'linear' or 'srgb'");
  }
  if (!(o.full_well_e >= 100 && o.full_well_e <= 1e9)) {
    throw Error("--full-well-e: expected the electrons at saturation in [100, 1e9], got " +
                number(o.full_well_e));
  }
  if (!(o.read_noise_e >= 0 && o.read_noise_e <= 0.1 * o.full_well_e)) {
    throw Error("--read-noise-e: expected read noise in [0, full well / 10] electrons rms, got " +
                number(o.read_noise_e));
  }
  if (!(o.black_level_e >= 0 && o.black_level_e <= 0.5 * o.full_well_e)) {
    throw Error("--black-level-e: expected a pedestal in [0, full well / 2] electrons, got " +
                number(o.black_level_e));
  }
  if (!(o.electrons_per_radiance_s == 0 ||
        (o.electrons_per_radiance_s > 0 && o.electrons_per_radiance_s <= 1e30))) {
    throw Error(
        "--camera-scale: expected electrons per (radiance s) in (0, 1e30], or 0 for "
        "automatic, got " +
        number(o.electrons_per_radiance_s));
  }
  if (!(o.auto_fill > 0 && o.auto_fill <= 1)) {
    throw Error("camera: auto_fill must be in (0, 1], got " + number(o.auto_fill));
  }
}

double camera_scale(const CameraOptions& options, double peak_radiance) {
  if (options.electrons_per_radiance_s > 0) return options.electrons_per_radiance_s;
  if (!(peak_radiance > 0))
    throw Error("camera: the image is black, no exposure scale can be chosen");
  if (options.exposures_s.empty()) throw Error("--exposures: expected at least one exposure time");
  return options.auto_fill * (options.full_well_e - options.black_level_e) /
         (peak_radiance * options.exposures_s.front());
}

imaging::RawImage expose(const imaging::ImageRgb& radiance, double exposure_s, double scale,
                         const CameraOptions& options, std::uint64_t stream) {
  validate_camera_options(options);
  const int max_value = options.bits == 8 ? 255 : 65535;
  imaging::RawImage out(radiance.width, radiance.height, max_value);
  std::mt19937_64 rng(splitmix64(options.seed ^ splitmix64(stream)));
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (std::size_t i = 0; i < radiance.data.size(); ++i) {
    const double signal = std::max(0.0, double(radiance.data[i])) * exposure_s * scale;
    double electrons = signal;
    if (options.noise) {
      // Poisson shot noise: exact below 1e4 expected electrons, Gaussian (its limit) above.
      if (signal < 1e4) {
        electrons = double(std::poisson_distribution<long long>(signal)(rng));
      } else {
        electrons = signal + std::sqrt(signal) * gauss(rng);
      }
      electrons += options.read_noise_e * gauss(rng);
    }
    electrons += options.black_level_e;
    const double linear = std::clamp(electrons / options.full_well_e, 0.0, 1.0);
    const double encoded = options.response == Response::kSrgb ? srgb_encode(linear) : linear;
    out.data[i] = static_cast<std::uint16_t>(std::lround(encoded * max_value));
  }
  return out;
}

imaging::BayerMosaic expose_mosaic(const imaging::ImageRgb& radiance, double exposure_s,
                                   double scale, const CameraOptions& options,
                                   std::uint64_t stream) {
  if (options.bits != 16 || options.response != Response::kLinear) {
    throw Error(
        "--bracket-format dng: a RAW sensor records linear 16-bit codes (use --bits 16 "
        "--response linear)");
  }
  CameraOptions sensor = options;
  const int black_code = int(std::lround(options.black_level_e / options.full_well_e * 65535));
  sensor.black_level_e = black_code * options.full_well_e / 65535;
  // Every photosite of a quad sees its pixel: expose the image at twice the resolution.
  const int w = radiance.width, h = radiance.height;
  imaging::ImageRgb sites(2 * w, 2 * h);
  for (int y = 0; y < 2 * h; ++y) {
    for (int x = 0; x < 2 * w; ++x) {
      for (int c = 0; c < 3; ++c) sites.at(x, y, c) = radiance.at(x / 2, y / 2, c);
    }
  }
  const imaging::RawImage codes = expose(sites, exposure_s, scale, sensor, stream);
  imaging::BayerMosaic mosaic;
  mosaic.width = 2 * w;
  mosaic.height = 2 * h;
  mosaic.data.resize(std::size_t(mosaic.width) * mosaic.height);
  for (int y = 0; y < mosaic.height; ++y) {
    for (int x = 0; x < mosaic.width; ++x) {
      const int colour = mosaic.pattern[(y % 2) * 2 + x % 2];
      mosaic.data[std::size_t(y) * mosaic.width + x] = codes.at(x, y, colour);
    }
  }
  mosaic.black_level = black_code;
  mosaic.white_level = 65535;
  mosaic.exposure_s = exposure_s;
  mosaic.iso = 100;
  return mosaic;
}

}  // namespace lucent::acquire
