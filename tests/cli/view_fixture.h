// What the `lucent view` tests share (view_command_test.cpp, view_layout_test.cpp): the window
// run under a fresh virtual X server with a script, and its screenshots read back.
#pragma once

#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli_runner.h"
#include "lucent/imaging/image_io.h"

namespace lucent::testing {

namespace fs = std::filesystem;

inline void write_text(const fs::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

inline bool have_xvfb() {
  return std::system("command -v xvfb-run >/dev/null 2>&1") == 0;
}

struct Shot {
  imaging::RawImage image;
  double mean[3] = {0, 0, 0};  // radiance x exposure over the pixels brighter than the background
  long lit = 0;
};

// The window's tone curve undone: sRGB decoded, then Reinhard's x / (1 + x) inverted.
inline double radiance_of(int code) {
  const double v = std::min(code, 254) / 255.0;
  const double linear = v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
  return linear / (1 - linear);
}

inline Shot load_shot(const fs::path& path) {
  Shot shot;
  shot.image = imaging::read_raw_image(path);
  for (int y = 0; y < shot.image.height; ++y) {
    for (int x = 0; x < shot.image.width; ++x) {
      const int sum = shot.image.at(x, y, 0) + shot.image.at(x, y, 1) + shot.image.at(x, y, 2);
      if (sum <= 6) continue;
      ++shot.lit;
      for (int c = 0; c < 3; ++c) shot.mean[c] += radiance_of(shot.image.at(x, y, c));
    }
  }
  for (double& m : shot.mean) m /= double(std::max(shot.lit, 1L));
  return shot;
}

inline long differing_pixels(const Shot& a, const Shot& b) {
  long n = 0;
  for (std::size_t i = 0; i < a.image.data.size(); i += 3) {
    if (std::abs(int(a.image.data[i]) - int(b.image.data[i])) > 8) ++n;
  }
  return n;
}

// Pixels where `image` shows the object (brighter than the background) and `with_panel`, the same
// frame with the panel drawn, differs: what the panel covers of the object.
inline long covered_object_pixels(const Shot& image, const Shot& with_panel) {
  long n = 0;
  for (std::size_t i = 0; i < image.image.data.size(); i += 3) {
    const int sum = image.image.data[i] + image.image.data[i + 1] + image.image.data[i + 2];
    if (sum <= 6) continue;
    for (std::size_t c = 0; c < 3; ++c)
      if (image.image.data[i + c] != with_panel.image.data[i + c]) {
        ++n;
        break;
      }
  }
  return n;
}

// xvfb-run -a probes for a free display from -n on; tests that ctest runs side by side start from
// different numbers so that two of them do not claim the same one at the same moment.
inline std::string server_number() {
  return std::to_string(100 + ::getpid() % 800);
}

class ViewCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!have_xvfb()) GTEST_SKIP() << "xvfb-run not found (scripts/install-deps installs xvfb)";
    dir_ = scratch_dir("view");
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  // Runs `lucent view ARGS` in dir_ under a fresh virtual X server; `input`, when given, runs in
  // the same server beside the window (xdotool's mouse and keys: X events as a person's).
  CommandResult view(const std::string& args, const std::string& before = "",
                     const std::string& screen = "640x480", const std::string& input = "") {
    std::string session = "\"" LUCENT_BINARY "\" view " + args;
    if (!input.empty()) {
      write_text(dir_ / "session.sh", session + " &\nwindow=$!\n" + input + "\nwait $window\n");
      session = "sh session.sh";
    }
    const std::string command = "cd \"" + dir_.string() + "\" || exit 1; " + before +
                                "MESA_SHADER_CACHE_DISABLE=true xvfb-run -a -n " + server_number() +
                                " -s '-screen 0 " + screen + "x24' " + session;
    const fs::path out = dir_ / "stdout", err = dir_ / "stderr";
    const int status =
        std::system((command + " >\"" + out.string() + "\" 2>\"" + err.string() + "\"").c_str());
    CommandResult result;
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
    result.out = read_text(out);
    result.err = read_text(err);
    return result;
  }
  fs::path dir_;
};

}  // namespace lucent::testing
