// The viewer's script is checked whole before a window opens (render/viewer/viewer_script.h):
// numbers outside what the viewer can do are refused by name (`wait 1e30` hung the viewer, `set
// exposure -5` and `set light_scale 1e30` were taken), and a valid script parses to its actions.
#include "viewer_script.h"

#include <gtest/gtest.h>

#include <string>

namespace lucent::render::viewer_detail {
namespace {

TEST(ViewerScript, NumbersOutsideWhatTheViewerCanDoAreRefused) {
  for (const auto& [script, needle] : std::vector<std::pair<std::string, std::string>>{
           {"wait 1e30", "wait 1e30"},
           {"wait -1", "wait -1"},
           {"wait nan", "wait nan"},
           {"sleep 1e9", "sleep 1e9"},
           {"sleep -2", "sleep"},
           {"set exposure -5", "exposure -5"},
           {"set exposure 0", "exposure 0"},
           {"set exposure inf", "exposure inf"},
           {"set light_scale 1e30", "light_scale 1e30"},
           {"set light_scale 0", "light_scale 0"},
           {"orbit 1e9 0", "orbit 1e9"},
           {"light 0 nan", "light 0 nan"},
           {"zoom 1e6", "zoom 1e6"},
           {"screenshot shot.exr", "FILE.png"},
           {"screenshot-panel shot", "FILE.png"},
           {"orbit 1", "expected orbit DX DY"},
           {"dance", "dance"}}) {
    try {
      (void)parse_script(script);
      ADD_FAILURE() << script << ": accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << script << ": " << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
}

TEST(ViewerScript, AValidScriptParsesToItsActions) {
  const std::vector<ScriptAction> a =
      parse_script("orbit 10 -5; set exposure 2; wait 3; sleep 0.5; screenshot a.PNG; quit");
  ASSERT_EQ(a.size(), 6u);
  EXPECT_EQ(a[0].verb, "orbit");
  EXPECT_EQ(a[1].args[1], "2");
  EXPECT_EQ(a[4].args[0], "a.PNG");
  EXPECT_EQ(a[5].verb, "quit");
}

}  // namespace
}  // namespace lucent::render::viewer_detail
