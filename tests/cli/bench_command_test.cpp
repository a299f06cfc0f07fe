#include <gtest/gtest.h>

#include <filesystem>

#include "cli_runner.h"

namespace lucent::testing {
namespace {

namespace fs = std::filesystem;

TEST(BenchCommand, RenderWritesOneRowOfStageTimesPerMesh) {
  const fs::path dir = scratch_dir("bench-render");
  const fs::path csv = dir / "render.csv";
  const auto r = run_lucent("bench render --meshes sphere --frames 1 --size 32 --radiance-map 32 "
                            "--light-map 32 --directions 2 --samples 4 --disc-points 64 --out \"" +
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
  const auto r = run_lucent("bench render --meshes sphere --directions 0 --out \"" + csv.string() + "\"");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("--directions"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(csv));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lucent::testing
