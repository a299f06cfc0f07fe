// Camera RAW brackets end to end: `lucent simulate --bracket-format dng` writes a Bayer sensor's
// DNGs (black level, exposure time and ISO in each file, none of them in capture.json), `lucent
// acquire` reads them through LibRaw and `lucent fit` recovers the material the Monte Carlo
// transport was run with. Bad RAW captures are refused with one line and no output.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "lucent/imaging/camera_raw.h"

namespace lucent::testing {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string q(const fs::path& p) {
  return "\"" + p.string() + "\"";
}

int lines(const std::string& text) {
  return int(std::count(text.begin(), text.end(), '\n'));
}

TEST(RawCapture, SimulatedDngBracketsAreFittedToTheTruth) {
  const fs::path dir = scratch_dir("raw-capture");
  const auto sim = run_lucent(
      "simulate --material marble --size 96 --pixel-mm 0.1 --photons "
      "400000 --seed 3 --bracket-format dng --no-dark -q -o " +
      q(dir / "sim"));
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const json capture = json::parse(read_text(dir / "sim" / "capture.json"));
  ASSERT_EQ(capture["images"].size(), 5u);
  for (const json& image : capture["images"]) {
    EXPECT_FALSE(image.contains("exposure_s")) << image;  // left to the files' metadata
    EXPECT_EQ(fs::path(image["path"].get<std::string>()).extension(), ".dng");
  }
  const auto acquired =
      run_lucent("acquire " + q(dir / "sim" / "capture.json") + " -o " + q(dir / "acq"));
  ASSERT_EQ(acquired.exit_code, 0) << acquired.err;
  const json profile = json::parse(read_text(dir / "acq" / "profile.json"));
  const json& provenance = profile["provenance"];
  const json truth_doc = json::parse(read_text(dir / "sim" / "truth.json"));
  // The exposure times came from the DNGs (ISO 100: the scale factor is 1).
  ASSERT_EQ(provenance["exposures_s"].size(), truth_doc["camera"]["exposures_s"].size())
      << provenance.dump();
  for (std::size_t k = 0; k < provenance["exposures_s"].size(); ++k) {
    // EXIF stores a rational (libtiff writes it through a float): 1e-7 relative.
    const double t = truth_doc["camera"]["exposures_s"][k].get<double>();
    EXPECT_NEAR(provenance["exposures_s"][k].get<double>(), t, 1e-6 * t);
  }
  EXPECT_TRUE(provenance.contains("camera_raw")) << provenance.dump();

  const auto fitted =
      run_lucent("fit " + q(dir / "acq" / "profile.json") + " -o " + q(dir / "m.json"));
  ASSERT_EQ(fitted.exit_code, 0) << fitted.err;
  const json& truth = truth_doc["material"];
  const json m = json::parse(read_text(dir / "m.json"));
  for (int ch = 0; ch < 3; ++ch) {
    for (const char* key : {"sigma_a", "sigma_s_reduced"}) {
      const double t = truth[key][ch], v = m[key][ch], sd = m["uncertainty"][key][ch];
      // A 9.6 mm field holds 1-2 diffuse mean free paths of marble: red sigma_a is the least
      // determined (its reported SD is ~7%); the SD must cover the error and stay honest.
      EXPECT_LT(std::abs(v - t), 3 * sd) << key << "[" << ch << "] " << v << " +- " << sd;
      EXPECT_LT(std::abs(v / t - 1), 0.15) << key << "[" << ch << "] " << v << " truth " << t;
    }
  }
  fs::remove_all(dir);
}

// A DNG without metadata, a RAW capture declared sRGB, and ISO on some brackets only.
TEST(RawCapture, BadRawCapturesAreRefusedWithOneLine) {
  const fs::path dir = scratch_dir("raw-bad");
  imaging::BayerMosaic m;
  m.width = m.height = 64;
  m.black_level = 256;
  m.white_level = 16383;
  m.data.resize(64 * 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      m.data[y * 64 + x] =
          std::uint16_t(256 + 8000 * std::exp(-0.01 * ((x - 32) * (x - 32) + (y - 32) * (y - 32))));
  imaging::write_dng(dir / "bare.dng", m);  // no exposure time, no ISO
  m.exposure_s = 0.01, m.iso = 100;
  imaging::write_dng(dir / "a.dng", m);
  m.exposure_s = 0.04;
  imaging::write_dng(dir / "b.dng", m);

  const auto write = [&](const std::string& name, const json& images, const char* response) {
    json doc = {
        {"format", "lucent-capture"}, {"version", 1},
        {"images", images},           {"pixel_pitch_mm", 0.1},
        {"response", response},       {"incidence", {{"polar_deg", 0.0}, {"azimuth_deg", 0.0}}}};
    std::ofstream(dir / name) << doc.dump(2);
    return dir / name;
  };
  struct Case {
    fs::path capture;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {write("bare.json", json::array({{{"path", "bare.dng"}}}), "linear"),
       "no exposure time in the file's metadata"},
      {write("srgb.json", json::array({{{"path", "a.dng"}}, {{"path", "b.dng"}}}), "srgb"),
       "camera RAW codes are linear"},
      {write("iso.json",
             json::array({{{"path", "a.dng"}}, {{"path", "bare.dng"}, {"exposure_s", 1.0}}}),
             "linear"),
       "no ISO"},
      {write("png.json", json::array({{{"path", "missing.png"}}}), "linear"),
       "images[0].exposure_s"},
  };
  for (const Case& c : cases) {
    const fs::path out = dir / ("out-" + c.capture.stem().string());
    const auto r = run_lucent("acquire " + q(c.capture) + " -o " + q(out));
    EXPECT_NE(r.exit_code, 0) << c.capture;
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << out;
  }
  // The two good DNGs alone merge: exposures and ISO from their metadata.
  const auto good = run_lucent(
      "acquire " +
      q(write("good.json", json::array({{{"path", "b.dng"}}, {{"path", "a.dng"}}}), "linear")) +
      " -o " + q(dir / "out-good") + " --json");
  ASSERT_EQ(good.exit_code, 0) << good.err;
  const json profile = json::parse(read_text(dir / "out-good" / "profile.json"));
  ASSERT_EQ(profile["provenance"]["exposures_s"].size(), 2u);
  // Given in the order b (0.04 s), a (0.01 s): merged shortest first.
  EXPECT_NEAR(profile["provenance"]["exposures_s"][0].get<double>(), 0.01, 1e-8);
  EXPECT_NEAR(profile["provenance"]["exposures_s"][1].get<double>(), 0.04, 1e-8);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lucent::testing
