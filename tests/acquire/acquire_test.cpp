// Tests of `lucent acquire` (acquire/src/hdr_merge.cpp, beam.cpp, profile.cpp, acquire.cpp) on
// small synthetic captures written by the tests themselves: a known radially symmetric radiance
// L(r) = A exp(-r / 2 mm) / (r + 0.5 mm) imaged through an exact (noise-free) or noisy camera.
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
#include "lucent/acquire/image_io.h"
#include "lucent/acquire/profile.h"
#include "lucent/materials/atomic_file.h"
#include "lucent/materials/error.h"
#include "raw_exr.h"

namespace lucent::acquire {
namespace {

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

ImageRgb spot_radiance(const Spot& s) {
  ImageRgb image(s.width, s.height);
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = float(spot_value(s, x, y, c));
    }
  }
  return image;
}

// A camera without noise: code = round(encode(clamp(L t gain + offset, 0, 1)) max).
RawImage exact_exposure(const ImageRgb& radiance, double t, double gain, int max_value,
                        Response response, double offset = 0) {
  RawImage out(radiance.width, radiance.height, max_value);
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

ImageSet write_brackets(const fs::path& dir, const std::string& stem, const ImageRgb& radiance,
                        const StackSpec& spec) {
  ImageSet set;
  for (std::size_t k = 0; k < spec.exposures_s.size(); ++k) {
    const std::string name = stem + "_" + std::to_string(k) + ".png";
    write_png(dir / name, exact_exposure(radiance, spec.exposures_s[k], spec.gain, spec.max_value,
                                         spec.response, spec.dark_offset));
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
ImageRgb white_radiance(int size, double pitch_mm, double power, double rho, double sigma_mm) {
  ImageRgb image(size, size);
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
HdrResult as_measured(const ImageRgb& radiance) {
  HdrResult hdr;
  hdr.radiance = radiance;
  hdr.standard_error = ImageRgb(radiance.width, radiance.height, 0.0f);
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

// ----------------------------------------------------------------------------------------------
// HDR merge

TEST(HdrMerge, LinearStackRecoversRadianceWithinQuantisation) {
  const fs::path dir = scratch_dir("merge-linear");
  const Spot spot;
  const ImageRgb truth = spot_radiance(spot);
  const StackSpec spec;
  const ImageSet set = write_brackets(dir, "b", truth, spec);
  const HdrResult hdr = merge_brackets(set, Response::kLinear, std::nullopt, dir);
  ASSERT_EQ(hdr.width(), spot.width);
  EXPECT_EQ(hdr.noise.source, "bracket pairs");
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(hdr.counts.total(c), 0);
    // No noise but quantisation: the fitted shot-noise gain is negligible (a camera has ~1e-5).
    EXPECT_LT(hdr.noise.gain[c], 1e-7);
  }
  // Rounding errs by at most half a code, sqrt(3) quantisation standard deviations per bracket: at
  // most sqrt(3 K) standard errors when K brackets' errors align, about one on average.
  const double bound = std::sqrt(3.0 * double(spec.exposures_s.size()));
  double sum_z2 = 0;
  for (std::size_t i = 0; i < truth.data.size(); ++i) {
    // The merge measures code fraction per second: the camera's gain times the radiance.
    const double value = hdr.radiance.data[i], expected = spec.gain * truth.data[i];
    const double se = hdr.standard_error.data[i];
    ASSERT_GT(se, 0.0) << i;
    EXPECT_LE(std::abs(value - expected), bound * se * (1 + 1e-6)) << "element " << i;
    EXPECT_NEAR(value, expected, 2e-4 * expected) << "element " << i;
    sum_z2 += std::pow((value - expected) / se, 2);
  }
  EXPECT_LT(std::sqrt(sum_z2 / double(truth.data.size())), 1.3);
}

TEST(HdrMerge, SrgbResponseRoundTrip) {
  const fs::path dir = scratch_dir("merge-srgb");
  const ImageRgb truth = spot_radiance(Spot{});
  for (int max_value : {255, 65535}) {
    StackSpec spec;
    spec.response = Response::kSrgb;
    spec.max_value = max_value;
    spec.exposures_s = {1, 2, 4, 8, 16, 32, 64};
    const ImageSet set = write_brackets(dir, "s" + std::to_string(max_value), truth, spec);
    const HdrResult hdr = merge_brackets(set, Response::kSrgb, std::nullopt, dir);
    ASSERT_TRUE(hdr.response.has_value());
    EXPECT_EQ(hdr.response->max_value, max_value);
    const double bound = std::sqrt(3.0 * double(spec.exposures_s.size()));
    double worst = 0, sum_z2 = 0;
    for (std::size_t i = 0; i < truth.data.size(); ++i) {
      ASSERT_EQ(hdr.mask[i], PixelMask::kValid);
      const double value = hdr.radiance.data[i], expected = spec.gain * truth.data[i];
      const double se = hdr.standard_error.data[i];
      EXPECT_LE(std::abs(value - expected), bound * se * (1 + 1e-6))
          << max_value << " element " << i;
      worst = std::max(worst, std::abs(value / expected - 1));
      sum_z2 += std::pow((value - expected) / se, 2);
    }
    EXPECT_LT(std::sqrt(sum_z2 / double(truth.data.size())), 1.3) << max_value;
    EXPECT_LT(worst, max_value == 255 ? 0.03 : 1e-4) << max_value;
  }
  // The curve itself: decode(encode(v)) = v on the codes.
  const ResponseCurve curve = standard_response(Response::kSrgb, 255);
  for (int v = 0; v <= 255; ++v) {
    EXPECT_EQ(std::lround(srgb_encode(curve.linear[1][v]) * 255), v);
  }
}

TEST(HdrMerge, PixelsSaturatedInEveryBracketAreMaskedNotGuessed) {
  const fs::path dir = scratch_dir("merge-saturated");
  Spot spot;
  spot.amplitude = 8;
  const ImageRgb truth = spot_radiance(spot);
  const StackSpec spec;
  const ImageSet set = write_brackets(dir, "b", truth, spec);
  const HdrResult hdr = merge_brackets(set, Response::kLinear, std::nullopt, dir);
  const RawImage shortest =
      exact_exposure(truth, spec.exposures_s.front(), spec.gain, 65535, Response::kLinear);
  std::array<std::int64_t, 3> expected{};
  for (std::size_t i = 0; i < truth.data.size(); ++i) {
    const bool saturated = shortest.data[i] >= 65534;
    expected[i % 3] += saturated;
    if (saturated) {
      EXPECT_EQ(hdr.mask[i], PixelMask::kSaturated) << i;
      EXPECT_EQ(hdr.radiance.data[i], 0.0f) << "a saturated pixel must not get a value";
    } else {
      EXPECT_EQ(hdr.mask[i], PixelMask::kValid) << i;
    }
  }
  EXPECT_GT(expected[0], 0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(hdr.counts.saturated[c], expected[c]) << c;
    EXPECT_EQ(hdr.counts.black[c], 0);
  }
}

TEST(HdrMerge, PixelsBlackInEveryBracketAreMasked) {
  const fs::path dir = scratch_dir("merge-black");
  ImageRgb truth = spot_radiance(Spot{});
  for (int y = 0; y < 5; ++y) {  // a dark 10x5 strip, blue channel only for half of it
    for (int x = 0; x < 10; ++x) {
      for (int c = x < 5 ? 0 : 2; c < 3; ++c) truth.at(x, y, c) = 0.0f;
    }
  }
  const ImageSet set = write_brackets(dir, "b", truth, StackSpec{});
  const HdrResult hdr = merge_brackets(set, Response::kLinear, std::nullopt, dir);
  EXPECT_EQ(hdr.counts.black[0], 25);
  EXPECT_EQ(hdr.counts.black[1], 25);
  EXPECT_EQ(hdr.counts.black[2], 50);
  EXPECT_EQ(hdr.mask_at(7, 2, 2), PixelMask::kBlack);
  EXPECT_EQ(hdr.mask_at(7, 2, 0), PixelMask::kValid);
}

TEST(HdrMerge, DarkFrameIsSubtractedBeforeDividingByExposure) {
  const fs::path dir = scratch_dir("merge-dark");
  ImageRgb truth = spot_radiance(Spot{});
  // At the dark level: a measurement of no light (valid, ~0), not censored. Masking such pixels
  // kept only those that noise lifted above the dark level: a floor in faint profiles.
  truth.at(0, 0, 0) = truth.at(0, 0, 1) = truth.at(0, 0, 2) = 0.0f;
  StackSpec spec;
  spec.dark_offset = 0.01;  // a black level of 1% of the range in every bracket
  const ImageSet set = write_brackets(dir, "b", truth, spec);
  write_png(dir / "dark.png", exact_exposure(ImageRgb(64, 64, 0.0f), 1, spec.gain, 65535,
                                             Response::kLinear, spec.dark_offset));
  const HdrResult with_dark = merge_brackets(set, Response::kLinear, fs::path("dark.png"), dir);
  const HdrResult without = merge_brackets(set, Response::kLinear, std::nullopt, dir);
  EXPECT_EQ(with_dark.mask_at(0, 0, 1), PixelMask::kValid);
  EXPECT_EQ(with_dark.counts.black[1], 0);
  EXPECT_NEAR(with_dark.radiance.at(0, 0, 1), 0.0, 1e-6);
  for (std::size_t i = 3; i < truth.data.size(); ++i) {
    if (with_dark.mask[i] != PixelMask::kValid) continue;
    EXPECT_NEAR(with_dark.radiance.data[i], spec.gain * truth.data[i],
                3e-4 * spec.gain * truth.data[i])
        << i;
  }
  // Without the dark frame the offset survives the merge: at least 0.01 / 64 s.
  EXPECT_GT(without.radiance.at(63, 63, 2) - spec.gain * truth.at(63, 63, 2), 0.01 / 64);
}

TEST(HdrMerge, StandardErrorMatchesTheActualScatter) {
  // Shot noise (full well 40000 electrons) and read noise (4 electrons) on a 16-bit linear camera:
  // the fitted model must recover the gain, and (merged - truth) / standard error must have unit
  // spread.
  const fs::path dir = scratch_dir("merge-noise");
  const ImageRgb truth = spot_radiance(Spot{});
  const double full_well = 40000, read_e = 4, gain = 0.2;
  const std::vector<double> exposures = {1, 4, 16, 64};
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss(0, 1);
  ImageSet set;
  for (std::size_t k = 0; k < exposures.size(); ++k) {
    RawImage image(64, 64, 65535);
    for (std::size_t i = 0; i < truth.data.size(); ++i) {
      const double electrons = truth.data[i] * exposures[k] * gain * full_well;
      const double noisy = electrons + std::sqrt(electrons + read_e * read_e) * gauss(rng);
      image.data[i] = std::uint16_t(std::lround(std::clamp(noisy / full_well, 0.0, 1.0) * 65535));
    }
    const std::string name = "n" + std::to_string(k) + ".png";
    write_png(dir / name, image);
    set.images.push_back({name, exposures[k]});
  }
  const HdrResult hdr = merge_brackets(set, Response::kLinear, std::nullopt, dir);
  ASSERT_EQ(hdr.noise.source, "bracket pairs");
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(hdr.noise.gain[c], 1 / full_well, 0.15 / full_well) << c;
  double sum2 = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < truth.data.size(); ++i) {
    if (hdr.mask[i] != PixelMask::kValid) continue;
    const double z = (hdr.radiance.data[i] - gain * truth.data[i]) / hdr.standard_error.data[i];
    sum2 += z * z;
    ++n;
  }
  const double spread = std::sqrt(sum2 / double(n));
  EXPECT_GT(spread, 0.85);
  EXPECT_LT(spread, 1.15);
}

TEST(HdrMerge, CalibratedResponseRecoversRadianceUpToScale) {
  // An 8-bit camera with a gamma-2.2 response that the merge is not told about.
  const fs::path dir = scratch_dir("merge-calibrate");
  const ImageRgb truth = spot_radiance(Spot{});
  const std::vector<double> exposures = {0.25, 1, 4, 16, 64};
  ImageSet set;
  for (std::size_t k = 0; k < exposures.size(); ++k) {
    RawImage image(64, 64, 255);
    for (std::size_t i = 0; i < truth.data.size(); ++i) {
      const double linear = std::clamp(truth.data[i] * exposures[k] * 0.2, 0.0, 1.0);
      image.data[i] = std::uint16_t(std::lround(std::pow(linear, 1 / 2.2) * 255));
    }
    const std::string name = "g" + std::to_string(k) + ".png";
    write_png(dir / name, image);
    set.images.push_back({name, exposures[k]});
  }
  const HdrResult hdr = merge_brackets(set, Response::kCalibrate, std::nullopt, dir);
  ASSERT_TRUE(hdr.response.has_value());
  EXPECT_EQ(hdr.response->kind, Response::kCalibrate);
  std::vector<double> ratios;
  for (std::size_t i = 0; i < truth.data.size(); ++i) {
    if (hdr.mask[i] == PixelMask::kValid) ratios.push_back(hdr.radiance.data[i] / truth.data[i]);
  }
  ASSERT_GT(ratios.size(), truth.data.size() * 9 / 10);
  std::sort(ratios.begin(), ratios.end());
  const double median = ratios[ratios.size() / 2];
  // Debevec's curve is smoothed and sampled at 70 points: a few percent, not quantisation.
  EXPECT_GT(ratios[ratios.size() / 20] / median, 0.85);
  EXPECT_LT(ratios[ratios.size() * 19 / 20] / median, 1.15);
}

TEST(HdrMerge, CalibrateRejectsSixteenBitBrackets) {
  const fs::path dir = scratch_dir("merge-calibrate16");
  const ImageSet set = write_brackets(dir, "b", spot_radiance(Spot{}), StackSpec{});
  try {
    merge_brackets(set, Response::kCalibrate, std::nullopt, dir);
    FAIL() << "expected lucent::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("8-bit"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("b_0.png"), std::string::npos) << e.what();
  }
}

TEST(HdrMerge, HdrInputMasksNonFinitePixels) {
  const fs::path dir = scratch_dir("merge-hdr");
  ImageRgb image = spot_radiance(Spot{});
  image.at(3, 4, 0) = std::numeric_limits<float>::quiet_NaN();
  image.at(5, 6, 1) = std::numeric_limits<float>::infinity();
  image.at(7, 8, 2) = -std::numeric_limits<float>::infinity();
  lucent::testing::write_raw_exr(dir / "hdr.exr", image);  // NaN on purpose
  ImageSet set;
  set.hdr = "hdr.exr";
  const HdrResult hdr = merge_brackets(set, Response::kLinear, std::nullopt, dir);
  EXPECT_EQ(hdr.counts.non_finite, (std::array<std::int64_t, 3>{1, 1, 1}));
  EXPECT_EQ(hdr.mask_at(3, 4, 0), PixelMask::kNonFinite);
  EXPECT_EQ(hdr.mask_at(3, 4, 1), PixelMask::kValid);
  EXPECT_EQ(hdr.radiance.at(3, 4, 0), 0.0f);
  EXPECT_EQ(hdr.noise.source, "neighbours");
  for (float v : hdr.standard_error.data) EXPECT_TRUE(std::isfinite(v));
}

// ----------------------------------------------------------------------------------------------
// Beam detection

TEST(BeamPoint, FindsAnOffCentreSymmetricSpotToFiveHundredthsOfAPixel) {
  for (const auto& [cx, cy] : std::vector<std::pair<double, double>>{
           {30.3, 33.7}, {20.5, 40.5}, {41.13, 22.87}, {32.0, 32.0}, {27.77, 35.25}}) {
    Spot spot;
    spot.cx = cx;
    spot.cy = cy;
    const BeamPoint beam = find_beam_point(as_measured(spot_radiance(spot)), "test");
    EXPECT_NEAR(beam.px[0], cx, 0.05) << cx << ", " << cy;
    EXPECT_NEAR(beam.px[1], cy, 0.05) << cx << ", " << cy;
    EXPECT_GT(beam.region_pixels, 9);
  }
}

TEST(BeamPoint, SaturatedCoreCountsAsTheBrightest) {
  Spot spot;
  spot.cx = 35.4;
  spot.cy = 28.6;
  HdrResult hdr = as_measured(spot_radiance(spot));
  // Mask the core as saturated (and, elsewhere, one stray hot pixel brighter than anything
  // measured).
  int saturated = 0;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      if (spot_value(spot, x, y, 0) > 1.5) {
        for (int c = 0; c < 3; ++c)
          hdr.mask[(std::size_t(y) * 64 + x) * 3 + c] = PixelMask::kSaturated;
        ++saturated;
      }
    }
  }
  ASSERT_GT(saturated, 4);
  const BeamPoint beam = find_beam_point(hdr, "test");
  EXPECT_EQ(beam.saturated_pixels, saturated);
  EXPECT_NEAR(beam.px[0], spot.cx, 0.1);
  EXPECT_NEAR(beam.px[1], spot.cy, 0.1);
}

TEST(BeamPoint, UnresolvedSpikeDoesNotPinTheCentroid) {
  // Single scattering lands in the one pixel that holds the entry point: here a spike ten times the
  // peak of the diffuse light, which alone would put the centroid at that pixel's centre.
  for (const auto& [cx, cy] :
       std::vector<std::pair<double, double>>{{32.0, 32.0}, {30.3, 33.7}, {41.13, 22.87}}) {
    Spot spot;
    spot.cx = cx;
    spot.cy = cy;
    ImageRgb image = spot_radiance(spot);
    for (int c = 0; c < 3; ++c) image.at(int(cx), int(cy), c) *= 10;
    const BeamPoint beam = find_beam_point(as_measured(image), "spike");
    EXPECT_TRUE(beam.spike_capped);
    EXPECT_NEAR(beam.px[0], cx, 0.05) << cx << ", " << cy;
    EXPECT_NEAR(beam.px[1], cy, 0.05) << cx << ", " << cy;
  }
  BeamDetectionOptions never;
  never.spike_ratio = 0;
  Spot corner;
  corner.cx = corner.cy = 32.0;
  ImageRgb image = spot_radiance(corner);
  for (int c = 0; c < 3; ++c) image.at(32, 32, c) *= 10;
  EXPECT_NEAR(find_beam_point(as_measured(image), "spike", never).px[0], 32.5, 1e-9);
}

TEST(BeamPoint, FlatImageHasNoBeam) {
  ImageRgb flat(64, 64, 1.0f);
  std::mt19937_64 rng(3);
  std::normal_distribution<float> gauss(0, 0.01f);
  for (float& v : flat.data) v += gauss(rng);
  EXPECT_THROW(find_beam_point(as_measured(flat), "flat"), Error);
  EXPECT_THROW(find_beam_point(as_measured(ImageRgb(64, 64, 1.0f)), "flat"), Error);
}

// ----------------------------------------------------------------------------------------------
// Radial binning and 2D samples

TEST(RadialBinning, LinearAndLogEdges) {
  RadialBinning binning;
  binning.bins = 10;
  binning.radius_mm = 3.0;
  const auto linear = radial_bin_edges_mm(binning, 0.1);
  ASSERT_EQ(linear.size(), 11u);
  EXPECT_EQ(linear.front(), 0.0);
  EXPECT_DOUBLE_EQ(linear[1], 0.3);
  EXPECT_EQ(linear.back(), 3.0);
  binning.log_bins = true;
  const auto log = radial_bin_edges_mm(binning, 0.1);
  ASSERT_EQ(log.size(), 11u);
  EXPECT_EQ(log[0], 0.0);
  EXPECT_DOUBLE_EQ(log[1], 0.05);  // half a pixel pitch
  EXPECT_EQ(log.back(), 3.0);
  for (std::size_t i = 2; i < log.size(); ++i) {
    EXPECT_NEAR(log[i] / log[i - 1], std::pow(3.0 / 0.05, 1.0 / 9), 1e-12) << i;
  }
  binning.radius_mm = 0.04;
  EXPECT_THROW(radial_bin_edges_mm(binning, 0.1), Error);
  binning.bins = 0;
  EXPECT_THROW(radial_bin_edges_mm(binning, 0.1), Error);
}

TEST(RadialBinning, CountsRangesAndValues) {
  // A uniform image around (32, 32) px: each bin's count is the number of pixel centres in its
  // annulus, its value the uniform value, its r_mm the mean distance of those centres.
  HdrResult hdr = as_measured(ImageRgb(64, 64, 2.0f));
  hdr.mask[(std::size_t(32) * 64 + 33) * 3 + 1] = PixelMask::kSaturated;  // one masked pixel, green
  RadialBinning binning;
  binning.bins = 20;
  binning.radius_mm = 2.0;
  const double pitch = 0.1;
  const std::array<double, 2> centre{32.0, 32.0};
  const RadialProfile profile = bin_radial_profile(hdr, centre, pitch, {kPi, kPi, kPi}, binning);
  const auto edges = radial_bin_edges_mm(binning, pitch);
  std::vector<std::int64_t> expected(20, 0);
  std::vector<double> sum_r(20, 0.0);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      const double r = pitch * std::hypot(x + 0.5 - 32, y + 0.5 - 32);
      if (r > 2.0) continue;
      const std::size_t b = std::min<std::size_t>(std::size_t(r / 0.1), 19);
      ++expected[b];
      sum_r[b] += r;
    }
  }
  std::size_t kept = 0;
  for (std::size_t b = 0; b < 20; ++b) kept += expected[b] >= 3;
  ASSERT_EQ(profile.size(), kept);
  for (std::size_t i = 0; i < profile.size(); ++i) {
    const std::size_t b = std::size_t(std::lround(profile.r_inner_mm[i] / 0.1));
    EXPECT_DOUBLE_EQ(profile.r_inner_mm[i], edges[b]);
    EXPECT_DOUBLE_EQ(profile.r_outer_mm[i], edges[b + 1]);
    EXPECT_EQ(profile.count[0][i], expected[b]);
    EXPECT_NEAR(profile.r_mm[i], sum_r[b] / double(expected[b]), 1e-12);
    EXPECT_GE(profile.r_mm[i], profile.r_inner_mm[i]);
    EXPECT_LE(profile.r_mm[i], profile.r_outer_mm[i]);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(profile.value[c][i], 2 * kPi, 1e-6);
      EXPECT_NEAR(profile.standard_error[c][i], 0.0, 1e-6);
    }
  }
  // The masked green pixel at distance 0.1 mm (r = hypot(1.5, 0.5) px) is missing from green only.
  const std::size_t b = 1;
  for (std::size_t i = 0; i < profile.size(); ++i) {
    if (std::lround(profile.r_inner_mm[i] / 0.1) == long(b)) {
      EXPECT_EQ(profile.count[1][i], expected[b] - 1);
      EXPECT_EQ(profile.count[0][i], expected[b]);
    }
  }
}

