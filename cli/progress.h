// Progress of a long command on stderr: on a terminal one line redrawn at most once a second with
// the share done and the time left; elsewhere (a log, a job array's output) one line per tenth,
// so that a log shows the stages without a carriage-return smear. Nothing in the first second (a
// short run prints only its result). No CLI11 here.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>

namespace lucent::cli {

/// "1 h 2 min 3 s", "4 min 5 s", "6 s".
inline std::string duration_text(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  std::string out;
  if (s >= 3600) out += std::to_string(s / 3600) + " h ";
  if (s >= 60) out += std::to_string((s % 3600) / 60) + " min ";
  return out + std::to_string(s % 60) + " s";
}

class ProgressLine {
 public:
  /// `what`: the command's name; `unit`: what is counted ("photons"; empty: a share of the work).
  /// Quiet: prints nothing.
  ProgressLine(std::string what, std::string unit, bool quiet)
      : what_(std::move(what)),
        unit_(std::move(unit)),
        quiet_(quiet),
        terminal_(::isatty(STDERR_FILENO) != 0),
        start_(std::chrono::steady_clock::now()),
        last_(start_) {}

  void update(std::uint64_t done, std::uint64_t total) {
    if (quiet_ || done == 0 || total == 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - start_ < std::chrono::seconds(1)) return;  // a short run shows nothing
    const int tenth = int(10 * done / total);
    if (terminal_ ? now - last_ < std::chrono::seconds(1) : tenth <= last_tenth_) return;
    last_ = now;
    last_tenth_ = tenth;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double left = elapsed * double(total - done) / double(done);
    // Without a unit the count is only a share ("render: 40%, 3 s left").
    const std::string of = unit_.empty() ? "" : " of " + std::to_string(total) + " " + unit_;
    std::fprintf(stderr, "%s%s: %d%%%s, %s left%s", terminal_ ? "\r" : "", what_.c_str(),
                 int(100 * done / total), of.c_str(), duration_text(left).c_str(),
                 terminal_ ? "   " : "\n");
    std::fflush(stderr);
    drawn_ = true;
  }
  /// Clears a terminal's line (call before printing the result).
  void finish() {
    if (drawn_ && terminal_) std::fprintf(stderr, "\r%s\r", std::string(70, ' ').c_str());
    drawn_ = false;
  }
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::string what_, unit_;
  bool quiet_, terminal_;
  std::chrono::steady_clock::time_point start_, last_;
  int last_tenth_ = 0;
  bool drawn_ = false;
};

/// Progress of a command made of stages (acquire, view's start-up): `stage(name, done)` says which
/// stage starts and the share of the work done before it. On a terminal a ticker redraws
/// "acquire: merging the sample brackets, 40%, 3 s left" once a second (after the first second,
/// so that it keeps moving through a long stage); elsewhere one line per stage begun after the
/// first second. Thread-safe.
class StageProgress {
 public:
  /// `heartbeat`: away from a terminal, also a line after the first second and then every ten
  /// ("render: rendering (hierarchical boundary elements), 11 s so far") for a stage that has no
  /// share to report (a technique's set-up).
  StageProgress(std::string what, bool quiet, bool heartbeat = false)
      : what_(std::move(what)),
        quiet_(quiet),
        terminal_(::isatty(STDERR_FILENO) != 0),
        heartbeat_(heartbeat),
        start_(std::chrono::steady_clock::now()) {
    if (!quiet_ && (terminal_ || heartbeat_)) ticker_ = std::thread([this] { tick(); });
  }
  ~StageProgress() { finish(); }
  StageProgress(const StageProgress&) = delete;
  StageProgress& operator=(const StageProgress&) = delete;

  void stage(const std::string& name, double done) {
    if (quiet_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    stage_ = name;
    done_ = std::clamp(done, 0.0, 1.0);
    if (!terminal_ && elapsed() >= 1.0) {
      std::fprintf(stderr, "%s: %s (%d%% done, %s so far)\n", what_.c_str(), name.c_str(),
                   int(100 * done_), duration_text(elapsed()).c_str());
      std::fflush(stderr);
    }
  }
  /// Stops the ticker and clears a terminal's line (call before printing the result).
  void finish() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (stopped_) return;
      stopped_ = true;
    }
    wake_.notify_all();
    if (ticker_.joinable()) ticker_.join();
    if (drawn_) std::fprintf(stderr, "\r%s\r", std::string(78, ' ').c_str());
  }

 private:
  double elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  void tick() {
    std::unique_lock<std::mutex> lock(mutex_);
    double next_line = 1;
    while (!wake_.wait_for(lock, std::chrono::seconds(1), [this] { return stopped_; })) {
      if (stage_.empty()) continue;
      const double t = elapsed();
      if (!terminal_) {
        if (t + 0.5 < next_line) continue;
        next_line = t < 5 ? 10 : next_line + 10;
        std::fprintf(stderr, "%s: %s, %s so far\n", what_.c_str(), stage_.c_str(),
                     duration_text(t).c_str());
        std::fflush(stderr);
        continue;
      }
      const std::string left =
          done_ > 0.02 ? ", " + duration_text(t * (1 - done_) / done_) + " left" : "";
      std::fprintf(stderr, "\r%s: %s, %d%%%s   ", what_.c_str(), stage_.c_str(), int(100 * done_),
                   left.c_str());
      std::fflush(stderr);
      drawn_ = true;
    }
  }

  std::string what_;
  bool quiet_, terminal_, heartbeat_;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::thread ticker_;
  std::string stage_;
  double done_ = 0;
  bool stopped_ = false, drawn_ = false;
};

}  // namespace lucent::cli
