// The one bounded JSON path (parse_json, read_json_file, check_finite_json) and the outputs of a
// command as one transaction (OutputTransaction, note_input, the non-finite guard), at library
// level; the CLI tables (tests/cli/bad_*_test.cpp) hold the same contract end to end.
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/core/json_file.h"

namespace lucent {
namespace {

namespace fs = std::filesystem;

struct Folder {
  fs::path path;
  Folder() {
    path = fs::temp_directory_path() /
           ("lucent-output-io-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~Folder() { fs::remove_all(path); }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(path)) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }
};

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(ParseJson, RefusesDuplicateKeysNamingTheObject) {
  EXPECT_EQ(message_of([] { parse_json(R"({"a": 1, "a": 2})", "f.json"); }),
            "f.json: duplicate key \"a\" in the top level (which one is meant?)");
  EXPECT_EQ(message_of([] { parse_json(R"({"o": {"k": 1, "k": 1}})", "f.json"); }),
            "f.json: duplicate key \"k\" in object \"o\" (which one is meant?)");
  // The same key in sibling objects, or in objects inside an array, is no duplicate.
  EXPECT_NO_THROW(parse_json(R"({"a": {"k": 1}, "b": {"k": 2}, "c": [{"k": 1}, {"k": 2}]})", "f"));
}

TEST(ParseJson, LimitsTheNestingAndKeepsErrorsOnOneLine) {
  const auto nested = [](int depth) {
    return std::string(std::size_t(depth), '[') + std::string(std::size_t(depth), ']');
  };
  EXPECT_NO_THROW(parse_json(nested(kMaxJsonDepth), "f"));
  EXPECT_NE(message_of([&] { parse_json(nested(kMaxJsonDepth + 1), "f"); })
                .find("nested deeper than 128 levels"),
            std::string::npos);
  EXPECT_NE(message_of([&] { parse_json(nested(100000), "f"); }).find("nested deeper"),
            std::string::npos);
  const std::string overflow = message_of([] { parse_json(R"({"x": 1e309})", "f.json"); });
  EXPECT_EQ(overflow.rfind("f.json: not valid JSON: number overflow", 0), 0u) << overflow;
  const std::string broken = message_of([] { parse_json("{\n\"x\": \n", "f.json"); });
  EXPECT_EQ(broken.find('\n'), std::string::npos) << broken;
  EXPECT_EQ(broken.find("[json.exception"), std::string::npos) << broken;
}

TEST(ReadInputFile, StopsAtItsLimit) {
  EXPECT_NE(message_of([] { read_input_file("/dev/zero", 1 << 20); }).find("larger than 1 MiB"),
            std::string::npos);
  EXPECT_NE(message_of([] { read_input_file("/nonexistent/x.json"); }).find("cannot open"),
            std::string::npos);
}

TEST(CheckFiniteJson, NamesTheFieldOfTheFirstNonFiniteNumber) {
  nlohmann::json doc = {{"a", {{"b", {1.0, std::nan("")}}}}, {"c", nullptr}};
  EXPECT_EQ(message_of([&] { check_finite_json(doc, "out.json"); }),
            "out.json: cannot write: a.b[1] is not finite (lucent writes only finite numbers)");
  doc["a"]["b"][1] = 2.0;
  EXPECT_NO_THROW(check_finite_json(doc, "out.json"));  // null is a value, not a NaN
}

TEST(WriteFileAtomically, RefusesNonFiniteNumbersInText) {
  Folder dir;
  const fs::path csv = dir.path / "x.csv";
  EXPECT_EQ(message_of([&] { write_file_atomically(csv, "r,R\n1,0.5\n2,-nan\n"); }),
            csv.string() + ": cannot write: line 3 would hold a non-finite number (lucent "
                           "writes only finite values)");
  EXPECT_TRUE(dir.names().empty());
  // Words are not numbers, comment lines are not searched, binary payloads are not text.
  EXPECT_NO_THROW(write_file_atomically(csv, "# material=nan model=inf\ninfo,infinite\n1,2\n"));
  EXPECT_NO_THROW(write_file_atomically(dir.path / "t.lut", std::string("nan\0inf", 7), true));
  EXPECT_EQ(dir.names(), (std::vector<std::string>{"t.lut", "x.csv"}));
}

TEST(OutputTransaction, CommitsEverythingOrNothing) {
  Folder dir;
  {
    OutputTransaction outputs;
    write_file_atomically(dir.path / "a.json", "{}\n");
    AtomicOutputPath image(dir.path / "b.png");
    std::ofstream(image.temporary()) << "png";
    image.commit();
    // Until the commit only hidden temporaries exist.
    for (const std::string& name : dir.names()) EXPECT_EQ(name[0], '.') << name;
  }  // not committed: a failed command
  EXPECT_TRUE(dir.names().empty());
  {
    OutputTransaction outputs;
    write_file_atomically(dir.path / "a.json", "{}\n");
    write_file_atomically(dir.path / "c.csv", "1,2\n");
    outputs.commit();
  }
  EXPECT_EQ(dir.names(), (std::vector<std::string>{"a.json", "c.csv"}));
}

TEST(OutputTransaction, NeverReplacesAnInput) {
  Folder dir;
  const fs::path in = dir.path / "p.json";
  std::ofstream(in) << "{\"format\": 1}";
  OutputTransaction outputs;
  (void)read_json_file(in);
  EXPECT_NE(message_of([&] { write_file_atomically(in, "{}\n"); }).find("is an input of this run"),
            std::string::npos);
  EXPECT_NE(message_of([&] { AtomicOutputDir out(dir.path); }).find("holds"), std::string::npos);
  outputs.commit();
  std::ifstream check(in);
  std::stringstream text;
  text << check.rdbuf();
  EXPECT_EQ(text.str(), "{\"format\": 1}");
}

TEST(AtomicOutputDir, AnExistingFolderNeedsPermissionAndIsReplacedWhole) {
  Folder dir;
  const fs::path target = dir.path / "out";
  fs::create_directories(target);
  std::ofstream(target / "old.txt") << "old";
  EXPECT_NE(message_of([&] { AtomicOutputDir out(target); }).find("--force"), std::string::npos);
  set_replace_folders(true);
  {
    AtomicOutputDir out(target);
    std::ofstream(out.temporary() / "new.txt") << "new";
    out.commit();
  }
  set_replace_folders(false);
  EXPECT_TRUE(fs::exists(target / "new.txt"));
  EXPECT_FALSE(fs::exists(target / "old.txt"));
  EXPECT_EQ(dir.names(), std::vector<std::string>{"out"});  // no backup or temporary left
}

}  // namespace
}  // namespace lucent
