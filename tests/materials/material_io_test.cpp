// Tests materials/src/material.cpp (the lucent-material file format and the bundled library) and
// materials/src/atomic_file.cpp (atomic output).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/materials/material.h"

namespace lucent::materials {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::vector<std::string> kBundledNames = {
    "apple",  "beer",   "chicken1", "chicken2", "coffee", "cream",   "grapefruit", "ketchup",
    "marble", "potato", "skimmilk", "skin1",    "skin2",  "soymilk", "wholemilk",  "wine"};

// A fresh, empty folder per test, removed afterwards; the pid keeps concurrent runs of the suite
// (two build folders, ctest -j) apart.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = "lucent_material_io_" + std::to_string(::getpid()) + "_" +
                       info->test_suite_name() + "_" + info->name();
    std::replace(name.begin(), name.end(), '/', '_');  // parameterised tests have '/' in names
    path_ = fs::path(::testing::TempDir()) / name;
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::vector<std::string> files_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// The message of the lucent::Error that `f` throws; fails the test if it throws nothing or another
// type.
std::string error_message(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected lucent::Error, got another exception: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected lucent::Error, nothing was thrown";
  return {};
}

// Every number in a JSON document is finite (JSON has no NaN; nlohmann would write null silently).
bool all_numbers_finite(const json& j) {
  if (j.is_number_float()) return std::isfinite(j.get<double>());
  if (j.is_structured()) {
    for (const auto& item : j) {
      if (!all_numbers_finite(item)) return false;
    }
  }
  return true;
}

// --- the bundled library ------------------------------------------------------------------------

TEST(MaterialLibrary, NamesListEveryBundledMaterial) {
  const std::vector<std::string> names = library_material_names();
  for (const std::string& name : kBundledNames) {
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  }
  EXPECT_TRUE(std::is_sorted(names.begin(), names.end()));
}

TEST(MaterialLibrary, EveryBundledMaterialLoadsByName) {
  for (const std::string& name : kBundledNames) {
    SCOPED_TRACE(name);
    Material m;
    ASSERT_NO_THROW(m = load_material(name));
    EXPECT_EQ(m.name, name);  // the file stem is the material's name
    EXPECT_GT(m.ior, 1.0);
    EXPECT_TRUE(m.provenance.is_object());
    EXPECT_EQ(m.provenance.value("units", ""), "mm^-1");
    EXPECT_TRUE(m.provenance.contains("source"));
    EXPECT_EQ(m.sigma_s.has_value(), m.g.has_value());
    for (int c = 0; c < 3; ++c) {
      const Medium<double> medium = m.medium(c);
      EXPECT_GT(medium.sigma_a, 0.0) << "channel " << c;
      EXPECT_GE(medium.sigma_s, 0.0) << "channel " << c;
    }
    EXPECT_TRUE(all_numbers_finite(material_to_json(m)));
    EXPECT_EQ(m.to_string().find('\n'), std::string::npos);
  }
}

TEST(MaterialLibrary, MarbleMatchesJensenTable) {
  const Material m = load_material("marble");
  EXPECT_EQ(m.ior, 1.5);
  EXPECT_EQ(m.sigma_a, (Rgb{0.0021, 0.0041, 0.0071}));
  EXPECT_EQ(m.sigma_s_reduced, (Rgb{2.19, 2.62, 3.00}));
  EXPECT_FALSE(m.sigma_s.has_value());
  EXPECT_FALSE(m.g.has_value());
  // Known only through sigma_s': isotropic medium.
  const Medium<double> red = m.medium(0);
  EXPECT_EQ(red.sigma_a, 0.0021);
  EXPECT_EQ(red.sigma_s, 2.19);
  EXPECT_EQ(red.g, 0.0);
  EXPECT_EQ(red.eta, 1.5);
}

TEST(MaterialLibrary, AppleUsesJensensBlueAbsorptionAndSaysSo) {
  const Material m = load_material("apple");
  EXPECT_EQ(m.sigma_a, (Rgb{0.0030, 0.0034, 0.046}));
  const std::string note = m.provenance.value("note", "");
  EXPECT_NE(note.find("0.0046"), std::string::npos) << note;
  EXPECT_NE(note.find("0.046"), std::string::npos) << note;
}

TEST(MaterialLibrary, NarasimhanMaterialsCarrySigmaSAndG) {
  const Material coffee = load_material("coffee");
  ASSERT_TRUE(coffee.sigma_s && coffee.g);
  EXPECT_EQ(*coffee.sigma_s, (Rgb{0.2707, 0.2828, 0.297}));
  EXPECT_EQ(*coffee.g, (Rgb{0.907, 0.896, 0.88}));
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(coffee.sigma_s_reduced[c], (*coffee.sigma_s)[c] * (1 - (*coffee.g)[c]), 1e-15);
    EXPECT_EQ(coffee.medium(c).g, (*coffee.g)[c]);
  }
}

