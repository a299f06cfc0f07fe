// Synthetic captures for the acquire tests (acquire_test.cpp, acquire_job_test.cpp): a known
// radially symmetric radiance L(r) = A exp(-r / 2 mm) / (r + 0.5 mm) imaged through an exact
// (noise-free) or noisy camera, written by the tests themselves.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "lucent/acquire/acquire.h"
#include "lucent/acquire/beam.h"
#include "lucent/acquire/camera.h"
#include "lucent/acquire/capture.h"
#include "lucent/acquire/hdr_merge.h"
#include "lucent/acquire/profile.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/imaging/image_io.h"
#include "raw_exr.h"

// One test file per executable includes this: plain (external) definitions are fine.
namespace lucent::acquire::fixtures {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double kPi = std::numbers::pi;
constexpr std::array<double, 3> kChannelScale = {1.0, 0.6, 0.3};

// Folders made by this test process, removed when it exits.
struct ScratchFolders {
  std::vector<fs::path> folders;
  ~ScratchFolders() {
    for (const auto& folder : folders) {
      std::error_code ignored;
      fs::remove_all(folder, ignored);
    }
  }
};

fs::path scratch_dir(const std::string& name) {
  static ScratchFolders made;
  const fs::path dir = fs::temp_directory_path() /
                       ("lucent-acquire-test-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  made.folders.push_back(dir);
  return dir;
}

std::set<std::string> listing(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir))
    names.insert(entry.path().filename().string());
  return names;
}

double falloff(double r_mm) {
  return std::exp(-r_mm / 2) / (r_mm + 0.5);
}

struct Spot {
  int width = 64, height = 64;
  double pitch_mm = 0.1;
  double cx = 30.3, cy = 33.7;  // px, pixel centres at i + 0.5
  double amplitude = 1.0;
};

double spot_value(const Spot& s, int x, int y, int c) {
  const double r_mm = s.pitch_mm * std::hypot(x + 0.5 - s.cx, y + 0.5 - s.cy);
  return s.amplitude * kChannelScale[c] * falloff(r_mm);
}

imaging::ImageRgb spot_radiance(const Spot& s) {
  imaging::ImageRgb image(s.width, s.height);
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = float(spot_value(s, x, y, c));
    }
  }
  return image;
}

// A camera without noise: code = round(encode(clamp(L t gain + offset, 0, 1)) max).
imaging::RawImage exact_exposure(const imaging::ImageRgb& radiance, double t, double gain,
                                 int max_value, Response response, double offset = 0) {
  imaging::RawImage out(radiance.width, radiance.height, max_value);
  for (std::size_t i = 0; i < radiance.data.size(); ++i) {
    const double linear = std::clamp(radiance.data[i] * t * gain + offset, 0.0, 1.0);
    const double encoded = response == Response::kSrgb ? srgb_encode(linear) : linear;
    out.data[i] = std::uint16_t(std::lround(encoded * max_value));
  }
  return out;
}

struct StackSpec {
  std::vector<double> exposures_s = {1, 4, 16, 64};
  double gain = 0.2;  // linear code fraction per (radiance x s)
  int max_value = 65535;
  Response response = Response::kLinear;
  double dark_offset = 0;  // linear, added to every bracket (and the dark frame, when written)
};

ImageSet write_brackets(const fs::path& dir, const std::string& stem,
                        const imaging::ImageRgb& radiance, const StackSpec& spec) {
  ImageSet set;
  for (std::size_t k = 0; k < spec.exposures_s.size(); ++k) {
    const std::string name = stem + "_" + std::to_string(k) + ".png";
    imaging::write_png(dir / name, exact_exposure(radiance, spec.exposures_s[k], spec.gain,
                                                  spec.max_value, spec.response, spec.dark_offset));
    set.images.push_back({name, spec.exposures_s[k]});
  }
  return set;
}

Capture make_capture(const ImageSet& sample, double pitch_mm, Response response) {
  Capture c;
  c.sample = sample;
  c.pixel_pitch_mm = pitch_mm;
  c.response = response;
  return c;
}

fs::path write_capture_file(const fs::path& dir, const Capture& capture,
                            const std::string& name = "capture.json") {
  write_capture(dir / name, capture);
  return dir / name;
}

// A Lambertian reference of reflectance rho lit by a beam of power P: radiance P rho / pi times a
// normalised Gaussian spot (per mm^2), point-sampled (sigma = 4 px, so the samples sum to 1).
imaging::ImageRgb white_radiance(int size, double pitch_mm, double power, double rho,
                                 double sigma_mm) {
  imaging::ImageRgb image(size, size);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double r2 = std::pow(pitch_mm * (x + 0.5 - size / 2.0), 2) +
                        std::pow(pitch_mm * (y + 0.5 - size / 2.0), 2);
      const double g = std::exp(-r2 / (2 * sigma_mm * sigma_mm)) / (2 * kPi * sigma_mm * sigma_mm);
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = float(power * rho / kPi * g);
    }
  }
  return image;
}

// An HdrResult holding `radiance` as measured, nothing masked, zero error: for the unit tests of
// beam detection and binning.
HdrResult as_measured(const imaging::ImageRgb& radiance) {
  HdrResult hdr;
  hdr.radiance = radiance;
  hdr.standard_error = imaging::ImageRgb(radiance.width, radiance.height, 0.0f);
  hdr.mask.assign(radiance.data.size(), PixelMask::kValid);
  return hdr;
}

// Runs `run_acquire` expecting lucent::Error whose message contains every one of `needles`, and
// checks that the output folder was not created (nor any temporary folder left beside it).
void expect_acquire_fails(const fs::path& capture, const fs::path& out,
                          const std::vector<std::string>& needles) {
  const bool existed = fs::exists(out);
  const std::set<std::string> before_parent = listing(out.parent_path());
  const std::set<std::string> before = existed ? listing(out) : std::set<std::string>{};
  try {
    run_acquire(capture, out);
    FAIL() << "expected lucent::Error for " << capture;
  } catch (const Error& e) {
    const std::string message = e.what();
    for (const auto& needle : needles) {
      EXPECT_NE(message.find(needle), std::string::npos)
          << "'" << needle << "' not in: " << message;
    }
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  EXPECT_EQ(fs::exists(out), existed);
  if (existed) {
    EXPECT_EQ(listing(out), before);
  }
  EXPECT_EQ(listing(out.parent_path()), before_parent) << "temporary folder left behind";
}

}  // namespace lucent::acquire::fixtures