TEST(RadialBinning, SamplesWithinRadius) {
  HdrResult hdr = as_measured(spot_radiance(Spot{}));
  hdr.mask[(std::size_t(33) * 64 + 30) * 3 + 2] = PixelMask::kBlack;
  const Samples2d s = sample_2d_profile(hdr, {30.3, 33.7}, 0.1, {1, 1, 1}, 1.0);
  std::size_t expected = 0;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) expected += std::hypot(x + 0.5 - 30.3, y + 0.5 - 33.7) <= 10.0;
  }
  EXPECT_EQ(s.size(), expected - 1);
  for (std::size_t i = 0; i < s.size(); ++i) {
    EXPECT_LE(std::hypot(s.x_mm[i], s.y_mm[i]), 1.0 + 1e-12);
    const int x = int(std::lround(s.x_mm[i] / 0.1 + 30.3 - 0.5));
    const int y = int(std::lround(s.y_mm[i] / 0.1 + 33.7 - 0.5));
    EXPECT_FLOAT_EQ(float(s.value[0][i]), hdr.radiance.at(x, y, 0));
  }
}

// ----------------------------------------------------------------------------------------------
// Profile files

Profile example_profile() {
  Profile p;
  p.calibrated = true;
  p.capture = "captures/milk.json";
  p.pixel_pitch_mm = 0.05;
  p.incidence_polar_deg = 30;
  p.incidence_azimuth_deg = 90;
  p.view_deg = 5;
  p.beam_point_px = {31.25, 32.0625};
  p.beam_point_source = "detected";
  p.beam_power = std::array<double, 3>{1.5, 1.25, 0.1 + 0.2};
  p.radial.r_mm = {0.1, 0.25};
  p.radial.r_inner_mm = {0.05, 0.2};
  p.radial.r_outer_mm = {0.2, 0.3};
  p.radial.value = {{{1.0 / 3, 0.2}, {0.5, 0.25}, {0.125, 1e-300}}};
  p.radial.standard_error = {{{0.01, 0.02}, {0.03, 0.04}, {0.05, 0.06}}};
  p.radial.count = {{{3, 4}, {5, 6}, {7, 8}}};
  Samples2d s;
  s.x_mm = {-0.1, 0.1};
  s.y_mm = {0.0, 0.05};
  s.value = {{{1, 2}, {3, 4}, {5, 6}}};
  s.standard_error = {{{0.1, 0.2}, {0.3, 0.4}, {0.5, 0.6}}};
  p.samples_2d = s;
  p.masked.saturated = {1, 2, 3};
  p.masked.black = {0, 0, 9};
  p.masked.non_finite = {4, 5, 6};
  p.provenance = {{"tool", "lucent acquire"}};
  return p;
}