TEST(MaterialLibrary, WineGreenAndBlueDoNotScatter) {
  const Material wine = load_material("wine");
  ASSERT_TRUE(wine.sigma_s && wine.g);
  const Medium<double> green = wine.medium(1);
  EXPECT_EQ(green.sigma_s, 0.0);
  EXPECT_EQ(green.sigma_a, 1.6429);
  EXPECT_EQ(wine.medium(2).sigma_s, 0.0);
  EXPECT_EQ(wine.sigma_s_reduced[1], 0.0);
  const json derived = material_to_json(wine)["derived"];
  EXPECT_EQ(derived["alpha_prime"][1].get<double>(), 0.0);
  EXPECT_EQ(derived["total_diffuse_reflectance"][1].get<double>(), 0.0);
  EXPECT_TRUE(all_numbers_finite(derived));
}

TEST(MaterialLibrary, LoadsAFileByPath) {
  const fs::path marble = material_library_dir() / "marble.json";
  EXPECT_EQ(load_material(marble.string()).sigma_a, load_material("marble").sigma_a);
}

TEST(MaterialLibrary, UnknownNameListsBundledMaterials) {
  const std::string message = error_message([] { load_material("no-such-material"); });
  EXPECT_NE(message.find("unknown material 'no-such-material'"), std::string::npos) << message;
  for (const std::string& name : kBundledNames) {
    EXPECT_NE(message.find(name), std::string::npos) << name << " missing from: " << message;
  }
  EXPECT_EQ(message.find('\n'), std::string::npos);
}

TEST(MaterialLibrary, EnvironmentVariableOverridesTheLibraryFolder) {
  TempDir dir;
  Material m = load_material("marble");
  m.name = "testonly";
  write_material(dir.path() / "testonly.json", m);
  write_text(dir.path() / "README.txt", "not a material");
  ASSERT_EQ(::setenv("LUCENT_MATERIAL_LIBRARY", dir.path().c_str(), 1), 0);
  EXPECT_EQ(material_library_dir(), dir.path());
  EXPECT_EQ(library_material_names(), std::vector<std::string>{"testonly"});
  EXPECT_EQ(load_material("testonly").name, "testonly");
  ::unsetenv("LUCENT_MATERIAL_LIBRARY");
  EXPECT_NE(material_library_dir(), dir.path());
}

// --- writing and reading
// --------------------------------------------------------------------------

Material awkward_material() {
  Material m;
  m.name = "round trip";
  m.ior = 1.0 / 0.7;
  m.sigma_a = {0.1 + 0.2, 1.0 / 3.0, 4.9406564584124654e-324};  // last: the smallest denormal
  m.sigma_s = Rgb{12.345678901234567, 0.0, 987654.32109876543};  // the largest allowed: 1e6
  m.g = Rgb{0.1 * 3.0, -0.999999999, 0.9};
  for (int c = 0; c < 3; ++c) m.sigma_s_reduced[c] = (*m.sigma_s)[c] * (1.0 - (*m.g)[c]);
  m.model = "ddipole";
  m.uncertainty = {{"sigma_a_std", {1e-5, 2e-5, 3e-5}},
                   {"correlation", {{1.0, -0.25}, {-0.25, 1.0}}}};
  m.provenance = {{"capture", "capture.json"}, {"tool_version", "0.1.0"}, {"rms_log", 0.0123}};
  return m;
}

