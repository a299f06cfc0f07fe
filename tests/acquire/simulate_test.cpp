#include "lucent/acquire/simulate.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <numbers>

#include "lucent/acquire/capture.h"
#include "lucent/core/error.h"
#include "lucent/imaging/image_io.h"

namespace lucent::acquire {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("lucent-sim-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

SimulateOptions small_marble() {
  SimulateOptions o;
  o.material = materials::load_material("marble");
  o.transport.photons = 4000;
  o.transport.size = 32;
  o.transport.pixel_mm = 0.2;
  o.transport.threads = 2;
  return o;
}

TEST(WhiteReference, IntegratesToReflectanceOverPi) {
  const imaging::ImageRgb white = white_reference_radiance(64, 0.1, 0.99, 0.1);
  double sum = 0;
  for (int j = 0; j < 64; ++j) {
    for (int i = 0; i < 64; ++i) sum += white.at(i, j, 0) * 0.01;
  }
  EXPECT_NEAR(sum, 0.99 / std::numbers::pi, 1e-6);
  EXPECT_EQ(white.at(31, 31, 0), white.at(32, 32, 0));  // centred between the four middle pixels
}

TEST(Simulate, WritesACaptureThatReadsBack) {
  const fs::path dir = fresh_dir("capture");
  const SimulateSummary summary = run_simulation(small_marble(), dir);
  const Capture capture = read_capture(dir / "capture.json");
  EXPECT_EQ(capture.sample.images.size(), 5u);
  ASSERT_TRUE(capture.white_reference.has_value());
  EXPECT_EQ(capture.white_reference->images.images.size(), 5u);
  EXPECT_DOUBLE_EQ(capture.white_reference->reflectance, 0.99);
  ASSERT_TRUE(capture.dark.has_value());
  EXPECT_DOUBLE_EQ(capture.pixel_pitch_mm, 0.2);
  EXPECT_EQ(capture.response, Response::kSrgb);
  for (const Bracket& b : capture.sample.images) {
    const imaging::RawImage raw = imaging::read_raw_image(dir / b.path);
    EXPECT_EQ(raw.width, 32);
    EXPECT_EQ(raw.max_value, 65535);
  }
  const imaging::ImageRgb truth = imaging::read_exr(dir / "truth_radiance.exr");
  EXPECT_EQ(truth.width, 32);
  EXPECT_GT(truth.at(16, 16, 0), truth.at(2, 2, 0));
  std::ifstream in(dir / "truth.json");
  const auto doc = nlohmann::json::parse(in);
  EXPECT_EQ(doc["format"], "lucent-simulation-truth");
  EXPECT_EQ(doc["material"]["name"], "marble");
  EXPECT_GT(doc["camera"]["electrons_per_radiance_s"].get<double>(), 0);
  EXPECT_EQ(summary.files.size(), 15u);
  fs::remove_all(dir);
}

TEST(Simulate, SameSeedSameFilesWhateverTheThreads) {
  const fs::path a = fresh_dir("seed-a"), b = fresh_dir("seed-b");
  SimulateOptions o = small_marble();
  o.transport.threads = 1;
  run_simulation(o, a);
  o.transport.threads = 2;
  run_simulation(o, b);
  for (const char* name : {"bracket_0.png", "bracket_4.png", "white_2.png", "dark.png",
                           "truth_radiance.exr", "capture.json"}) {
    std::ifstream fa(a / name, std::ios::binary), fb(b / name, std::ios::binary);
    const std::string da((std::istreambuf_iterator<char>(fa)), {});
    const std::string db((std::istreambuf_iterator<char>(fb)), {});
    EXPECT_FALSE(da.empty()) << name;
    EXPECT_EQ(da, db) << name;
  }
  fs::remove_all(a);
  fs::remove_all(b);
}

TEST(Simulate, BadOptionsLeaveNoFolder) {
  const fs::path dir = fresh_dir("bad");
  SimulateOptions o = small_marble();
  o.camera.exposures_s = {0.01, 0.005};
  EXPECT_THROW(run_simulation(o, dir), Error);
  EXPECT_FALSE(fs::exists(dir));
  o = small_marble();
  o.transport.pixel_mm = -1;
  EXPECT_THROW(run_simulation(o, dir), Error);
  EXPECT_FALSE(fs::exists(dir));
  o = small_marble();
  o.camera.bits = 12;
  EXPECT_THROW(run_simulation(o, dir), Error);
  EXPECT_FALSE(fs::exists(dir));
  // Nothing stray beside it either.
  for (const auto& entry : fs::directory_iterator(dir.parent_path())) {
    EXPECT_EQ(entry.path().filename().string().find("." + dir.filename().string()),
              std::string::npos);
  }
}

TEST(Simulate, ProfileOnlyWritesTruthAndExitance) {
  const fs::path dir = fresh_dir("profile-only");
  SimulateOptions o = small_marble();
  o.profile_only = true;
  const fs::path csv =
      fs::temp_directory_path() / ("lucent-exitance-" + std::to_string(::getpid()) + ".csv");
  o.exitance_csv = csv;
  run_simulation(o, dir);
  EXPECT_TRUE(fs::exists(dir / "truth.json"));
  EXPECT_FALSE(fs::exists(dir / "capture.json"));
  std::ifstream in(csv);
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first.rfind("#", 0), 0u);
  fs::remove_all(dir);
  fs::remove(csv);
}

}  // namespace
}  // namespace lucent::acquire
