#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <vector>

#include "cli_runner.h"

namespace lucent::testing {
namespace {

namespace fs = std::filesystem;
const std::string kData = LUCENT_TEST_DATA_DIR;

std::vector<std::vector<std::string>> parse_csv(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    // The totals line of lucent's radial CSV, "# total=R,G,B", as a row "total,R,G,B".
    if (line.rfind("# total=", 0) == 0) line = "total," + line.substr(8);
    std::vector<std::string> fields;
    std::istringstream f(line);
    std::string field;
    while (std::getline(f, field, ',')) fields.push_back(field);
    rows.push_back(fields);
  }
  return rows;
}

// Same header, same labels, numbers equal to 1e-12 relative: goldens survive last-bit differences
// in libm between machines but catch any change of formula.
void expect_csv_matches_golden(const std::string& actual, const std::string& golden_name) {
  const std::string golden = read_text(kData + "/golden/" + golden_name);
  ASSERT_FALSE(golden.empty()) << "missing golden " << golden_name;
  const auto a = parse_csv(actual), g = parse_csv(golden);
  ASSERT_EQ(a.size(), g.size()) << golden_name;
  for (std::size_t i = 0; i < g.size(); ++i) {
    ASSERT_EQ(a[i].size(), g[i].size()) << golden_name << " row " << i;
    for (std::size_t j = 0; j < g[i].size(); ++j) {
      char* end = nullptr;
      const double expected = std::strtod(g[i][j].c_str(), &end);
      if (i == 0 || *end != '\0') {
        EXPECT_EQ(a[i][j], g[i][j]) << golden_name << " row " << i << " column " << j;
      } else {
        const double value = std::stod(a[i][j]);
        EXPECT_NEAR(value, expected, 1e-12 * std::abs(expected))
            << golden_name << " row " << i << " column " << j;
      }
    }
  }
}

TEST(ProfileCommand, DipoleRadiiMatchGolden) {
  const auto r =
      run_lucent("profile --material marble --model dipole --r 0,0.1,0.5,1,2,10 --total");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  expect_csv_matches_golden(r.out, "marble_dipole_radii.csv");
}

TEST(ProfileCommand, DirectionalDipoleRangeMatchesGolden) {
  const auto r =
      run_lucent("profile --material marble --model ddipole --r-range 0.01:50:20:log --total");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_csv_matches_golden(r.out, "marble_ddipole_range.csv");
}

TEST(ProfileCommand, ConfigurationsMatchGoldenForBothModels) {
  const fs::path dir = scratch_dir("configs");
  for (const std::string model : {"ddipole", "dipole"}) {
    const fs::path out = dir / (model + ".csv");
    const auto r = run_lucent("profile --material potato --model " + model + " --configs \"" +
                              kData + "/data/configs.csv\" -o \"" + out.string() + "\"");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(r.out.empty());
    expect_csv_matches_golden(read_text(out), "potato_" + model + "_configs.csv");
  }
  fs::remove_all(dir);
}

TEST(ProfileCommand, MaterialFromAFilePath) {
  const auto by_name = run_lucent("profile --material skin1 --r 1");
  const auto by_path = run_lucent("profile --material \"" + std::string(LUCENT_SOURCE_DIR) +
                                  "/materials/library/skin1.json\" --r 1");
  ASSERT_EQ(by_name.exit_code, 0) << by_name.err;
  EXPECT_EQ(by_name.out, by_path.out);
}

TEST(ProfileCommand, DipoleTotalEqualsClosedFormAndDdipoleExceedsIt) {
  const auto dipole =
      parse_csv(run_lucent("profile --material marble --model dipole --r 1 --total").out);
  const auto ddipole =
      parse_csv(run_lucent("profile --material marble --model ddipole --r 1 --total").out);
  // Row 0 is the format line, row 1 the totals.
  ASSERT_EQ(dipole[1][0], "total");
  ASSERT_EQ(ddipole[1][0], "total");
  EXPECT_NEAR(std::stod(dipole[1][1]), 0.8301914562772919, 1e-12);
  EXPECT_GT(std::stod(ddipole[1][1]), std::stod(dipole[1][1]));
}

struct BadInput {
  const char* name;
  std::string args;
  const char* message;  // expected substring of the single error line
};

void PrintTo(const BadInput& bad, std::ostream* os) {
  *os << bad.name;
}

class ProfileCommandBadInput : public ::testing::TestWithParam<BadInput> {};

TEST_P(ProfileCommandBadInput, OneLineNonZeroExitNoOutputFile) {
  const BadInput& bad = GetParam();
  const fs::path dir = scratch_dir(std::string("bad-") + bad.name);
  const fs::path out = dir / "out.csv";
  std::string args = bad.args;
  for (std::string key : {std::string("DATA"), std::string("OUT")}) {
    const std::string value = key == "DATA" ? kData + "/data" : out.string();
    for (auto pos = args.find("{" + key + "}"); pos != std::string::npos;
         pos = args.find("{" + key + "}")) {
      args.replace(pos, key.size() + 2, value);
    }
  }
  const auto r = run_lucent(args, bad.name);
  EXPECT_NE(r.exit_code, 0) << bad.name;
  EXPECT_NE(r.err.find(bad.message), std::string::npos) << bad.name << ": " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << bad.name << ": " << r.err;
  EXPECT_FALSE(fs::exists(out)) << bad.name;
  EXPECT_EQ(fs::directory_iterator(dir), fs::directory_iterator()) << bad.name << ": stray files";
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, ProfileCommandBadInput,
    ::testing::Values(
        BadInput{"unknown_material", "profile --material unobtainium --r 1 -o {OUT}",
                 "unknown material 'unobtainium'"},
        BadInput{"negative_r", "profile --material marble --r 1,-2 -o {OUT}", "[0, 1e6] mm"},
        BadInput{"r_not_number", "profile --material marble --r 1,abc -o {OUT}", "--r: expected"},
        BadInput{"bad_range", "profile --material marble --r-range 0:10:5:log -o {OUT}",
                 "log spacing needs FROM > 0"},
        BadInput{"unknown_model", "profile --material marble --model tripole --r 1 -o {OUT}",
                 "--model: expected 'dipole', 'ddipole' or 'tabulated'"},
        BadInput{"tabulated_configs",
                 "profile --material potato --model tabulated --configs {DATA}/configs.csv -o {OUT}",
                 "radial only"},
        BadInput{"bad_quantity", "profile --material marble --quantity flux --r 1 -o {OUT}",
                 "--quantity: expected 'exitance' or 'radiance'"},
        BadInput{"no_points", "profile --material marble -o {OUT}", "give one of --r"},
        BadInput{"two_modes", "profile --material marble --r 1 --r-range 1:2:3 -o {OUT}",
                 "excludes"},
        BadInput{"missing_configs", "profile --material marble --configs {DATA}/nope.csv -o {OUT}",
                 "cannot open"},
        BadInput{"malformed_row",
                 "profile --material marble --configs {DATA}/malformed_row.csv -o {OUT}",
                 "malformed_row.csv: line 3: column wi_y: expected a finite number"},
        BadInput{"short_row", "profile --material marble --configs {DATA}/short_row.csv -o {OUT}",
                 "short_row.csv: line 2: expected 15 comma-separated numbers"},
        BadInput{"non_unit_normal",
                 "profile --material marble --configs {DATA}/non_unit_normal.csv -o {OUT}",
                 "non_unit_normal.csv: line 2: ni must be a unit vector"},
        BadInput{"bad_header", "profile --material marble --configs {DATA}/bad_header.csv -o {OUT}",
                 "bad_header.csv: line 1: expected the header"},
        BadInput{"bad_material_file", "profile --material {DATA}/bad_material.json --r 1 -o {OUT}",
                 "bad_material.json"},
        BadInput{"unwritable_output", "profile --material marble --r 1 -o {DATA}/no/such/dir/x.csv",
                 "no/such/dir/x.csv"}),
    [](const ::testing::TestParamInfo<BadInput>& info) { return std::string(info.param.name); });

TEST(ProfileCommand, HelpAndVersion) {
  const auto help = run_lucent("profile --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("radii in mm"), std::string::npos) << help.out;
  const auto version = run_lucent("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_EQ(version.out.rfind("lucent ", 0), 0u) << version.out;
}

}  // namespace
}  // namespace lucent::testing
