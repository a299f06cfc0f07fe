// Tests of `lucent acquire` as a whole (acquire/src/acquire.cpp, profile files): profile files,
// the whole job, and bad input, on the synthetic captures of acquire_fixtures.h.
#include "acquire_fixtures.h"

namespace lucent::acquire {
namespace {

using namespace fixtures;
namespace fs = std::filesystem;
using nlohmann::json;

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

// The first line of `csv` that is not a # comment.
std::string csv_header(std::istream& in) {
  std::string line;
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '#') return line;
  return "";
}

TEST(ProfileFile, CsvHasTheFitHeaderAndFullPrecision) {
  const std::string csv = profile_csv(example_profile());
  std::istringstream in(csv);
  // The one radial schema (lucent fit reads it unchanged): key=value comments, annuli, counts.
  EXPECT_NE(csv.find("# format=lucent-radial-csv"), std::string::npos) << csv;
  EXPECT_NE(csv.find("quantity=radiance"), std::string::npos) << csv;
  EXPECT_NE(csv.find(" calibrated="), std::string::npos) << csv;
  EXPECT_NE(csv.find(" pixel_mm="), std::string::npos) << csv;
  const std::string header = csv_header(in);
  EXPECT_EQ(header, "r_mm,r_inner_mm,r_outer_mm,R_r,R_g,R_b,se_r,se_g,se_b,n_r,n_g,n_b");
  std::string row;
  std::getline(in, row);
  EXPECT_EQ(row.substr(0, row.find(',')), "0.10000000000000001");
  EXPECT_NE(row.find(",0.33333333333333331,0.5,0.125,0.01,0.029999999999999999,"
                     "0.050000000000000003,3,5,7"),
            std::string::npos)
      << row;
}

// ----------------------------------------------------------------------------------------------
// The whole job

struct SyntheticCapture {
  fs::path dir, capture;
  Spot spot;
  // The beam's power, capture units: enough that the spot's light (its pi L integrated over the
  // field) stays below what came in; at 2 it was 9 times that, and acquire now refuses a white
  // reference darker than the sample.
  double power = 20.0;
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
    spec.exposures_s = {0.05, 0.2, 0.8};
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
  for (int c = 0; c < 3; ++c) EXPECT_NEAR((*summary.beam_power)[c], 0.2 * s.power, 1e-4 * s.power) << c;
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
  const imaging::ImageRgb exr = imaging::read_exr(out / "capture.exr");
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(exr.at(10, 50, c), spot_value(s.spot, 10, 50, c) / s.power,
                0.01 * spot_value(s.spot, 10, 50, c) / s.power);
  }
  // The CSV is the radial table (after its # lines).
  std::ifstream csv(out / "profile.csv");
  std::string line;
  std::size_t rows = 0;
  while (std::getline(csv, line)) rows += !line.empty() && line[0] != '#';
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
  EXPECT_EQ(csv_header(csv), "r_mm,r_inner_mm,r_outer_mm,R_r,R_g,R_b,se_r,se_g,se_b,n_r,n_g,n_b");
  const imaging::RawImage png = imaging::read_raw_image(out / "acquire.png");
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
  imaging::write_png(dir / "b_1.png",
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
  const ImageSet set = write_brackets(dir, "b", imaging::ImageRgb(64, 64, 100.0f), StackSpec{});
  expect_acquire_fails(write_capture_file(dir, make_capture(set, 0.1, Response::kLinear)),
                       dir / "out", {"all-saturated", "b_0.png"});
}

TEST(AcquireBadInput, AllBlackStack) {
  const fs::path dir = scratch_dir("bad-black");
  const ImageSet set = write_brackets(dir, "b", imaging::ImageRgb(64, 64, 0.0f), StackSpec{});
  expect_acquire_fails(write_capture_file(dir, make_capture(set, 0.1, Response::kLinear)),
                       dir / "out", {"all-black", "b_0.png"});
}

TEST(AcquireBadInput, NoBeamFound) {
  const fs::path dir = scratch_dir("bad-flat");
  const ImageSet set = write_brackets(dir, "b", imaging::ImageRgb(64, 64, 0.05f), StackSpec{});
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
  imaging::ImageRgb image = spot_radiance(Spot{});
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

  lucent::testing::write_raw_exr(
      dir / "nan.exr", imaging::ImageRgb(64, 64, std::numeric_limits<float>::quiet_NaN()));
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
  const ImageSet set = write_brackets(dir, "b", imaging::ImageRgb(64, 64, 0.0f), StackSpec{});
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