TEST(ProfileFile, JsonRoundTripIsExact) {
  const fs::path dir = scratch_dir("profile-roundtrip");
  const Profile p = example_profile();
  write_profile(dir / "profile.json", p);
  const Profile q = read_profile(dir / "profile.json");
  EXPECT_EQ(profile_to_json(q), profile_to_json(p));
  EXPECT_EQ(q.radial.value[0][0], 1.0 / 3);  // bit-exact doubles
  EXPECT_EQ(q.radial.value[2][1], 1e-300);
  ASSERT_TRUE(q.samples_2d.has_value());
  EXPECT_EQ(q.samples_2d->y_mm[1], 0.05);
  EXPECT_EQ(q.masked.non_finite[2], 6);
  // The file describes itself: format and version first.
  std::ifstream in(dir / "profile.json");
  std::string first, second, third;
  std::getline(in, first);
  std::getline(in, second);
  std::getline(in, third);
  EXPECT_EQ(second, "  \"format\": \"lucent-profile\",");
  EXPECT_EQ(third, "  \"version\": 1,");
  // Uncalibrated: null power, relative units.
  Profile relative = p;
  relative.calibrated = false;
  relative.beam_power.reset();
  relative.samples_2d.reset();
  const json doc = profile_to_json(relative);
  EXPECT_TRUE(doc["beam_power"].is_null());
  EXPECT_EQ(doc["units"], "relative (pi L, uncalibrated)");
  EXPECT_FALSE(doc.contains("samples_2d"));
  EXPECT_EQ(profile_to_json(profile_from_json(doc, "x")), doc);
}

