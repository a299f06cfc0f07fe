// Each technique's flags (cli/technique_flags.cpp): one option group per technique with its prefix
// in the help; every earlier spelling still reaching the same option (the settings the render
// reports are those of the new spelling, and differ from the defaults) with one deprecation line;
// enums naming their choices; and the maps under more lights than disc samples (a crash before).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_runner.h"

namespace lucent::testing {
namespace {

namespace fs = std::filesystem;

int lines(const std::string& text) {
  return int(std::count(text.begin(), text.end(), '\n'));
}

// The smallest render of each technique, with one light (no default-rig line on stderr), as
// (flag, value) pairs: a case replaces its own flag's pair rather than giving the option twice.
using Flags = std::vector<std::pair<std::string, std::string>>;

Flags tiny_flags(const std::string& technique) {
  const Flags common = {
      {"--material", "marble"}, {"--size", "8x8"}, {"--light", "directional:0.3,0.8,0.5:1,1,1"}};
  Flags own;
  if (technique == "maps") {
    own = {{"--maps-frames", "1"},       {"--maps-directions", "2"},    {"--maps-samples", "4"},
           {"--maps-disc-points", "16"}, {"--maps-radiance-map", "16"}, {"--maps-light-map", "16"}};
  } else if (technique == "sh") {
    own = {{"--technique", "sh"}, {"--sh-shadow-map", "32"}, {"--sh-cube-map", "8"}};
  } else if (technique == "hierarchical") {
    own = {{"--technique", "hierarchical"}, {"--mesh", "sphere:1"}};
  } else {
    own = {{"--technique", "reference"}, {"--reference-samples-pixel", "4"}};
  }
  own.insert(own.begin(), common.begin(), common.end());
  return own;
}

// `render` with the technique's tiny flags, `name value` in place of `replaces`'s pair (or added).
std::string tiny(const std::string& technique, const std::string& replaces = "",
                 const std::string& name = "", const std::string& value = "") {
  std::string args = "render";
  bool placed = false;
  for (const auto& [flag, v] : tiny_flags(technique)) {
    if (flag == replaces) {
      args += " " + name + " " + value;
      placed = true;
    } else {
      args += " " + flag + " " + v;
    }
  }
  if (!name.empty() && !placed) args += " " + name + " " + value;
  return args;
}

// The "settings" of a render's --json document (every technique reports its options there).
std::string settings_of(const std::string& args, const std::string& tag, std::string* err) {
  const fs::path dir = scratch_dir("flags-" + tag);
  const auto r = run_lucent(args + " --json -o \"" + (dir / "out.exr").string() + "\"", tag);
  *err = without_progress(r.err);
  EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.err;
  fs::remove_all(dir);
  if (r.exit_code != 0) return "";
  return nlohmann::json::parse(r.out).value("settings", "");
}

// Every earlier spelling of `technique`'s flags reaches the new one's option with one deprecation
// line (a test per technique: ctest runs them side by side; one test of all took 120 s).
void check_earlier_spellings(const std::string& only) {
  // technique, earlier spelling, new spelling, a value other than the default
  const std::vector<std::tuple<std::string, std::string, std::string, std::string>> renamed = {
      {"maps", "--frames", "--maps-frames", "2"},
      {"maps", "--directions", "--maps-directions", "3"},
      {"maps", "--samples", "--maps-samples", "3"},
      {"maps", "--disc-points", "--maps-disc-points", "20"},
      {"maps", "--disc-distribution", "--maps-disc-distribution", "exponential"},
      {"maps", "--q", "--maps-q", "2"},
      {"maps", "--disc-selection", "--maps-disc-selection", "nearest"},
      {"maps", "--max-blur", "--maps-max-blur", "1"},
      {"maps", "--radiance-map", "--maps-radiance-map", "24"},
      {"maps", "--light-map", "--maps-light-map", "24"},
      {"sh", "--shadow-map", "--sh-shadow-map", "48"},
      {"sh", "--cube-map", "--sh-cube-map", "12"},
      {"sh", "--depth-blur", "--sh-depth-blur", "0.5"},
      {"hierarchical", "--hbe-irradiance-cache", "--hierarchical-irradiance-cache", "off"},
      {"hierarchical", "--hbe-mode", "--hierarchical-mode", "incremental"},
      {"hierarchical", "--hbe-epsilon1", "--hierarchical-epsilon1", "0.07"},
      {"hierarchical", "--hbe-epsilon2", "--hierarchical-epsilon2", "0.3"},
      {"hierarchical", "--hbe-near", "--hierarchical-near", "0.02"},
      {"hierarchical", "--hbe-planarity", "--hierarchical-planarity", "0.8"},
      {"hierarchical", "--hbe-edge-constant", "--hierarchical-edge-constant", "0.3"},
      {"hierarchical", "--hbe-rule", "--hierarchical-rule", "midpoint"},
      {"hierarchical", "--hbe-dipole", "--hierarchical-dipole", "seed"},
      {"hierarchical", "--hbe-budget", "--hierarchical-budget", "77"},
      {"reference", "--samples-pixel", "--reference-samples-pixel", "3"},
      {"reference", "--samples-reference", "--reference-samples", "1234"},
      {"reference", "--area-light-samples", "--reference-area-light-samples", "3"},
      {"reference", "--irradiance-cache", "--reference-irradiance-cache", "on"},
      {"reference", "--passes", "--reference-passes", "2"},
      {"reference", "--threads", "--reference-threads", "2"},
  };
  std::string err;
  std::map<std::string, std::string> defaults;
  int checked = 0;
  for (const auto& [technique, old_name, new_name, value] : renamed) {
    if (technique != only) continue;
    ++checked;
    if (!defaults.count(technique))
      defaults[technique] = settings_of(tiny(technique), technique + "-defaults", &err);
    const std::string now =
        settings_of(tiny(technique, new_name, new_name, value), technique + "-new", &err);
    EXPECT_TRUE(err.empty()) << new_name << ": " << err;
    const std::string before =
        settings_of(tiny(technique, new_name, old_name, value), technique + "-old", &err);
    EXPECT_FALSE(now.empty());
    EXPECT_EQ(before, now) << old_name << " and " << new_name << " set different options";
    EXPECT_NE(now, defaults[technique])
        << new_name << " " << value << " changed nothing the render reports";
    EXPECT_EQ(lines(err), 1) << err;
    EXPECT_NE(err.find("deprecated: " + old_name + " is now " + new_name), std::string::npos)
        << err;
  }
  EXPECT_GT(checked, 0) << only;
}

TEST(TechniqueFlags, EveryEarlierMapsSpellingReachesItsOptionWithOneDeprecationLine) {
  check_earlier_spellings("maps");
}
TEST(TechniqueFlags, EveryEarlierShSpellingReachesItsOptionWithOneDeprecationLine) {
  check_earlier_spellings("sh");
}
TEST(TechniqueFlags, EveryEarlierHierarchicalSpellingReachesItsOptionWithOneDeprecationLine) {
  check_earlier_spellings("hierarchical");
}
TEST(TechniqueFlags, EveryEarlierReferenceSpellingReachesItsOptionWithOneDeprecationLine) {
  check_earlier_spellings("reference");
}

TEST(TechniqueFlags, TheEarlierSpellingsRenderTheSameImage) {
  const fs::path dir = scratch_dir("flags-image");
  const std::string old_args =
      "render --material marble --size 12x12 --frames 2 --directions 2 --samples 4 "
      "--disc-points 16 --radiance-map 16 --light-map 16 --light point:60,80,60:4000,4000,4000";
  auto r = run_lucent(old_args + " -o \"" + (dir / "old.exr").string() + "\"", "old-image");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines(without_progress(r.err)), 1) << r.err;
  r = run_lucent(
      "render --material marble --size 12x12 --maps-frames 2 --maps-directions 2 "
      "--maps-samples 4 --maps-disc-points 16 --maps-radiance-map 16 "
      "--maps-light-map 16 --light point:60,80,60:4000,4000,4000 -o \"" +
          (dir / "new.exr").string() + "\"",
      "new-image");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(without_progress(r.err).empty()) << r.err;
  EXPECT_EQ(read_text(dir / "old.exr"), read_text(dir / "new.exr"));
  fs::remove_all(dir);
}

TEST(TechniqueFlags, HelpShowsOneGroupPerTechniqueAndNoEarlierSpelling) {
  const auto r = run_lucent("render --help", "help");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* group : {"maps", "sh", "hierarchical", "fur", "reference"})
    EXPECT_NE(r.out.find(std::string("[Option Group: ") + group + "]"), std::string::npos) << group;
  for (const char* now : {"--maps-frames", "--sh-cube-map", "--hierarchical-mode", "--fur-shells",
                          "--reference-samples-pixel"})
    EXPECT_NE(r.out.find(now), std::string::npos) << now;
  for (const char* before : {" --frames ", "--hbe-", " --samples-pixel ", " --threads "})
    EXPECT_EQ(r.out.find(before), std::string::npos) << before << " is in the help";
}

TEST(TechniqueFlags, AnEnumNamesItsChoicesUnderEitherSpelling) {
  for (const char* name : {"--hierarchical-mode", "--hbe-mode"}) {
    const auto r =
        run_lucent(tiny("hierarchical") + " " + name + " fast -o /tmp/never.exr", "enum");
    EXPECT_NE(r.exit_code, 0);
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(std::string(name) + ": expected render, incremental or on-the-fly, got "
                                             "'fast'"),
              std::string::npos)
        << r.err;
  }
  EXPECT_FALSE(fs::exists("/tmp/never.exr"));
}

// Three lights (the default rig) and one disc sample: every light gathers the one point. Before,
// each light past the first appended a copy past the GPU buffer's end (heap corruption, abort).
TEST(TechniqueFlags, MoreLightsThanDiscSamplesRenders) {
  const fs::path dir = scratch_dir("flags-lights");
  const auto r = run_lucent(
      "render --material marble --size 8x8 --maps-frames 1 --maps-directions 1 "
      "--maps-radiance-map 8 --maps-light-map 8 --maps-samples 1 --maps-disc-points 1 -o \"" +
          (dir / "one.exr").string() + "\"",
      "lights");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "one.exr"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace lucent::testing
