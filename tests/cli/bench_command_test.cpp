#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.h"

namespace lucent::testing {
namespace {

namespace fs = std::filesystem;

TEST(BenchCommand, RenderWritesOneRowOfStageTimesPerMesh) {
  const fs::path dir = scratch_dir("bench-render");
  const fs::path csv = dir / "render.csv";
  const auto r = run_lucent(
      "bench render --meshes sphere --frames 1 --size 32 --maps-radiance-map 32 "
      "--maps-light-map 32 --maps-directions 2 --maps-samples 4 --maps-disc-points 64 --out \"" +
      csv.string() + "\"");
  if (r.exit_code != 0 && r.err.find("EGL") != std::string::npos) GTEST_SKIP() << r.err;
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string text = read_text(csv);
  EXPECT_EQ(text.rfind("mesh,triangles,K,W_s,W_l,N,M,disc,frames,size_px,light_map_ms,radiance_map_ms,", 0), 0u);
  EXPECT_NE(text.find("\nsphere,5120,2,32,32,4,64,strata,1,32,"), std::string::npos) << text;
  EXPECT_NE(text.find("\nsphere,5120,2,32,32,4,64,nearest,1,32,"), std::string::npos) << text;
  fs::remove_all(dir);
}

TEST(BenchCommand, BadSettingIsOneLineAndNoFile) {
  const fs::path dir = scratch_dir("bench-render-bad");
  const fs::path csv = dir / "render.csv";
  const auto r =
      run_lucent("bench render --meshes sphere --maps-directions 0 --out \"" + csv.string() + "\"");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--maps-directions"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(csv));
  fs::remove_all(dir);
}

// A tiny tile (8 texels, 4 shells, 32 x 24 pixels): one row per shell count and distance, with
// positive times and a covered fraction in (0, 1].
TEST(BenchCommand, FurWritesARowPerShellCountAndDistance) {
  const fs::path dir = scratch_dir("bench-fur");
  const fs::path csv = dir / "fur.csv";
  const auto r = run_lucent("bench fur --texels 8 --shells 2,4 --frames 1 --size 32x24 --out \"" +
                            csv.string() + "\"");
  if (r.exit_code != 0 && r.err.find("EGL") != std::string::npos) GTEST_SKIP() << r.err;
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream text(read_text(csv));
  std::string line;
  std::getline(text, line);
  EXPECT_EQ(line.rfind("texels,shells,hairs,width_px,height_px,distance_radii,covered,frames,", 0), 0u);
  int rows = 0;
  while (std::getline(text, line)) {
    std::istringstream row(line);
    std::vector<double> v;
    std::string cell;
    while (std::getline(row, cell, ',') && v.size() < 12) v.push_back(std::stod(cell));
    ASSERT_EQ(v.size(), 12u) << line;
    EXPECT_EQ(v[0], 8);
    EXPECT_EQ(v[1], rows < 2 ? 2 : 4) << line;
    EXPECT_EQ(v[3], 32);
    EXPECT_EQ(v[4], 24);
    EXPECT_GT(v[6], 0) << "covered: " << line;
    EXPECT_LE(v[6], 1) << "covered: " << line;
    EXPECT_GT(v[9], 0) << "draw median: " << line;
    ++rows;
  }
  EXPECT_EQ(rows, 4);
  fs::remove_all(dir);
}

TEST(BenchCommand, FurBadSizeIsOneLineAndNoFile) {
  const fs::path dir = scratch_dir("bench-fur-bad");
  const fs::path csv = dir / "fur.csv";
  for (const char* bad : {"--size 0x10", "--size 64", "--shells 0", "--frames 0"}) {
    const auto r = run_lucent(std::string("bench fur ") + bad + " --out \"" + csv.string() + "\"");
    EXPECT_NE(r.exit_code, 0) << bad;
    EXPECT_NE(r.err.find(std::string(bad).substr(0, std::string(bad).find(' '))), std::string::npos)
        << bad << ": " << r.err;
    EXPECT_FALSE(fs::exists(csv)) << bad;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lucent::testing