TEST(ProfileFile, ReaderRejectsBadDocumentsNamingTheField) {
  const json good = profile_to_json(example_profile());
  const auto expect_rejected = [&](json doc, const std::string& field) {
    try {
      profile_from_json(doc, "bad.json");
      ADD_FAILURE() << "accepted a document with a bad " << field;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("bad.json: field '" + field + "'"), std::string::npos)
          << e.what();
    }
  };
  json doc = good;
  doc["format"] = "lucent-material";
  expect_rejected(doc, "format");
  doc = good;
  doc["version"] = 2;
  expect_rejected(doc, "version");
  doc = good;
  doc["radial"]["value"][1].erase(1);
  expect_rejected(doc, "radial.value[1]");
  doc = good;
  doc["radial"]["r_outer_mm"].push_back(1.0);
  expect_rejected(doc, "radial.r_outer_mm");
  doc = good;
  doc["radial"]["count"][2] = {1};
  expect_rejected(doc, "radial.count[2]");
  doc = good;
  doc["radial"]["standard_error"].erase(2);
  expect_rejected(doc, "radial.standard_error");
  doc = good;
  doc["samples_2d"]["y_mm"].push_back(0.0);
  expect_rejected(doc, "samples_2d.y_mm");
  doc = good;
  doc["masked"]["black"] = {1, 2};
  expect_rejected(doc, "masked.black");
  doc = good;
  doc["beam_power"] = nullptr;
  expect_rejected(doc, "beam_power");  // calibrated without a power
  doc = good;
  doc["units"] = "relative (pi L, uncalibrated)";
  expect_rejected(doc, "units");
  doc = good;
  doc["beam_point_px"] = {1.0};
  expect_rejected(doc, "beam_point_px");
  doc = good;
  doc["colour"] = "red";
  expect_rejected(doc, "colour");

  const fs::path dir = scratch_dir("profile-bad");
  std::ofstream(dir / "broken.json") << "{\"format\": ";
  EXPECT_THROW(read_profile(dir / "broken.json"), Error);
  EXPECT_THROW(read_profile(dir / "absent.json"), Error);
}

