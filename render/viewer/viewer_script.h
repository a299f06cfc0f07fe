// The viewer's script (lucent view --script): actions separated by ';', checked whole before the
// window opens. Private to lucent_viewer (and its test).
#pragma once

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "lucent/core/error.h"

namespace lucent::render::viewer_detail {

// ---------------------------------------------------------------------------------------------
// The script: one action per frame.

struct ScriptAction {
  std::string verb;
  std::vector<std::string> args;
};

inline std::vector<ScriptAction> parse_script(const std::string& text) {
  std::vector<ScriptAction> actions;
  std::stringstream all(text);
  std::string item;
  while (std::getline(all, item, ';')) {
    std::stringstream words(item);
    ScriptAction action;
    if (!(words >> action.verb)) continue;
    for (std::string w; words >> w;) action.args.push_back(w);
    const std::string& v = action.verb;
    const std::size_t n = action.args.size();
    const bool ok = ((v == "orbit" || v == "light" || v == "set") && n == 2) ||
                    ((v == "zoom" || v == "wait" || v == "sleep" || v == "screenshot" ||
                      v == "screenshot-panel" || v == "save") &&
                     n == 1) ||
                    (v == "key" && n == 1 && action.args[0].size() == 1 &&
                     std::isalpha(static_cast<unsigned char>(action.args[0][0]))) ||
                    ((v == "restart" || v == "settle" || v == "quit") && n == 0) ||
                    ((v == "panel" || v == "difference") && n == 1 &&
                     (action.args[0] == "on" || action.args[0] == "off"));
    // Numbers within what the viewer can do, checked before the window opens: `wait 1e30` hung,
    // `set exposure -5` and `set light_scale 1e30` were taken.
    const auto in = [&](std::size_t k, double lo, double hi, const char* what) {
      char* end = nullptr;
      const double x = std::strtod(action.args[k].c_str(), &end);
      if (action.args[k].empty() || *end != '\0' || !std::isfinite(x) || x < lo || x > hi) {
        std::string whole = v;
        for (const std::string& w : action.args) whole += " " + w;
        throw Error("--script: '" + whole + "': expected " + what);
      }
    };
    if (ok && (v == "orbit" || v == "light")) {
      in(0, -1e4, 1e4, "DX in [-1e4, 1e4] pixels");
      in(1, -1e4, 1e4, "DY in [-1e4, 1e4] pixels");
    }
    if (ok && v == "zoom") in(0, -100, 100, "STEPS in [-100, 100]");
    if (ok && v == "wait") in(0, 0, 1e5, "FRAMES in [0, 100000]");
    if (ok && v == "sleep") in(0, 0, 3600, "SECONDS in [0, 3600]");
    if (ok && v == "set" && action.args[0] == "exposure")
      in(1, 1e-6, 1e6, "an exposure in [1e-6, 1e6]");
    if (ok && v == "set" && action.args[0] == "light_scale")
      in(1, 1e-3, 1e3, "a light scale factor in [1e-3, 1e3]");
    if (ok && (v == "screenshot" || v == "screenshot-panel")) {
      std::string ext = std::filesystem::path(action.args[0]).extension().string();
      for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
      if (ext != ".png")
        throw Error("--script: '" + v + " " + action.args[0] + "': expected FILE.png");
    }
    if (ok && v == "save") {
      std::string ext = std::filesystem::path(action.args[0]).extension().string();
      for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
      if (ext != ".json")
        throw Error("--script: 'save " + action.args[0] + "': expected FILE.json (a material)");
    }
    if (!ok) {
      const auto first = item.find_first_not_of(' ');
      const auto last = item.find_last_not_of(' ');
      throw Error("--script: '" + item.substr(first, last - first + 1) +
                  "': expected orbit DX DY, light DX DY, zoom STEPS, set NAME VALUE, key LETTER, "
                  "wait FRAMES, sleep SECONDS, settle, screenshot FILE.png, screenshot-panel "
                  "FILE.png, save FILE.json, panel on|off, "
                  "difference on|off, restart or quit");
    }
    actions.push_back(std::move(action));
  }
  return actions;
}

inline float parse_float(const std::string& text, const std::string& what) {
  char* end = nullptr;
  const float v = std::strtof(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v)) {
    throw Error("--script: " + what + ": expected a number, got '" + text + "'");
  }
  return v;
}

}  // namespace lucent::render::viewer_detail
