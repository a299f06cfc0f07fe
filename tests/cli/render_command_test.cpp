// End-to-end tests of `lucent render` (cli/render_command.cpp): tiny reference renders to PNG and
// EXR, and every kind of bad input failing with one line on stderr and no output file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "lucent/imaging/image_io.h"

namespace lucent::testing {
namespace {

namespace fs = std::filesystem;

// A tiny, fast reference render; append the case's own options.
const std::string kTiny =
    "render --technique reference --size 24x20 --reference-samples-pixel 64 --reference-threads 2 "
    "--view 30,20,4 ";

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

std::string read_prefix(const fs::path& path, std::size_t n) {
  std::ifstream in(path, std::ios::binary);
  std::string s(n, '\0');
  in.read(s.data(), std::streamsize(n));
  s.resize(std::size_t(in.gcount()));
  return s;
}

int lines(const std::string& text) {
  return int(std::count(text.begin(), text.end(), '\n'));
}

TEST(RenderCommand, ReferenceToPngWithStats) {
  const auto dir = scratch_dir("render-png");
  const fs::path out = dir / "sphere.png", stats = dir / "stats.json";
  const auto r = run_lucent(kTiny +
                                "--material marble --mesh sphere --light directional:1,1,1:2,2,2 "
                                "-o \"" +
                                out.string() + "\" --stats \"" + stats.string() + "\"",
                            "png");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  ASSERT_TRUE(fs::exists(out));
  EXPECT_EQ(read_prefix(out, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  // One line on stdout says what was written, how, and in how long.
  EXPECT_EQ(lines(r.out), 1) << r.out;
  EXPECT_NE(r.out.find("wrote " + out.string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("CPU reference"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("exposure"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(auto)"), std::string::npos) << r.out;
  const auto doc = nlohmann::json::parse(read_text(stats));
  EXPECT_EQ(doc.at("format"), "lucent-render-stats");
  EXPECT_EQ(doc.at("version"), 1);
  EXPECT_EQ(doc.at("technique"), "reference");
  EXPECT_EQ(doc.at("width"), 24);
  EXPECT_EQ(doc.at("height"), 20);
  EXPECT_EQ(doc.at("scene").at("model"), "tabulated");  // an unfitted material inside the table
  EXPECT_EQ(doc.at("details").at("single_scattering"), true);  // --single-scattering auto
  EXPECT_GT(doc.at("total_ms").get<double>(), 0);
  fs::remove_all(dir);
}

TEST(RenderCommand, PathTraceWritesTheImageAndItsNoise) {
  const auto dir = scratch_dir("render-pathtrace");
  const fs::path out = dir / "sphere.exr", stats = dir / "stats.json";
  const auto r = run_lucent(
      "render --technique pathtrace --size 16x12 --view 30,20,4 --pathtrace-samples-pixel 4 "
      "--pathtrace-threads 2 --material skin1 --mesh sphere:2 --object-size-mm 20 "
      "--light directional:1,1,1:2,2,2 --light point:0,40,40:900,900,900 -o \"" +
          out.string() + "\" --stats \"" + stats.string() + "\"",
      "exr");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  ASSERT_TRUE(fs::exists(out));
  EXPECT_NE(r.out.find("path-traced truth"), std::string::npos) << r.out;
  const auto doc = nlohmann::json::parse(read_text(stats));
  EXPECT_EQ(doc.at("technique"), "pathtrace");
  const auto& d = doc.at("details");
  EXPECT_EQ(d.at("samples_per_pixel").get<double>(), 4.0);
  EXPECT_GT(d.at("object_pixels").get<int>(), 50);
  for (int c = 0; c < 3; ++c) {
    const double mean = d.at("object_mean")[c].get<double>();
    const double error = d.at("object_mean_standard_error")[c].get<double>();
    EXPECT_GT(mean, 0);
    EXPECT_GT(error, 0);
    EXPECT_LT(error, 0.2 * mean);
  }
  EXPECT_GT(d.at("connections").get<double>(), 0);  // skin1 eta 1.3: through the boundary
  EXPECT_EQ(doc.at("settings"), "PathTraceOptions{samples_pixel=4, passes=1, seed=1, jitter=on}");
  fs::remove_all(dir);
}

TEST(RenderCommand, ReferenceToExrWithPointLightAndDipole) {
  const auto dir = scratch_dir("render-exr");
  const fs::path out = dir / "sphere.exr";
  const auto r = run_lucent(kTiny +
                                "--material ketchup --model dipole "
                                "--light point:0,80,80:20000,20000,20000 -o \"" +
                                out.string() + "\"",
                            "exr");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::exists(out));
  EXPECT_EQ(read_prefix(out, 4), std::string("\x76\x2f\x31\x01", 4));  // OpenEXR magic
}

TEST(RenderCommand, EnvironmentLightsTheObject) {
  const auto dir = scratch_dir("render-env");
  // A flat 8x4 Radiance .hdr of radiance 1 (mantissa 128, exponent 129).
  const fs::path env = dir / "sky.hdr", out = dir / "lit.png";
  {
    std::ofstream f(env, std::ios::binary);
    f << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n";
    for (int p = 0; p < 32; ++p) f << char(128) << char(128) << char(128) << char(129);
  }
  const auto r = run_lucent(
      kTiny + "--material marble --env \"" + env.string() + ":4\" -o \"" + out.string() + "\"",
      "env");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out));
  fs::remove_all(dir);
}

TEST(RenderCommand, NonManifoldMeshWarnsAndRenders) {
  const auto dir = scratch_dir("render-open");
  const fs::path mesh = dir / "open.obj", out = dir / "open.png";
  write_text(mesh, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0.2\nf 1 2 3\nf 2 4 3\n");
  const auto r = run_lucent(kTiny + "--material marble --mesh \"" + mesh.string() +
                                "\" --light directional:0,0,1:1,1,1 -o \"" + out.string() + "\"",
                            "open");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("warning: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("4 non-manifold edges; rendering what is there"), std::string::npos)
      << r.err;
  EXPECT_TRUE(fs::exists(out));
  fs::remove_all(dir);
}

// Each bad input: non-zero exit, exactly one line on stderr naming the problem, no output file.
struct BadCase {
  const char* name;
  std::string args;      // after kTiny, before -o
  const char* mentions;  // a word the error line must contain
};

class RenderCommandBadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(RenderCommandBadInput, FailsWithOneLineAndNoOutput) {
  const BadCase& c = GetParam();
  const auto dir = scratch_dir(std::string("render-bad-") + c.name);
  write_text(dir / "points.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
             "property float z\nelement face 0\nproperty list uchar int vertex_indices\n"
             "end_header\n0 0 0\n1 0 0\n0 1 0\n");
  write_text(dir / "notes.exr", "these are notes, not an image\n");
  std::string args = c.args;
  for (std::string::size_type at; (at = args.find("$DIR")) != std::string::npos;) {
    args.replace(at, 4, dir.string());
  }
  const fs::path out = dir / "out.png";
  const auto r = run_lucent(kTiny + args + " -o \"" + out.string() + "\"", c.name);
  EXPECT_NE(r.exit_code, 0) << c.name;
  EXPECT_EQ(lines(r.err), 1) << c.name << ": " << r.err;
  EXPECT_NE(r.err.find(c.mentions), std::string::npos) << c.name << ": " << r.err;
  EXPECT_FALSE(fs::exists(out)) << c.name;
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, RenderCommandBadInput,
    ::testing::Values(
        BadCase{"unknown_mesh", "--material marble --mesh teapot --light directional:0,0,1:1,1,1",
                "teapot"},
        BadCase{"empty_mesh",
                "--material marble --mesh $DIR/points.ply "
                "--light directional:0,0,1:1,1,1",
                "no triangles"},
        BadCase{"missing_material", "--material unobtainium --light directional:0,0,1:1,1,1",
                "unobtainium"},
        BadCase{"bad_exposure", "--material marble --exposure bright", "--exposure"},
        BadCase{"negative_exposure", "--material marble --exposure -2", "--exposure"},
        BadCase{"bad_roughness", "--material marble --roughness 3", "--roughness"},
        BadCase{"bad_specular", "--material marble --specular maybe", "--specular"},
        BadCase{"bad_backdrop", "--material marble --backdrop 1,2", "--backdrop"},
        BadCase{"bad_reference_sampling", "--material marble --reference-sampling grid",
                "--reference-sampling"},
        BadCase{"snapshot_of_the_reference",
                "--material marble --light directional:0,0,1:1,1,1 --snapshots 1", "--snapshots"},
        BadCase{"zero_size", "--material marble --light directional:0,0,1:1,1,1 --size 0x0",
                "--size"},
        BadCase{"bad_size", "--material marble --light directional:0,0,1:1,1,1 --size 64x",
                "--size"},
        BadCase{"env_not_an_image", "--material marble --env $DIR/notes.exr", "notes.exr"},
        BadCase{"bad_light", "--material marble --light directional:0,0,0:1,1,1", "--light"},
        BadCase{"bad_model", "--material marble --light directional:0,0,1:1,1,1 --model tripole",
                "--model"},
        BadCase{"bad_view", "--material marble --light directional:0,0,1:1,1,1 --view 1,2",
                "--view"},
        BadCase{"bad_technique",
                "--material marble --light directional:0,0,1:1,1,1 --technique raytrace",
                "--technique"},
        BadCase{"bad_maps_setting",
                "--material marble --light directional:0,0,1:1,1,1 --maps-samples 2000 "
                "--maps-disc-points 1000",
                "--maps-samples"}),
    [](const ::testing::TestParamInfo<BadCase>& info) { return std::string(info.param.name); });

TEST(RenderCommand, UnsupportedOutputFormatFails) {
  const auto dir = scratch_dir("render-tif");
  const fs::path out = dir / "out.tif";
  const auto r = run_lucent(
      kTiny + "--material marble --light directional:0,0,1:1,1,1 -o \"" + out.string() + "\"",
      "tif");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir);
}

// No --light and no --env: the default rig (key, fill, rim), named on stderr; the image is lit.
// --exposure auto puts the object's bright side near the top of the tone curve without clipping;
// a fixed exposure of 1 leaves this scene darker.
TEST(RenderCommand, DefaultRigAndAutoExposure) {
  const auto dir = scratch_dir("render-rig");
  const fs::path automatic = dir / "auto.exr", png = dir / "auto.png", dim = dir / "dim.png";
  auto r = run_lucent(kTiny + "--material marble -o \"" + png.string() + "\"", "rig");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("default rig"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("--light directional:"), std::string::npos) << r.err;
  r = run_lucent(kTiny + "--material marble --exposure 1 -o \"" + dim.string() + "\"", "dim");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto bright = imaging::read_raw_image(png), dark = imaging::read_raw_image(dim);
  ASSERT_EQ(bright.max_value, 255);
  double sum_bright = 0, sum_dark = 0;
  int max_bright = 0;
  for (std::size_t i = 0; i < bright.data.size(); ++i) {
    sum_bright += bright.data[i];
    sum_dark += dark.data[i];
    max_bright = std::max<int>(max_bright, bright.data[i]);
  }
  // Auto picks ~5.8 here: through the tone curve and sRGB the pixel sum grows 1.67-fold.
  EXPECT_GT(sum_bright, 1.3 * sum_dark);
  EXPECT_LT(max_bright, 255);  // Reinhard never clips
  EXPECT_GT(max_bright, 180);
  fs::remove_all(dir);
}

// --snapshots writes the maps' linear image after the frames named; `lucent compare` measures
// them against the final image: the difference falls as frames accumulate, and an image compared
// with itself differs by nothing.
TEST(RenderCommand, SnapshotsAndCompare) {
  const auto dir = scratch_dir("render-snapshots");
  const fs::path out = dir / "maps.exr";
  auto r = run_lucent(
      "render --material marble --mesh sphere --size 24x24 --maps-frames 8 --maps-directions 4 "
      "--maps-samples 8 "
      "--maps-disc-points 64 --maps-radiance-map 32 --maps-light-map 32 --light "
      "directional:1,0,1:1,1,1 "
      "--snapshots 1,4,8 -o \"" +
          out.string() + "\"",
      "snapshots");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (int t : {1, 4, 8})
    ASSERT_TRUE(fs::exists(dir / ("maps.f" + std::to_string(t) + ".exr"))) << t;
  const auto difference = [&](const std::string& name) {
    const auto c =
        run_lucent("compare \"" + (dir / name).string() + "\" \"" + out.string() + "\" --json",
                   "compare-" + name);
    EXPECT_EQ(c.exit_code, 0) << c.err;
    return nlohmann::json::parse(c.out).at("relative_rmse").get<double>();
  };
  const double first = difference("maps.f1.exr"), last = difference("maps.f8.exr");
  EXPECT_GT(first, 0);
  EXPECT_EQ(last, 0);  // frame 8 of 8 is the final image
  EXPECT_LE(difference("maps.f4.exr"), first);
  const auto bad =
      run_lucent("compare \"" + out.string() + "\" \"" + (dir / "none.exr").string() + "\"",
                 "compare-missing");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_EQ(lines(bad.err), 1) << bad.err;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lucent::testing

namespace lucent::testing {
namespace {

// --json: the summary as one JSON document on stdout (what a pipeline reads), the --stats
// document inside it.
// --size N is an N x N image (as simulate's --size), not a refusal.
TEST(RenderCommand, OneSizeIsASquare) {
  const auto dir = scratch_dir("render-square");
  const auto r = run_lucent(
      "render --technique reference --reference-samples-pixel 16 "
      "--reference-threads 2 --material marble --mesh sphere --light "
      "directional:1,1,1:2,2,2 --size 20 --json -o \"" +
          (dir / "s.exr").string() + "\"",
      "square");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto doc = nlohmann::json::parse(r.out);
  EXPECT_EQ(doc.at("width"), 20);
  EXPECT_EQ(doc.at("height"), 20);
  fs::remove_all(dir);
}

TEST(RenderCommand, JsonSummaryOnStdout) {
  const auto dir = scratch_dir("render-json");
  const fs::path out = dir / "s.png";
  const auto r = run_lucent(kTiny +
                                "--material marble --mesh sphere --light directional:1,1,1:2,2,2 "
                                "--json -o \"" +
                                out.string() + "\"",
                            "json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto doc = nlohmann::json::parse(r.out);
  EXPECT_EQ(doc.at("output"), out.string());
  EXPECT_EQ(doc.at("technique"), "reference");
  EXPECT_EQ(doc.at("width"), 24);
  EXPECT_EQ(doc.at("scene").at("mesh"), "sphere");
  EXPECT_TRUE(doc.at("auto_exposure").get<bool>());
  EXPECT_GT(doc.at("exposure").get<double>(), 0);
  EXPECT_GT(doc.at("seconds").get<double>(), 0);
  EXPECT_TRUE(fs::exists(out));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lucent::testing

namespace lucent::testing {
namespace {

// --env NAME: a CC0 HDRI of the data package (scripts/install-deps), by name; an unknown name lists
// the ones there are.
TEST(RenderCommand, RendersABundledEnvironmentByName) {
  const char* cache_env = std::getenv("LUCENT_DATA_CACHE");
  const fs::path cache = cache_env && *cache_env ? fs::path(cache_env)
                                                 : fs::path(std::getenv("HOME")) / ".cache/lucent";
  if (!fs::exists(cache / "hdri/studio.exr"))
    GTEST_SKIP() << "no environment maps in " << cache << " (run scripts/install-deps)";
  const auto dir = scratch_dir("render-env-name");
  const fs::path out = dir / "studio.exr";
  const auto r = run_lucent(
      kTiny + "--material marble --mesh sphere --env studio:4 -o \"" + out.string() + "\"",
      "env-name");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const imaging::ImageRgb image = imaging::read_exr(out);
  double corner = 0;  // the background is the studio, not black
  for (int c = 0; c < 3; ++c) corner += image.at(0, 0, c);
  EXPECT_GT(corner, 0);
  const auto bad = run_lucent(kTiny + "--material marble --mesh sphere --env stuido -o \"" +
                                  (dir / "x.exr").string() + "\"",
                              "env-unknown");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_EQ(lines(bad.err), 1) << bad.err;
  EXPECT_NE(bad.err.find("'stuido' is neither a file nor a bundled environment map"),
            std::string::npos)
      << bad.err;
  EXPECT_NE(bad.err.find("studio"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "x.exr"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lucent::testing
