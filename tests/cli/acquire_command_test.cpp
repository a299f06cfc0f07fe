// `lucent acquire` end to end through the executable: one good run, bad input answered with one
// line on stderr, a non-zero exit and no output folder.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "lucent/acquire/capture.h"
#include "lucent/imaging/image_io.h"

namespace lucent::testing {
namespace {

namespace fs = std::filesystem;
using namespace lucent::acquire;
using namespace lucent::imaging;

// Three 16-bit linear brackets of a spot at (30.3, 33.7) px, L = exp(-r / 2 mm) / (r + 0.5 mm).
fs::path write_capture_folder(const fs::path& dir) {
  Capture capture;
  capture.pixel_pitch_mm = 0.1;
  capture.response = Response::kLinear;
  for (double t : {1.0, 4.0, 16.0}) {
    RawImage image(64, 64, 65535);
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; ++x) {
        const double r = 0.1 * std::hypot(x + 0.5 - 30.3, y + 0.5 - 33.7);
        const double linear = std::min(1.0, 0.2 * t * std::exp(-r / 2) / (r + 0.5));
        for (int c = 0; c < 3; ++c) image.at(x, y, c) = std::uint16_t(std::lround(linear * 65535));
      }
    }
    const std::string name = "bracket_" + std::to_string(int(t)) + ".png";
    write_png(dir / name, image);
    capture.sample.images.push_back({name, t});
  }
  write_capture(dir / "capture.json", capture);
  return dir / "capture.json";
}

int lines(const std::string& text) {
  return int(std::count(text.begin(), text.end(), '\n'));
}

TEST(AcquireCommand, WritesTheOutputFolderAndASummary) {
  const fs::path dir = scratch_dir("acquire-good");
  const fs::path capture = write_capture_folder(dir);
  const fs::path out = dir / "out";
  const auto r = run_lucent(
      "acquire \"" + capture.string() + "\" -o \"" + out.string() + "\" --bins 40 --json",
      "acquire-good");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  for (const char* name : {"capture.exr", "profile.json", "profile.csv", "acquire.png"}) {
    EXPECT_TRUE(fs::is_regular_file(out / name)) << name;
  }
  const nlohmann::json summary = nlohmann::json::parse(r.out);
  EXPECT_EQ(summary["beam_point_source"], "detected");
  EXPECT_NEAR(summary["beam_point_px"][0].get<double>(), 30.3, 0.05);
  EXPECT_EQ(summary["calibrated"], false);
  EXPECT_GT(summary["bins_written"].get<int>(), 10);

  const auto again = run_lucent("acquire \"" + capture.string() + "\" -o \"" + out.string() + "\"",
                                "acquire-again");
  EXPECT_EQ(again.exit_code, 1);  // the folder exists: refused without --force, one line
  EXPECT_NE(again.err.find("--force"), std::string::npos) << again.err;
  EXPECT_EQ(lines(again.err), 1) << again.err;
  const auto human = run_lucent(
      "acquire \"" + capture.string() + "\" -o \"" + out.string() + "\" --force", "acquire-human");
  ASSERT_EQ(human.exit_code, 0) << human.err;
  EXPECT_NE(human.out.find("entry point"), std::string::npos) << human.out;
  EXPECT_NE(human.out.find("relative"), std::string::npos) << human.out;
  fs::remove_all(dir);
}

TEST(AcquireCommand, MissingImageIsOneLineAndNoOutput) {
  const fs::path dir = scratch_dir("acquire-missing");
  const fs::path capture = write_capture_folder(dir);
  fs::remove(dir / "bracket_4.png");
  const fs::path out = dir / "out";
  const auto r = run_lucent("acquire \"" + capture.string() + "\" -o \"" + out.string() + "\"",
                            "acquire-missing");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.rfind("lucent: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("bracket_4.png"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

TEST(AcquireCommand, BadPixelPitchIsOneLineAndNoOutput) {
  const fs::path dir = scratch_dir("acquire-pitch");
  const fs::path capture = write_capture_folder(dir);
  Capture c = read_capture(capture);
  c.pixel_pitch_mm = 0;
  write_capture(capture, c);
  const fs::path out = dir / "out";
  const auto r = run_lucent("acquire \"" + capture.string() + "\" -o \"" + out.string() + "\"",
                            "acquire-pitch");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("pixel_pitch_mm"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));

  const auto bins = run_lucent(
      "acquire \"" + capture.string() + "\" -o \"" + out.string() + "\" --bins 0", "acquire-bins");
  EXPECT_NE(bins.exit_code, 0);
  EXPECT_EQ(lines(bins.err), 1) << bins.err;
  EXPECT_NE(bins.err.find("--bins"), std::string::npos) << bins.err;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lucent::testing