TEST(ProfileFile, CsvHasTheFitHeaderAndFullPrecision) {
  const std::string csv = profile_csv(example_profile());
  std::istringstream in(csv);
  std::string header, row;
  std::getline(in, header);
  EXPECT_EQ(header, "r_mm,R_r,R_g,R_b,se_r,se_g,se_b,n_r,n_g,n_b");
  std::getline(in, row);
  EXPECT_EQ(row,
            "0.10000000000000001,0.33333333333333331,0.5,0.125,0.01,0.029999999999999999,"
            "0.050000000000000003,3,5,7");
}

// ----------------------------------------------------------------------------------------------
// The whole job

struct SyntheticCapture {
  fs::path dir, capture;
  Spot spot;
  double power = 2.0;
};

// 16-bit linear brackets of the spot; optionally a white reference of power `power`.
SyntheticCapture make_synthetic(const std::string& name, bool white, double polar_deg = 0) {
  SyntheticCapture s;
  s.dir = scratch_dir(name);
  const ImageSet sample = write_brackets(s.dir, "sample", spot_radiance(s.spot), StackSpec{});
  Capture capture = make_capture(sample, s.spot.pitch_mm, Response::kLinear);
  capture.incidence_polar_deg = polar_deg;
  if (white) {
    StackSpec spec;
    spec.exposures_s = {0.5, 2, 8};
    WhiteReference reference;
    reference.reflectance = 0.9;
    reference.images = write_brackets(s.dir, "white",
                                      white_radiance(64, s.spot.pitch_mm, s.power, 0.9, 0.4), spec);
    capture.white_reference = reference;
  }
  s.capture = write_capture_file(s.dir, capture);
  return s;
}

