// The bad-input tables (issue "Nothing crashes, nothing is lost"): each case prepares a fresh
// folder, runs one lucent command on it, and asserts the contract for every refusal: exit status 1
// or 2 (no signal, no internal error), exactly one line on stderr naming the file, field or option
// (the case's needle), and the folder exactly as it was: no output, no temporary, no input changed.
// The shared inputs (the "world": a material, a capture, profiles, meshes, maps) are checked
// unchanged too.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_runner.h"

namespace lucent::testing {

namespace fs = std::filesystem;

struct BadCase {
  std::string name;
  /// Writes the case's own files into `dir` (may be empty).
  std::function<void(const fs::path& dir)> setup;
  /// Arguments; "{dir}" becomes the case's folder, "{world}" the shared inputs' folder.
  std::string args;
  /// What the one stderr line must contain (the file, field or option, and what was wrong).
  std::string needle;
};

inline void PrintTo(const BadCase& c, std::ostream* os) { *os << c.name; }

inline void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

inline std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Every file under `dir` (hidden ones included) with its contents.
inline std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  if (!fs::exists(dir)) return files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string rel = fs::relative(e.path(), dir).string();
    files[rel] = e.is_regular_file() ? read_bytes(e.path()) : std::string("<folder>");
  }
  return files;
}

inline std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
  return s;
}

inline std::string first_line_or_all(const std::string& s) {
  return s.size() > 600 ? s.substr(0, 600) + "..." : s;
}

/// Every refusal runs bounded: 1 GiB of address space (lucent itself starts in about 300 MiB; the
/// audit's memory blow-ups reached 1.6-3.2 GB from inputs of a few KB, so a reader that sizes an
/// allocation from a header it has not checked fails here with bad_alloc and no named field) and 120 s
/// (every refusal takes well under 10 s on 2 cores, ASan included; the audit's hangs never ended).
inline constexpr RunLimits kRefusalLimits{1L << 20, 120};

/// The shared, valid inputs every table mutates: made once per test binary.
const fs::path& world();

inline void expect_clean_refusal(const BadCase& c) {
  const fs::path dir = scratch_dir("bad-" + c.name);
  if (c.setup) c.setup(dir);
  const auto before = snapshot(dir);
  const auto world_before = snapshot(world());
  const std::string args =
      replace_all(replace_all(c.args, "{dir}", dir.string()), "{world}", world().string());
  const CommandResult r = run_lucent(args, "bad-" + c.name, kRefusalLimits);
  EXPECT_TRUE(r.exit_code == 1 || r.exit_code == 2)
      << c.name << ": exit " << r.exit_code << "\nargs: " << args << "\nstderr: " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1)
      << c.name << ": stderr must be one line:\n" << first_line_or_all(r.err);
  EXPECT_NE(r.err.find(c.needle), std::string::npos)
      << c.name << ": '" << c.needle << "' not in: " << r.err;
  EXPECT_EQ(r.err.find("internal error"), std::string::npos) << c.name << ": " << r.err;
  const auto after = snapshot(dir);
  for (const auto& [name, bytes] : after) {
    EXPECT_TRUE(before.count(name)) << c.name << ": left " << name;
  }
  for (const auto& [name, bytes] : before) {
    const auto it = after.find(name);
    EXPECT_TRUE(it != after.end() && it->second == bytes) << c.name << ": changed " << name;
  }
  EXPECT_TRUE(snapshot(world()) == world_before) << c.name << ": changed the shared inputs";
  fs::remove_all(dir);
}

// JSON documents made by mutating a valid one.
using Json = nlohmann::ordered_json;

inline Json read_json(const fs::path& path) { return Json::parse(read_bytes(path)); }

/// A case folder's file made from the world's file `base` with `edit` applied (read when the case
/// runs: the tables are built before main, the world only when first needed).
inline std::function<void(const fs::path&)> edited_json(std::string base, std::string name,
                                                        std::function<void(Json&)> edit) {
  return [=](const fs::path& dir) {
    Json doc = read_json(world() / base);
    edit(doc);
    write_file(dir / name, doc.dump(2));
  };
}

/// A case folder's file with these exact bytes.
inline std::function<void(const fs::path&)> bytes_file(std::string name, std::string bytes) {
  return [=](const fs::path& dir) { write_file(dir / name, bytes); };
}

/// `depth` nested arrays: the provenance bomb.
inline std::string deep_nesting(int depth) {
  return std::string(std::size_t(depth), '[') + std::string(std::size_t(depth), ']');
}

}  // namespace lucent::testing