void expect_identical(const Material& a, const Material& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.ior, b.ior);
  EXPECT_EQ(a.sigma_a, b.sigma_a);
  EXPECT_EQ(a.sigma_s_reduced, b.sigma_s_reduced);
  EXPECT_EQ(a.sigma_s, b.sigma_s);
  EXPECT_EQ(a.g, b.g);
  EXPECT_EQ(a.model, b.model);
  EXPECT_EQ(a.uncertainty, b.uncertainty);
  EXPECT_EQ(a.provenance, b.provenance);
}

TEST(MaterialIo, WriteThenReadReproducesEveryFieldExactly) {
  TempDir dir;
  const Material original = awkward_material();
  const fs::path path = dir.path() / "awkward.json";
  write_material(path, original);
  expect_identical(read_material(path), original);
  EXPECT_EQ(files_in(dir.path()), std::vector<std::string>{"awkward.json"});  // no temporaries
}

TEST(MaterialIo, RoundTripsAMaterialWithoutOptionalFields) {
  TempDir dir;
  Material original;
  original.name = "minimal";
  original.ior = 1.5;
  original.sigma_a = {0.0021, 0.0041, 0.0071};
  original.sigma_s_reduced = {2.19, 2.62, 3.00};
  const fs::path path = dir.path() / "minimal.json";
  write_material(path, original);
  const json written = json::parse(read_text(path));
  EXPECT_FALSE(written.contains("sigma_s"));
  EXPECT_FALSE(written.contains("g"));
  EXPECT_FALSE(written.contains("model"));
  EXPECT_FALSE(written.contains("uncertainty"));
  EXPECT_FALSE(written.contains("provenance"));
  expect_identical(read_material(path), original);
}

TEST(MaterialIo, FileStartsWithFormatAndVersion) {
  TempDir dir;
  const fs::path path = dir.path() / "m.json";
  write_material(path, load_material("marble"));
  const std::string text = read_text(path);
  EXPECT_EQ(text.rfind("{\n  \"format\": \"lucent-material\",\n  \"version\": 1,\n", 0), 0u)
      << text;
}

TEST(MaterialIo, DerivedBlockIsWrittenAndFinite) {
  const json doc = material_to_json(load_material("skin1"));
  ASSERT_TRUE(doc.contains("derived"));
  const json& derived = doc["derived"];
  for (const char* key : {"alpha_prime", "sigma_tr_per_mm", "diffuse_mean_free_path_mm",
                          "total_diffuse_reflectance"}) {
    ASSERT_TRUE(derived.contains(key)) << key;
    ASSERT_TRUE(derived[key].is_array()) << key;
    EXPECT_EQ(derived[key].size(), 3u) << key;
  }
  for (int c = 0; c < 3; ++c) {
    const double sigma_tr = derived["sigma_tr_per_mm"][c].get<double>();
    EXPECT_GT(sigma_tr, 0.0);
    EXPECT_DOUBLE_EQ(derived["diffuse_mean_free_path_mm"][c].get<double>(), 1.0 / sigma_tr);
    const double r_tot = derived["total_diffuse_reflectance"][c].get<double>();
    EXPECT_GT(r_tot, 0.0);
    EXPECT_LT(r_tot, 1.0);
  }
  EXPECT_TRUE(all_numbers_finite(doc));
}

TEST(MaterialIo, DerivedMeanFreePathIsNullWithoutAbsorption) {
  Material m = load_material("marble");
  m.sigma_a = {0.0, 0.0041, 0.0};
  const json derived = material_to_json(m)["derived"];
  EXPECT_EQ(derived["sigma_tr_per_mm"][0].get<double>(), 0.0);
  EXPECT_TRUE(derived["diffuse_mean_free_path_mm"][0].is_null());
  EXPECT_TRUE(derived["diffuse_mean_free_path_mm"][1].is_number());
  EXPECT_TRUE(all_numbers_finite(derived));

  // A channel with nothing in it at all (no absorption, no scattering) stays finite too.
  m.sigma_s_reduced = {0.0, 2.62, 3.00};
  EXPECT_TRUE(all_numbers_finite(material_to_json(m)));
}