TEST(Acquire, CalibratedProfileIsPiLOverBeamPower) {
  const SyntheticCapture s = make_synthetic("acquire-calibrated", true);
  const fs::path out = s.dir / "out";
  AcquireOptions options;
  options.bins = 40;
  const AcquireSummary summary = run_acquire(s.capture, out, options);
  ASSERT_TRUE(summary.calibrated);
  ASSERT_TRUE(summary.beam_power.has_value());
  // In the capture's units (code fraction per second): the camera gain 0.2 times the power.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR((*summary.beam_power)[c], 0.2 * s.power, 2e-4) << c;
  EXPECT_EQ(summary.beam_power_source, "white reference");
  for (const char* name : {"capture.exr", "profile.json", "profile.csv", "acquire.png"}) {
    EXPECT_TRUE(fs::is_regular_file(out / name)) << name;
  }

  const Profile profile = read_profile(out / "profile.json");
  EXPECT_TRUE(profile.calibrated);
  EXPECT_EQ(profile.units(), "per mm^2 (pi L / beam power)");
  EXPECT_FALSE(profile.samples_2d.has_value());
  ASSERT_GT(profile.radial.size(), 20u);
  // Each bin against pi L / P averaged over the same pixel centres.
  const auto& bp = profile.beam_point_px;
  for (std::size_t i = 0; i < profile.radial.size(); ++i) {
    const bool last = i + 1 == profile.radial.size();
    for (int c = 0; c < 3; ++c) {
      double sum = 0;
      std::int64_t n = 0;
      for (int y = 0; y < 64; ++y) {
        for (int x = 0; x < 64; ++x) {
          const double r = s.spot.pitch_mm * std::hypot(x + 0.5 - bp[0], y + 0.5 - bp[1]);
          if (r < profile.radial.r_inner_mm[i] || r > profile.radial.r_outer_mm[i]) continue;
          if (r == profile.radial.r_outer_mm[i] && !last) continue;
          sum += kPi * spot_value(s.spot, x, y, c) / s.power;
          ++n;
        }
      }
      ASSERT_EQ(profile.radial.count[c][i], n) << "bin " << i;
      EXPECT_NEAR(profile.radial.value[c][i], sum / double(n), 0.01 * sum / double(n))
          << "bin " << i << " channel " << c;
      EXPECT_GT(profile.radial.standard_error[c][i], 0.0);
    }
  }
  // The HDR image is radiance per unit power.
  const ImageRgb exr = read_exr(out / "capture.exr");
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(exr.at(10, 50, c), spot_value(s.spot, 10, 50, c) / s.power,
                0.01 * spot_value(s.spot, 10, 50, c) / s.power);
  }
  // The CSV is the radial table.
  std::ifstream csv(out / "profile.csv");
  std::string line;
  std::size_t rows = 0;
  while (std::getline(csv, line)) rows += !line.empty();
  EXPECT_EQ(rows, profile.radial.size() + 1);
}

TEST(Acquire, DetectedEntryPointIsSubPixelAccurate) {
  const SyntheticCapture s = make_synthetic("acquire-detect", false);
  const AcquireSummary summary = run_acquire(s.capture, s.dir / "out");
  EXPECT_EQ(summary.beam_point_source, "detected");
  EXPECT_NEAR(summary.beam_point_px[0], s.spot.cx, 0.05);
  EXPECT_NEAR(summary.beam_point_px[1], s.spot.cy, 0.05);
  // Default radius: to the nearest image edge.
  EXPECT_NEAR(summary.radius_mm, s.spot.pitch_mm * (64 - s.spot.cy), 0.01);
}

TEST(Acquire, UncalibratedProfileIsRelativeAndSaysSo) {
  const SyntheticCapture s = make_synthetic("acquire-relative", false);
  AcquireOptions options;
  options.bins = 30;
  const AcquireSummary summary = run_acquire(s.capture, s.dir / "out", options);
  EXPECT_FALSE(summary.calibrated);
  EXPECT_FALSE(summary.beam_power.has_value());
  const Profile profile = read_profile(s.dir / "out" / "profile.json");
  EXPECT_FALSE(profile.calibrated);
  EXPECT_FALSE(profile.beam_power.has_value());
  EXPECT_EQ(profile.units(), "relative (pi L, uncalibrated)");
  // value = pi L in the capture's units (code fraction per second: the camera gain 0.2 times L),
  // at the bin's mean radius within 1% (narrow bins, far from the cusp).
  for (std::size_t i = 0; i < profile.radial.size(); ++i) {
    if (profile.radial.r_mm[i] < 1.0) continue;
    const double expected = kPi * 0.2 * falloff(profile.radial.r_mm[i]);
    EXPECT_NEAR(profile.radial.value[0][i], expected, 0.01 * expected);
  }
}

