// cli/progress.h away from a terminal (ctest's stderr is a file): nothing in the first second,
// then one line per stage (StageProgress) or per tenth (ProgressLine), each ending in a newline.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "../../cli/progress.h"

namespace lucent::cli {
namespace {

// Runs `f` with stderr pointed at a file and returns what it wrote.
template <class F>
std::string captured_stderr(F f) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("lucent-progress-" + std::to_string(::getpid()) + ".txt");
  std::fflush(stderr);
  const int saved = ::dup(2);
  const int file = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ::dup2(file, 2);
  ::close(file);
  f();
  std::fflush(stderr);
  ::dup2(saved, 2);
  ::close(saved);
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  std::filesystem::remove(path);
  return s.str();
}

TEST(Progress, DurationText) {
  EXPECT_EQ(duration_text(6.4), "6 s");
  EXPECT_EQ(duration_text(245), "4 min 5 s");
  EXPECT_EQ(duration_text(3723), "1 h 2 min 3 s");
  EXPECT_EQ(duration_text(-3), "0 s");
}

// A stage with no share to report (render's hierarchical links): with the heartbeat, a line after
// the first second away from a terminal, and none before it.
TEST(Progress, AHeartbeatSaysALongStageIsAlive) {
  const std::string quick = captured_stderr([] {
    StageProgress progress("render", false, true);
    progress.stage("rendering (hierarchical)", 0.0);
    progress.finish();
  });
  EXPECT_EQ(quick, "");
  const std::string text = captured_stderr([] {
    StageProgress progress("render", false, true);
    progress.stage("rendering (hierarchical)", 0.0);
    std::this_thread::sleep_for(std::chrono::milliseconds(1600));
    progress.finish();
  });
  EXPECT_NE(text.find("render: rendering (hierarchical), 1 s so far\n"), std::string::npos) << text;
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << text;
  EXPECT_EQ(text.find('\r'), std::string::npos) << text;
}

TEST(Progress, StagesAfterTheFirstSecondGetOneLineEach) {
  const std::string text = captured_stderr([] {
    StageProgress progress("acquire", false);
    progress.stage("merging", 0.0);  // within the first second: silent
    std::this_thread::sleep_for(std::chrono::milliseconds(1100));
    progress.stage("binning the profile", 0.6);
    progress.stage("writing", 0.9);
    progress.finish();
  });
  EXPECT_EQ(text.find("merging"), std::string::npos) << text;
  EXPECT_NE(text.find("acquire: binning the profile (60% done"), std::string::npos) << text;
  EXPECT_NE(text.find("acquire: writing (90% done"), std::string::npos) << text;
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2) << text;
  EXPECT_EQ(text.find('\r'), std::string::npos) << text;  // no redraws in a log
}

TEST(Progress, QuietPrintsNothing) {
  const std::string text = captured_stderr([] {
    StageProgress stages("acquire", true);
    ProgressLine line("simulate", "photons", true);
    std::this_thread::sleep_for(std::chrono::milliseconds(1100));
    stages.stage("merging", 0.5);
    line.update(5, 10);
  });
  EXPECT_TRUE(text.empty()) << text;
}

TEST(Progress, ProgressLinePrintsEachTenthOnce) {
  const std::string text = captured_stderr([] {
    ProgressLine line("tabulate", "photons", false);
    line.update(1, 10);  // first second: silent
    std::this_thread::sleep_for(std::chrono::milliseconds(1100));
    for (int done = 2; done <= 10; ++done) {
      line.update(done, 10);
      line.update(done, 10);  // the same tenth again: no second line
    }
    line.finish();
  });
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 9) << text;
  EXPECT_NE(text.find("tabulate: 20% of 10 photons"), std::string::npos) << text;
  EXPECT_NE(text.find("tabulate: 100% of 10 photons, 0 s left"), std::string::npos) << text;
}

}  // namespace
}  // namespace lucent::cli