TEST(MaterialIo, DerivedIsIgnoredOnRead) {
  TempDir dir;
  json doc = material_to_json(load_material("marble"));
  doc["derived"] = {{"alpha_prime", "bogus"}, {"whatever", {1, 2}}, {"nested", {{"x", nullptr}}}};
  const fs::path path = dir.path() / "bogus_derived.json";
  write_text(path, doc.dump(2));
  expect_identical(read_material(path), load_material("marble"));
}

TEST(MaterialIo, SigmaSReducedIsComputedWhenOmitted) {
  const json doc = {
      {"format", "lucent-material"}, {"version", 1},         {"name", "x"},        {"ior", 1.3},
      {"sigma_a", {1, 2, 3}},        {"sigma_s", {2, 4, 0}}, {"g", {0.5, 0.75, 0}}};
  const Material m = material_from_json(doc, "inline");
  EXPECT_EQ(m.sigma_s_reduced, (Rgb{1.0, 1.0, 0.0}));
}

TEST(MaterialIo, SigmaSReducedMayDifferFromTheProductByRounding) {
  json doc = {{"format", "lucent-material"},
              {"version", 1},
              {"name", "x"},
              {"ior", 1.3},
              {"sigma_a", {1, 2, 3}},
              {"sigma_s", {2, 4, 1e-13}},
              {"g", {0.5, 0.75, 0}},
              {"sigma_s_reduced", {1.0000005, 0.9999995, 0}}};
  EXPECT_NO_THROW(material_from_json(doc, "inline"));
  doc["sigma_s_reduced"] = {1.000002, 1.0, 0.0};
  EXPECT_NE(error_message([&] {
              material_from_json(doc, "inline");
            }).find("field 'sigma_s_reduced': element 0 (R)"),
            std::string::npos);
}

TEST(MaterialIo, ReaderGuardsAgainstNonFiniteNumbers) {
  // Strict JSON cannot spell NaN or infinity, but a document built in memory can hold them.
  const json base = material_to_json(load_material("marble"));
  json doc = base;
  doc["sigma_a"][1] = std::nan("");
  EXPECT_NE(error_message([&] {
              material_from_json(doc, "mem");
            }).find("mem: field 'sigma_a': element 1 (G): expected a number in [0, 1e6]"),
            std::string::npos);
  doc = base;
  doc["ior"] = INFINITY;
  EXPECT_NE(error_message([&] { material_from_json(doc, "mem"); }).find("field 'ior'"),
            std::string::npos);
  doc = base;
  doc["sigma_s"] = {1, 1, 1};
  doc["g"] = {0.5, -INFINITY, 0.5};
  doc.erase("sigma_s_reduced");
  EXPECT_NE(error_message([&] { material_from_json(doc, "mem"); }).find("field 'g': element 1"),
            std::string::npos);
}

TEST(MaterialIo, MissingFileNamesThePath) {
  const fs::path missing = fs::path(::testing::TempDir()) / "lucent_no_such_dir" / "nothing.json";
  const std::string message = error_message([&] { read_material(missing); });
  EXPECT_EQ(message.rfind(missing.string() + ": cannot open", 0), 0u) << message;
  EXPECT_NE(message.find("No such file"), std::string::npos) << message;
  // A path-like argument to load_material is read as a path, not looked up in the library.
  EXPECT_EQ(error_message([&] { load_material(missing.string()); }).rfind(missing.string(), 0), 0u);
}

TEST(MaterialIo, ToStringIsOneLineWithUnits) {
  const std::string s = load_material("coffee").to_string();
  EXPECT_EQ(s.find('\n'), std::string::npos);
  EXPECT_NE(s.find("coffee"), std::string::npos) << s;
  EXPECT_NE(s.find("ior=1.3"), std::string::npos) << s;
  EXPECT_NE(s.find("/mm"), std::string::npos) << s;
  EXPECT_NE(s.find("g=["), std::string::npos) << s;
}

// --- bad input: one file per mistake, each with the message it must produce
// ------------------------

struct BadMaterialCase {
  const char* file;
  const char* expected;  // substring of the message: the field and what was expected
};

std::ostream& operator<<(std::ostream& os, const BadMaterialCase& c) {
  return os << c.file;
}

