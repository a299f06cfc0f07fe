// The headless OpenGL 4.5 context shared by the tests of one suite: derive the suite's fixture
// from GlTest and start each GL test with LUCENT_SKIP_WITHOUT_GL() (llvmpipe or a GPU; skipped
// where none can be made).
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "lucent/render/gl_context.h"

namespace lucent::render::testing_gl {

class GlTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    setenv("MESA_SHADER_CACHE_DISABLE", "true", 0);
    context_ = GlContext::try_create_headless(&why_not_).release();
  }
  static void TearDownTestSuite() {
    delete context_;
    context_ = nullptr;
  }
  static inline GlContext* context_ = nullptr;
  static inline std::string why_not_;
};

}  // namespace lucent::render::testing_gl

#define LUCENT_SKIP_WITHOUT_GL() \
  if (context_ == nullptr) GTEST_SKIP() << "no headless OpenGL: " << why_not_
