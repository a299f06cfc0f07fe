// Runs the lucent executable in a shell and captures its exit status, stdout and stderr.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace lucent::testing {

struct CommandResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A fresh, empty folder for one test.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("lucent-test-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// `args` is appended to the binary's path verbatim (quote what needs quoting).
inline CommandResult run_lucent(const std::string& args, const std::string& name = "cmd") {
  const auto dir = scratch_dir("run-" + name);
  const auto out = dir / "stdout", err = dir / "stderr";
  const std::string command = std::string("\"") + LUCENT_BINARY + "\" " + args + " >\"" +
                              out.string() + "\" 2>\"" + err.string() + "\" </dev/null";
  const int status = std::system(command.c_str());
  CommandResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  result.out = read_text(out);
  result.err = read_text(err);
  std::filesystem::remove_all(dir);
  return result;
}

}  // namespace lucent::testing