class BadMaterialFile : public ::testing::TestWithParam<BadMaterialCase> {};

TEST_P(BadMaterialFile, IsRejectedWithOneLineNamingFileAndField) {
  const fs::path path = fs::path(LUCENT_TEST_DATA_DIR) / "bad_materials" / GetParam().file;
  ASSERT_TRUE(fs::exists(path)) << path;
  const std::string message = error_message([&] { read_material(path); });
  EXPECT_NE(message.find(GetParam().expected), std::string::npos)
      << "expected to find: " << GetParam().expected << "\nin: " << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(message.rfind(path.string() + ": ", 0), 0u) << message;
}

INSTANTIATE_TEST_SUITE_P(
    MaterialIo, BadMaterialFile,
    ::testing::Values(
        BadMaterialCase{"missing_sigma_a.json", "field 'sigma_a': missing; expected an array of 3"},
        BadMaterialCase{"sigma_a_length_2.json",
                        "field 'sigma_a': expected an array of 3 numbers (R, G, B), each a number "
                        "in [0, 1e6] (mm^-1), found an array of 2 elements"},
        BadMaterialCase{"sigma_a_negative.json",
                        "field 'sigma_a': element 2 (B): expected a number in [0, 1e6] (mm^-1), "
                        "found -0.0071"},
        BadMaterialCase{"sigma_a_string_element.json",
                        "field 'sigma_a': element 1 (G): expected a number in [0, 1e6] (mm^-1), "
                        "found string \"0.0041\""},
        BadMaterialCase{"sigma_a_not_array.json",
                        "field 'sigma_a': expected an array of 3 numbers"},
        BadMaterialCase{"ior_zero.json", "field 'ior': expected a number in [0.25, 4]"},
        BadMaterialCase{"ior_five.json", "field 'ior': expected a number in [0.25, 4]"},
        BadMaterialCase{"ior_string.json", "field 'ior': expected a number in [0.25, 4]"},
        BadMaterialCase{"g_one.json",
                        "field 'g': element 0 (R): expected a number in (-1, 1), found 1"},
        BadMaterialCase{"g_minus_one.json",
                        "field 'g': element 2 (B): expected a number in (-1, 1), found -1"},
        BadMaterialCase{"sigma_s_without_g.json",
                        "field 'g': missing; expected together with 'sigma_s'"},
        BadMaterialCase{"g_without_sigma_s.json",
                        "field 'sigma_s': missing; expected together with 'g'"},
        BadMaterialCase{"sigma_s_reduced_disagrees.json",
                        "field 'sigma_s_reduced': element 1 (G): expected sigma_s (1 - g) = 0.5"},
        BadMaterialCase{"missing_sigma_s_reduced.json", "field 'sigma_s_reduced': missing"},
        BadMaterialCase{"format_profile.json",
                        "field 'format': expected \"lucent-material\" (a material file), found "
                        "string \"lucent-profile\""},
        BadMaterialCase{"missing_format.json", "field 'format': missing"},
        BadMaterialCase{"version_2.json", "field 'version': expected 1 or older"},
        BadMaterialCase{"version_string.json",
                        "field 'version': expected a positive integer, found string \"1\""},
        BadMaterialCase{"version_zero.json", "field 'version': expected a positive integer"},
        BadMaterialCase{"unknown_field.json",
                        "field 'sigma_s_reducd': unknown field (did you mean 'sigma_s_reduced'?)"},
        BadMaterialCase{"name_empty.json", "field 'name': expected a non-empty string"},
        BadMaterialCase{"model_not_string.json", "field 'model': expected a string"},
        BadMaterialCase{"provenance_not_object.json", "field 'provenance': expected an object"},
        BadMaterialCase{"top_level_array.json", "expected a JSON object"},
        BadMaterialCase{"not_json.json", "not valid JSON: parse error at line 1, column"},
        BadMaterialCase{"truncated.json", "not valid JSON: parse error at line 7"},
        BadMaterialCase{"empty.json", "not valid JSON"}),
    [](const ::testing::TestParamInfo<BadMaterialCase>& info) {
      return fs::path(info.param.file).stem().string();
    });

