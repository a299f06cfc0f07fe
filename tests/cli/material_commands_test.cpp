// lucent export and lucent materials from the command line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "cli_runner.h"

namespace lucent::testing {
namespace {

namespace fs = std::filesystem;

TEST(MaterialsCommand, ListsTheLibrary) {
  const auto r = run_lucent("materials");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("marble"), std::string::npos);
  EXPECT_NE(r.out.find("ketchup"), std::string::npos);
  EXPECT_NE(r.out.find("Jensen, Marschner"), std::string::npos);  // the source
  const auto j = run_lucent("materials --json");
  ASSERT_EQ(j.exit_code, 0) << j.err;
  const nlohmann::json list = nlohmann::json::parse(j.out);
  bool marble = false;
  for (const auto& m : list)
    if (m["name"] == "marble") {
      marble = true;
      EXPECT_EQ(m["ior"], 1.5);
      EXPECT_EQ(m["sigma_s_reduced"][0], 2.19);
      EXPECT_NEAR(m["diffuse_mean_free_path_mm"][0].get<double>(), 8.509, 1e-3);
    }
  EXPECT_TRUE(marble);
  EXPECT_GT(list.size(), 10u);
}

TEST(ExportCommand, WritesEveryTargetAndPrintsTheRoundTrip) {
  const fs::path dir = scratch_dir("export");
  for (const auto& [to, ext] : {std::pair{"pbrt", ".pbrt"}, {"mitsuba", ".xml"},
                                {"materialx", ".mtlx"}, {"openpbr", ".mtlx"}, {"gltf", ".gltf"}}) {
    const fs::path out = dir / (std::string("marble_") + to + ext);
    const auto r = run_lucent(std::string("export --material marble --to ") + to + " -o \"" +
                              out.string() + "\"");
    ASSERT_EQ(r.exit_code, 0) << to << ": " << r.err;
    EXPECT_TRUE(fs::exists(out)) << to;
    EXPECT_NE(r.out.find("round trip"), std::string::npos) << to;
    EXPECT_NE(r.out.find("sigma_s'"), std::string::npos) << to;
  }
  // A fitted material file exports too (its name and coefficients, not the library's).
  const fs::path fitted = dir / "fitted.json";
  {
    std::ofstream(fitted) << R"({"format": "lucent-material", "version": 1, "name": "mine",
      "ior": 1.4, "sigma_a": [0.01, 0.02, 0.03], "sigma_s_reduced": [1, 1.5, 2]})";
  }
  const auto r = run_lucent("export --material \"" + fitted.string() + "\" --to pbrt --scene-unit cm -o \"" +
                            (dir / "mine.pbrt").string() + "\"");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string text = read_text(dir / "mine.pbrt");
  EXPECT_NE(text.find("MakeNamedMaterial \"mine\""), std::string::npos);
  EXPECT_NE(text.find("\"float scale\" [ 10 ]"), std::string::npos);
  EXPECT_NE(text.find("\"float eta\" [ 1.4 ]"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lucent::testing
