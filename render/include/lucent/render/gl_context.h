// An OpenGL 4.5 core context for lucent's renderer: headless through EGL (Mesa llvmpipe on CPU
// machines, the vendor driver on GPUs), made current on the calling thread. GL types and headers
// stay out of this header; the renderer's sources include them.
#pragma once

#include <memory>
#include <string>

namespace lucent::render {

class GlContext {
 public:
  struct Options {
    /// KHR_debug output to stderr (errors, warnings, performance notes), on in debug builds and
    /// where $LUCENT_GL_DEBUG is set to anything but 0.
    bool debug_output = default_debug_output();
    static bool default_debug_output();
  };

  /// A surfaceless EGL context (GL 4.5 core) made current on this thread. Tries
  /// EGL_PLATFORM_SURFACELESS_MESA, then each EGL device (EGL_EXT_platform_device, for vendor
  /// drivers), then the default display. Throws lucent::Error with one line saying what is missing
  /// (no EGL display, no GL 4.5 core context) when none works.
  static std::unique_ptr<GlContext> create_headless(const Options& options);
  static std::unique_ptr<GlContext> create_headless() { return create_headless(Options{}); }

  /// create_headless, or nullptr with the reason in *why_not (tests skip on it).
  static std::unique_ptr<GlContext> try_create_headless(std::string* why_not);

  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  /// Makes the context current on the calling thread (it already is after creation).
  void make_current();

  /// "GL_RENDERER | GL_VERSION", e.g. "llvmpipe (LLVM 15.0.6, 256 bits) | 4.5 (Core Profile) Mesa".
  std::string describe() const;

  /// True when the renderer is a CPU rasteriser (llvmpipe, softpipe, swrast): tests shrink work.
  bool is_software() const;

 private:
  struct Egl;
  explicit GlContext(std::unique_ptr<Egl> egl);
  std::unique_ptr<Egl> egl_;
};

}  // namespace lucent::render