TEST(MaterialIo, EveryBadFixtureIsCovered) {
  // A fixture added to bad_materials/ without a row above would be silently untested.
  const std::vector<std::string> fixtures =
      files_in(fs::path(LUCENT_TEST_DATA_DIR) / "bad_materials");
  EXPECT_EQ(fixtures.size(), 27u);
}

// --- atomic output ------------------------------------------------------------------------------

TEST(AtomicFile, WritesAndReplaces) {
  TempDir dir;
  const fs::path target = dir.path() / "out.txt";
  write_file_atomically(target, "first");
  write_file_atomically(target, "second, longer");
  EXPECT_EQ(read_text(target), "second, longer");
  write_file_atomically(target, "");
  EXPECT_EQ(read_text(target), "");
  EXPECT_EQ(files_in(dir.path()), std::vector<std::string>{"out.txt"});
}

TEST(AtomicFile, MissingFolderThrowsAndLeavesNothing) {
  TempDir dir;
  const fs::path target = dir.path() / "no_such_folder" / "out.json";
  const std::string message = error_message([&] { write_file_atomically(target, "content"); });
  EXPECT_EQ(message.rfind(target.string() + ": ", 0), 0u) << message;
  EXPECT_NE(message.find("No such file or directory"), std::string::npos) << message;
  EXPECT_TRUE(files_in(dir.path()).empty());

  EXPECT_THROW(write_material(target, load_material("marble")), Error);
  EXPECT_TRUE(files_in(dir.path()).empty());
}

TEST(AtomicFile, FailedRenameRemovesTheTemporary) {
  TempDir dir;
  const fs::path target = dir.path() / "occupied";
  fs::create_directories(target / "child");  // a non-empty folder cannot be renamed over
  const std::string message = error_message([&] { write_file_atomically(target, "content"); });
  EXPECT_EQ(message.rfind(target.string() + ": ", 0), 0u) << message;
  EXPECT_EQ(files_in(dir.path()), std::vector<std::string>{"occupied"});
}

TEST(AtomicOutputPath, WithoutCommitLeavesNoFile) {
  TempDir dir;
  const fs::path target = dir.path() / "image.exr";
  fs::path temporary;
  {
    AtomicOutputPath out(target);
    temporary = out.temporary();
    EXPECT_EQ(out.target(), target);
    EXPECT_EQ(temporary.parent_path(), target.parent_path());
    EXPECT_EQ(temporary.extension(), ".exr");  // format-sniffing writers still see the type
    EXPECT_EQ(temporary.filename().string().rfind(".image.tmp-", 0), 0u) << temporary;
    write_text(temporary, "partial");
  }
  EXPECT_FALSE(fs::exists(temporary));
  EXPECT_TRUE(files_in(dir.path()).empty());

  { AtomicOutputPath never_written(target); }  // nothing to remove: still no throw, no file
  EXPECT_TRUE(files_in(dir.path()).empty());
}

TEST(AtomicOutputPath, CommitLeavesExactlyTheTarget) {
  TempDir dir;
  const fs::path target = dir.path() / "image.png";
  write_text(target, "old");
  {
    AtomicOutputPath out(target);
    write_text(out.temporary(), "new");
    out.commit();
  }
  EXPECT_EQ(read_text(target), "new");
  EXPECT_EQ(files_in(dir.path()), std::vector<std::string>{"image.png"});
}

TEST(AtomicOutputPath, CommitWithoutAFileThrowsNamingTheTarget) {
  TempDir dir;
  const fs::path target = dir.path() / "image.png";
  AtomicOutputPath out(target);
  const std::string message = error_message([&] { out.commit(); });
  EXPECT_EQ(message.rfind(target.string() + ": ", 0), 0u) << message;
  EXPECT_TRUE(files_in(dir.path()).empty());
}

TEST(AtomicOutputPath, TemporaryNamesAreUnique) {
  TempDir dir;
  AtomicOutputPath a(dir.path() / "x.csv");
  AtomicOutputPath b(dir.path() / "x.csv");
  EXPECT_NE(a.temporary(), b.temporary());
}

}  // namespace
}  // namespace lucent::materials
