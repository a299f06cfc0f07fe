// Tests of `lucent acquire`'s parts (acquire/src/hdr_merge.cpp, beam.cpp, profile.cpp): HDR
// merge, beam detection, radial binning and 2D samples, on the synthetic captures of
// acquire_fixtures.h.
#include "acquire_fixtures.h"
#include "lucent/acquire/beam.h"

#include <numbers>

namespace lucent::acquire {
namespace {

using namespace fixtures;
namespace fs = std::filesystem;
using nlohmann::json;

// ----------------------------------------------------------------------------------------------
// HDR merge

TEST(HdrMerge, LinearStackRecoversRadianceWithinQuantisation) {
  const fs::path dir = scratch_dir("merge-linear");
  const Spot spot;
  const imaging::ImageRgb truth = spot_radiance(spot);
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
  const imaging::ImageRgb truth = spot_radiance(Spot{});
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
  const imaging::ImageRgb truth = spot_radiance(spot);
  const StackSpec spec;
  const ImageSet set = write_brackets(dir, "b", truth, spec);
  const HdrResult hdr = merge_brackets(set, Response::kLinear, std::nullopt, dir);
  const imaging::RawImage shortest =
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
  imaging::ImageRgb truth = spot_radiance(Spot{});
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
  imaging::ImageRgb truth = spot_radiance(Spot{});
  // At the dark level: a measurement of no light (valid, ~0), not censored. Masking such pixels
  // kept only those that noise lifted above the dark level: a floor in faint profiles.
  truth.at(0, 0, 0) = truth.at(0, 0, 1) = truth.at(0, 0, 2) = 0.0f;
  StackSpec spec;
  spec.dark_offset = 0.01;  // a black level of 1% of the range in every bracket
  const ImageSet set = write_brackets(dir, "b", truth, spec);
  imaging::write_png(dir / "dark.png", exact_exposure(imaging::ImageRgb(64, 64, 0.0f), 1, spec.gain,
                                                      65535, Response::kLinear, spec.dark_offset));
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
  const imaging::ImageRgb truth = spot_radiance(Spot{});
  const double full_well = 40000, read_e = 4, gain = 0.2;
  const std::vector<double> exposures = {1, 4, 16, 64};
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss(0, 1);
  ImageSet set;
  for (std::size_t k = 0; k < exposures.size(); ++k) {
    imaging::RawImage image(64, 64, 65535);
    for (std::size_t i = 0; i < truth.data.size(); ++i) {
      const double electrons = truth.data[i] * exposures[k] * gain * full_well;
      const double noisy = electrons + std::sqrt(electrons + read_e * read_e) * gauss(rng);
      image.data[i] = std::uint16_t(std::lround(std::clamp(noisy / full_well, 0.0, 1.0) * 65535));
    }
    const std::string name = "n" + std::to_string(k) + ".png";
    imaging::write_png(dir / name, image);
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
  const imaging::ImageRgb truth = spot_radiance(Spot{});
  const std::vector<double> exposures = {0.25, 1, 4, 16, 64};
  ImageSet set;
  for (std::size_t k = 0; k < exposures.size(); ++k) {
    imaging::RawImage image(64, 64, 255);
    for (std::size_t i = 0; i < truth.data.size(); ++i) {
      const double linear = std::clamp(truth.data[i] * exposures[k] * 0.2, 0.0, 1.0);
      image.data[i] = std::uint16_t(std::lround(std::pow(linear, 1 / 2.2) * 255));
    }
    const std::string name = "g" + std::to_string(k) + ".png";
    imaging::write_png(dir / name, image);
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
  imaging::ImageRgb image = spot_radiance(Spot{});
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
    imaging::ImageRgb image = spot_radiance(spot);
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
  imaging::ImageRgb image = spot_radiance(corner);
  for (int c = 0; c < 3; ++c) image.at(32, 32, c) *= 10;
  EXPECT_NEAR(find_beam_point(as_measured(image), "spike", never).px[0], 32.5, 1e-9);
}

TEST(BeamPoint, FlatImageHasNoBeam) {
  imaging::ImageRgb flat(64, 64, 1.0f);
  std::mt19937_64 rng(3);
  std::normal_distribution<float> gauss(0, 0.01f);
  for (float& v : flat.data) v += gauss(rng);
  EXPECT_THROW(find_beam_point(as_measured(flat), "flat"), Error);
  EXPECT_THROW(find_beam_point(as_measured(imaging::ImageRgb(64, 64, 1.0f)), "flat"), Error);
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
  HdrResult hdr = as_measured(imaging::ImageRgb(64, 64, 2.0f));
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

}  // namespace
}  // namespace lucent::acquire

namespace lucent::testing {
namespace {

// The system response from an image of a spot (the white reference's, or --beam-image): a round
// Gaussian of sigma 0.5 mm on 0.1 mm pixels comes back as that Gaussian (unit integral, per mm^2)
// and its rms radius sqrt(2) sigma; an image without light gives nothing.
TEST(SystemResponseImage, AGaussianSpotIsItsOwnResponse) {
  const int n = 121;
  const double pixel = 0.1, sigma = 0.5, c = 60.5;  // the spot's centre, pixels
  std::vector<double> light(std::size_t(n) * n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double r2 = (std::pow(x + 0.5 - c, 2) + std::pow(y + 0.5 - c, 2)) * pixel * pixel;
      light[std::size_t(y) * n + x] = 7.0 * std::exp(-r2 / (2 * sigma * sigma));
    }
  const acquire::SystemResponse r = acquire::system_response(light, n, n, pixel);
  ASSERT_GT(r.r_mm.size(), 100u);
  double worst = 0;
  for (std::size_t i = 0; i < r.r_mm.size(); ++i) {
    const double want = std::exp(-r.r_mm[i] * r.r_mm[i] / (2 * sigma * sigma)) /
                        (2 * std::numbers::pi * sigma * sigma);
    if (r.r_mm[i] > 3 * sigma) break;
    // Rings of half a pixel average the pixels whose centres fall in them: the ring's radius is
    // its middle, good to ~ (pixel / sigma)^2 / 8 near the centre; 3% allowed.
    worst = std::max(worst, std::abs(r.value[i] / want - 1));
  }
  EXPECT_LT(worst, 0.03);
  EXPECT_NEAR(r.rms_mm, std::sqrt(2.0) * sigma, 0.01);
  std::fill(light.begin(), light.end(), 0.0);
  EXPECT_TRUE(acquire::system_response(light, n, n, pixel).r_mm.empty());
  std::fill(light.begin(), light.end(), -1.0);
  EXPECT_TRUE(acquire::system_response(light, n, n, pixel).r_mm.empty());
}

}  // namespace
}  // namespace lucent::testing