TEST(Acquire, BeamPowerFromTheCaptureFile) {
  SyntheticCapture s = make_synthetic("acquire-power", false);
  Capture capture = read_capture(s.capture);
  capture.beam_power = 4.0;
  write_capture(s.capture, capture);
  const AcquireSummary summary = run_acquire(s.capture, s.dir / "out");
  ASSERT_TRUE(summary.calibrated);
  EXPECT_EQ(summary.beam_power_source, "capture");
  const Profile profile = read_profile(s.dir / "out" / "profile.json");
  for (std::size_t i = 0; i < profile.radial.size(); ++i) {
    if (profile.radial.r_mm[i] < 1.0) continue;
    const double expected = kPi * 0.2 * 0.6 * falloff(profile.radial.r_mm[i]) / 4;
    EXPECT_NEAR(profile.radial.value[1][i], expected, 0.01 * expected);
  }
}

TEST(Acquire, GivenBeamPointOverridesDetection) {
  SyntheticCapture s = make_synthetic("acquire-given", false);
  Capture capture = read_capture(s.capture);
  capture.beam_point_px = std::array<double, 2>{25.0, 30.5};
  write_capture(s.capture, capture);
  const AcquireSummary summary = run_acquire(s.capture, s.dir / "out");
  EXPECT_EQ(summary.beam_point_source, "given");
  EXPECT_EQ(summary.beam_point_px, (std::array<double, 2>{25.0, 30.5}));
  const Profile profile = read_profile(s.dir / "out" / "profile.json");
  EXPECT_EQ(profile.beam_point_source, "given");
  EXPECT_EQ(profile.beam_point_px, (std::array<double, 2>{25.0, 30.5}));
  EXPECT_FALSE(profile.provenance.contains("beam_detection"));

  capture.beam_point_px = std::array<double, 2>{70.0, 30.5};  // outside the 64x64 image
  write_capture(s.capture, capture);
  expect_acquire_fails(s.capture, s.dir / "out2", {"beam_point_px"});
}

TEST(Acquire, ObliqueCaptureWritesTwoDimensionalSamples) {
  const SyntheticCapture s = make_synthetic("acquire-oblique", false, 45);
  AcquireOptions options;
  options.radius_mm = 1.5;
  options.log_bins = true;
  options.bins = 20;
  const AcquireSummary summary = run_acquire(s.capture, s.dir / "out", options);
  const Profile profile = read_profile(s.dir / "out" / "profile.json");
  EXPECT_EQ(profile.incidence_polar_deg, 45);
  ASSERT_TRUE(profile.samples_2d.has_value());
  const auto& bp = profile.beam_point_px;
  std::size_t expected = 0;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x)
      expected += 0.1 * std::hypot(x + 0.5 - bp[0], y + 0.5 - bp[1]) <= 1.5;
  }
  EXPECT_EQ(profile.samples_2d->size(), expected);
  EXPECT_EQ(summary.samples_2d, int(expected));
  for (std::size_t i = 0; i < profile.samples_2d->size(); ++i) {
    const double x = profile.samples_2d->x_mm[i] / 0.1 + bp[0],
                 y = profile.samples_2d->y_mm[i] / 0.1 + bp[1];
    const double r_mm = 0.1 * std::hypot(x - s.spot.cx, y - s.spot.cy);
    const double expected = kPi * 0.2 * falloff(r_mm);  // uncalibrated: pi L x camera gain
    EXPECT_NEAR(profile.samples_2d->value[0][i], expected, 2e-3 * expected);
    EXPECT_GT(profile.samples_2d->standard_error[0][i], 0.0);
  }
  // Log bins: consecutive outer edges in a constant ratio.
  const auto& outer = profile.radial.r_outer_mm;
  ASSERT_GT(outer.size(), 5u);
  const double ratio = std::pow(1.5 / 0.05, 1.0 / 19);
  for (std::size_t i = 1; i < outer.size(); ++i) {
    const double steps = std::log(outer[i] / outer[i - 1]) / std::log(ratio);
    EXPECT_NEAR(steps, std::round(steps), 1e-9);
  }
}

