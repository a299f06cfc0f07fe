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

namespace lucent::testing {
namespace {

// lucent fit --batch: a manifest of lucent's own profiles (tabulated model, so the fit is exact),
// one row that cannot be read; the summary keeps every row's outcome, the exit status says one
// failed; shards run through GNU parallel (when installed: scripts/install-deps installs it) and
// merged equal the unsharded summary byte for byte.
TEST(FitBatch, ShardedRunsMergeToTheOneRun) {
  const fs::path dir = scratch_dir("batch");
  const auto q = [](const fs::path& p) { return "\"" + p.string() + "\""; };
  std::ofstream manifest(dir / "manifest.csv");
  manifest << "input,output,ior,name\n";
  for (const char* m : {"marble", "skin1", "ketchup", "apple"}) {
    const fs::path csv = dir / (std::string(m) + ".csv");
    ASSERT_EQ(run_lucent(std::string("profile --material ") + m +
                         " --model tabulated --r-range 0.2:20:40:log -o " + q(csv))
                  .exit_code,
              0);
    manifest << m << ".csv,out/" << m << ".json,"
             << (std::string(m) == "marble" ? "1.5" : "1.3") << "," << m << "_fit\n";
  }
  manifest << "missing.csv,out/missing.json,1.3,\n";
  manifest.close();
  fs::create_directories(dir / "out");
  const auto one = run_lucent("fit --batch " + q(dir / "manifest.csv") + " --quality fast -o " +
                              q(dir / "all.json"));
  EXPECT_EQ(one.exit_code, 1) << one.err;
  EXPECT_NE(one.err.find("1 of 5 rows failed"), std::string::npos) << one.err;
  const nlohmann::json all = nlohmann::json::parse(read_text(dir / "all.json"));
  ASSERT_EQ(all["rows"].size(), 5u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(all["rows"][i]["status"], "ok") << all["rows"][i].dump();
    EXPECT_TRUE(fs::exists(all["rows"][i]["output"].get<std::string>()));
  }
  EXPECT_EQ(all["rows"][4]["status"], "failed");
  EXPECT_NE(all["rows"][4]["error"].get<std::string>().find("missing.csv"), std::string::npos);
  const nlohmann::json marble = nlohmann::json::parse(read_text(dir / "out" / "marble.json"));
  EXPECT_EQ(marble["name"], "marble_fit");
  EXPECT_NEAR(marble["sigma_s_reduced"][0].get<double>(), 2.19, 0.02 * 2.19);

  // Three shards, as a job array would run them.
  std::string shards;
  if (std::system("command -v parallel >/dev/null 2>&1") == 0) {
    const std::string cmd = "parallel --will-cite -j 2 \"" + std::string(LUCENT_BINARY) +
                            "\" fit --batch " + q(dir / "manifest.csv") +
                            " --quality fast --shard {}/3 -o " + q(dir / "s{}.json") +
                            " ::: 0 1 2 >/dev/null 2>&1";
    EXPECT_NE(std::system(cmd.c_str()), 0);  // a shard holds the failed row
  } else {
    for (int i = 0; i < 3; ++i)
      run_lucent("fit --batch " + q(dir / "manifest.csv") + " --quality fast --shard " +
                 std::to_string(i) + "/3 -o " + q(dir / ("s" + std::to_string(i) + ".json")));
  }
  for (int i = 0; i < 3; ++i) shards += " " + q(dir / ("s" + std::to_string(i) + ".json"));
  const auto merged = run_lucent("merge" + shards + " -o " + q(dir / "merged.json"));
  ASSERT_EQ(merged.exit_code, 0) << merged.err;
  EXPECT_EQ(read_text(dir / "merged.json"), read_text(dir / "all.json"));
  // A shard missing: refused, counting the rows the shards hold against the manifest's.
  const auto partial = run_lucent("merge " + q(dir / "s0.json") + " " + q(dir / "s1.json") +
                                  " -o " + q(dir / "partial.json"));
  EXPECT_NE(partial.exit_code, 0);
  EXPECT_NE(partial.err.find("a shard missing"), std::string::npos) << partial.err;
  EXPECT_FALSE(fs::exists(dir / "partial.json"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lucent::testing
