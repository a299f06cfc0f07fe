// Runs the lucent executable in a shell and captures its exit status, stdout and stderr.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
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

// stderr without the progress lines of a run that took over a second ("render: 40%, 3 s left",
// "render: rendering (sh), 1 s so far"): what a test of the messages reads.
inline std::string without_progress(const std::string& err) {
  std::string kept;
  std::size_t pos = 0;
  while (pos < err.size()) {
    const std::size_t end = std::min(err.find('\n', pos), err.size());
    const std::string line = err.substr(pos, end - pos);
    const bool share = line.find("%, ") != std::string::npos && line.size() > 5 &&
                       line.compare(line.size() - 5, 5, " left") == 0;
    const bool alive = line.size() > 7 && line.compare(line.size() - 7, 7, " so far") == 0;
    if (!share && !alive) kept += line + (end < err.size() ? "\n" : "");
    pos = end + 1;
  }
  return kept;
}

/// A fresh, empty folder for one test.
inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("lucent-test-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Bounds on a run: its address space (`ulimit -v`, KiB; 0 = none) and its wall time (seconds; the
/// run is killed past it and reports exit 137 or 124).
struct RunLimits {
  long memory_kib = 0;
  int seconds = 0;
};

/// Whether this build runs under AddressSanitizer, which reserves terabytes of address space up
/// front: `ulimit -v` cannot bound such a process, so memory bounds are skipped there.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif
#else
inline constexpr bool kAddressSanitizer = false;
#endif

/// `args` is appended to the binary's path verbatim (quote what needs quoting).
inline CommandResult run_lucent(const std::string& args, const std::string& name = "cmd",
                                RunLimits limits = {}) {
  const auto dir = scratch_dir("run-" + name);
  const auto out = dir / "stdout", err = dir / "stderr";
  std::string prefix;
  if (limits.memory_kib > 0 && !kAddressSanitizer)
    prefix += "ulimit -v " + std::to_string(limits.memory_kib) + " && exec ";
  if (limits.seconds > 0) prefix += "timeout -s KILL " + std::to_string(limits.seconds) + " ";
  const std::string command = prefix + "\"" + LUCENT_BINARY + "\" " + args + " >\"" +
                              out.string() + "\" 2>\"" + err.string() + "\" </dev/null";
  const int status = std::system(command.c_str());
  CommandResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  result.out = read_text(out);
  result.err = read_text(err);
  std::filesystem::remove_all(dir);
  return result;
}

/// Starts lucent in the background (stdout and stderr to `log`); returns its pid for kill/waitpid.
inline pid_t spawn_lucent(const std::string& args, const std::filesystem::path& log) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const std::string command = std::string("exec \"") + LUCENT_BINARY + "\" " + args + " >\"" +
                                log.string() + "\" 2>&1 </dev/null";
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

/// Whether `dir` holds one of lucent's temporaries (".tmp-" in the name).
inline bool has_temporary(const std::filesystem::path& dir) {
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec))
    if (e.path().filename().string().find(".tmp-") != std::string::npos) return true;
  return false;
}

}  // namespace lucent::testing