TEST(Acquire, ExistingOutputFolderIsReplacedWholeOnlyWhenAllowed) {
  const SyntheticCapture s = make_synthetic("acquire-existing", false);
  const fs::path out = s.dir / "out";
  fs::create_directories(out);
  std::ofstream(out / "notes.txt") << "mine";
  std::ofstream(out / "profile.csv") << "old";
  // Refused by default: the folder is left exactly as it was.
  EXPECT_THROW(run_acquire(s.capture, out), Error);
  EXPECT_EQ(listing(out), (std::set<std::string>{"notes.txt", "profile.csv"}));
  // Allowed (the CLI's --force): replaced whole, no stale file of the earlier folder survives.
  set_replace_folders(true);
  run_acquire(s.capture, out);
  set_replace_folders(false);
  EXPECT_EQ(listing(out),
            (std::set<std::string>{"acquire.png", "capture.exr", "profile.csv", "profile.json"}));
  std::ifstream csv(out / "profile.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header, "r_mm,R_r,R_g,R_b,se_r,se_g,se_b,n_r,n_g,n_b");
  const RawImage png = read_raw_image(out / "acquire.png");
  EXPECT_GE(png.width, 512);
}

// ----------------------------------------------------------------------------------------------
// Bad input: one clear line, and no output folder (or an existing one unchanged).

TEST(AcquireBadInput, MissingImage) {
  const fs::path dir = scratch_dir("bad-missing");
  ImageSet set = write_brackets(dir, "b", spot_radiance(Spot{}), StackSpec{});
  set.images[2].path = "missing.png";
  expect_acquire_fails(write_capture_file(dir, make_capture(set, 0.1, Response::kLinear)),
                       dir / "out", {"missing.png"});
}

TEST(AcquireBadInput, MismatchedImageSizes) {
  const fs::path dir = scratch_dir("bad-sizes");
  const ImageSet set = write_brackets(dir, "b", spot_radiance(Spot{}), StackSpec{});
  Spot small;
  small.height = 60;
  write_png(dir / "b_1.png",
            exact_exposure(spot_radiance(small), 4, 0.2, 65535, Response::kLinear));
  expect_acquire_fails(write_capture_file(dir, make_capture(set, 0.1, Response::kLinear)),
                       dir / "out", {"b_1.png", "64x60", "64x64"});
}

TEST(AcquireBadInput, NonMonotonicExposures) {
  const fs::path dir = scratch_dir("bad-order");
  ImageSet set = write_brackets(dir, "b", spot_radiance(Spot{}), StackSpec{});
  std::swap(set.images[1].exposure_s, set.images[2].exposure_s);
  expect_acquire_fails(write_capture_file(dir, make_capture(set, 0.1, Response::kLinear)),
                       dir / "out", {"images[2].exposure_s", "capture.json"});
}

TEST(AcquireBadInput, DuplicateExposures) {
  const fs::path dir = scratch_dir("bad-duplicate");
  ImageSet set = write_brackets(dir, "b", spot_radiance(Spot{}), StackSpec{});
  set.images[1].exposure_s = set.images[0].exposure_s;
  expect_acquire_fails(write_capture_file(dir, make_capture(set, 0.1, Response::kLinear)),
                       dir / "out", {"images[1].exposure_s"});
}

TEST(AcquireBadInput, AllSaturatedStack) {
  const fs::path dir = scratch_dir("bad-saturated");
  const ImageSet set = write_brackets(dir, "b", ImageRgb(64, 64, 100.0f), StackSpec{});
  expect_acquire_fails(write_capture_file(dir, make_capture(set, 0.1, Response::kLinear)),
                       dir / "out", {"all-saturated", "b_0.png"});
}

TEST(AcquireBadInput, AllBlackStack) {
  const fs::path dir = scratch_dir("bad-black");
  const ImageSet set = write_brackets(dir, "b", ImageRgb(64, 64, 0.0f), StackSpec{});
  expect_acquire_fails(write_capture_file(dir, make_capture(set, 0.1, Response::kLinear)),
                       dir / "out", {"all-black", "b_0.png"});
}

TEST(AcquireBadInput, NoBeamFound) {
  const fs::path dir = scratch_dir("bad-flat");
  const ImageSet set = write_brackets(dir, "b", ImageRgb(64, 64, 0.05f), StackSpec{});
  expect_acquire_fails(write_capture_file(dir, make_capture(set, 0.1, Response::kLinear)),
                       dir / "out", {"no beam found", "b_0.png"});
}

TEST(AcquireBadInput, PixelPitchNotPositive) {
  const fs::path dir = scratch_dir("bad-pitch");
  const ImageSet set = write_brackets(dir, "b", spot_radiance(Spot{}), StackSpec{});
  for (double pitch : {0.0, -0.1}) {
    expect_acquire_fails(write_capture_file(dir, make_capture(set, pitch, Response::kLinear)),
                         dir / "out", {"pixel_pitch_mm"});
  }
}

TEST(AcquireBadInput, UnreadableExr) {
  const fs::path dir = scratch_dir("bad-exr");
  std::ofstream(dir / "sample.exr") << "this is not an OpenEXR file\n";
  ImageSet set;
  set.hdr = "sample.exr";
  expect_acquire_fails(write_capture_file(dir, make_capture(set, 0.1, Response::kLinear)),
                       dir / "out", {"sample.exr"});
}

TEST(AcquireBadInput, NonFinitePixelsAreMaskedAndReportedUnlessEveryPixelIs) {
  const fs::path dir = scratch_dir("bad-nan");
  ImageRgb image = spot_radiance(Spot{});
  for (int x = 0; x < 6; ++x) image.at(x, 60, 1) = std::numeric_limits<float>::quiet_NaN();
  image.at(50, 10, 0) = std::numeric_limits<float>::infinity();
  lucent::testing::write_raw_exr(dir / "sample.exr", image);  // NaN on purpose
  ImageSet set;
  set.hdr = "sample.exr";
  const fs::path capture = write_capture_file(dir, make_capture(set, 0.1, Response::kLinear));
  const AcquireSummary summary = run_acquire(capture, dir / "out");
  EXPECT_EQ(summary.masked.non_finite, (std::array<std::int64_t, 3>{1, 6, 0}));
  const Profile profile = read_profile(dir / "out" / "profile.json");
  EXPECT_EQ(profile.masked.non_finite, (std::array<std::int64_t, 3>{1, 6, 0}));
  EXPECT_NEAR(summary.beam_point_px[0], 30.3, 0.05);

  lucent::testing::write_raw_exr(dir / "nan.exr",
                                 ImageRgb(64, 64, std::numeric_limits<float>::quiet_NaN()));
  set.hdr = "nan.exr";
  expect_acquire_fails(
      write_capture_file(dir, make_capture(set, 0.1, Response::kLinear), "nan.json"),
      dir / "out-nan", {"nan.exr", "no finite pixels"});
}

TEST(AcquireBadInput, FailureLeavesAnExistingOutputFolderUnchanged) {
  const fs::path dir = scratch_dir("bad-existing");
  const fs::path out = dir / "out";
  fs::create_directories(out);
  std::ofstream(out / "profile.json") << "{\"keep\": true}";
  const ImageSet set = write_brackets(dir, "b", ImageRgb(64, 64, 0.0f), StackSpec{});
  set_replace_folders(true);  // allowed to replace it, but the run fails: the folder must survive
  expect_acquire_fails(write_capture_file(dir, make_capture(set, 0.1, Response::kLinear)), out,
                       {"all-black"});
  set_replace_folders(false);
  std::ifstream in(out / "profile.json");
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "{\"keep\": true}");
}

}  // namespace
}  // namespace lucent::acquire
